"""Only the observer-recognition rows of benchmarks/bench_gait.py, for choosing among candidate weights quickly
(about 30 s per split): each walk of a corpus split seeds a generated gait with its own emotion vector, and the
synthetic observer (generation/quality/observer.py) reads it; optionally also procedural seeds of the unseen
mixtures. Uses bench_gait's own functions, so the figures are the benchmark's.

    python -m benchmarks.gait_observer_rows WEIGHTS.pt [WEIGHTS2.pt ...] [--split val|test|both]
        [--guidance 0,1,2] [--seed-frames 0,80,160] [--no-procedural] [--steps 200]

Choose on --split val; report test only for the chosen candidate. With 19-29 walks per class one walk moves a
class by 0.04, so for choosing, seed each walk at several frames (``--seed-frames``) and compare also the
continuous score "p(own)": the observer's mean probability of the intended class, per class.
"""
from __future__ import annotations

import argparse
import itertools
import time
from pathlib import Path

import numpy as np
import torch

from benchmarks import bench_gait as bench
from benchmarks.bench_record import one_thread
from generation.core.paths import straight
from generation.gait.data import DEFAULT_CORPUS, load_corpus_sequences
from generation.gait.generate import load_model
from generation.procedural.corpus import GaitCorpus
from generation.quality.gait_guidance import heldout_corpus, seed_walks, single_dominant
from protocol.vocabulary import GAIT_EMOTIONS

ROOT = Path(__file__).resolve().parents[1]


def row(table: dict) -> str:
    """'overall (happy / sad / angry / neutral) lowest x'."""
    per_class = " / ".join(f"{table[e]:.2f}" for e in GAIT_EMOTIONS)
    return f"{table['overall']:.2f} ({per_class}) lowest {min(table[e] for e in GAIT_EMOTIONS):.2f}"


def p_own_row(proba: np.ndarray, intended: np.ndarray) -> str:
    """'p(own) happy / sad / angry / neutral (lowest x)': mean observer probability of the intended class."""
    p = [float(proba[intended == k, k].mean()) for k in range(len(GAIT_EMOTIONS))]
    return "p(own) " + " / ".join(f"{v:.3f}" for v in p) + f" (lowest {min(p):.3f})"


def main(argv=None) -> int:
    one_thread()
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("weights", nargs="+")
    ap.add_argument("--split", choices=("val", "test", "both", "extra-a", "extra-b"), default="val",
                    help="extra-a / extra-b: the even / odd walks of --extra-corpus (every walk unseen in training)")
    ap.add_argument("--extra-corpus", default=None,
                    help="default: the held-out corpus of generation.quality.gait_guidance.heldout_corpus (built with "
                         "another seed when missing): more held-out walks, so that a class's figure rests on ~110 "
                         "walks per half")
    ap.add_argument("--guidance", default="0", help="comma-separated emotion-guidance scales")
    ap.add_argument("--no-procedural", action="store_true", help="skip the procedural seeds of unseen mixtures")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--seed-frames", default="0", help="comma-separated first frames of the seed windows")
    ap.add_argument("--corpus", default=str(ROOT / DEFAULT_CORPUS))
    args = ap.parse_args(argv)
    try:
        scales = [float(x) for x in args.guidance.split(",")]
    except ValueError:
        ap.error(f"--guidance: numbers separated by commas, got {args.guidance!r}")
    try:
        starts = [int(x) for x in args.seed_frames.split(",")]
    except ValueError:
        ap.error(f"--seed-frames: whole numbers separated by commas, got {args.seed_frames!r}")
    torch.set_num_threads(1)
    corpus, data = GaitCorpus.load(args.corpus), load_corpus_sequences(args.corpus)
    observer = bench.Observer(data.subset((data.split == "train") & (data.offset == 0)))
    splits = ["val", "test"] if args.split == "both" else [args.split]
    if args.split.startswith("extra"):
        extra_path = args.extra_corpus or heldout_corpus(ROOT)
        extra_corpus, extra = GaitCorpus.load(extra_path), load_corpus_sequences(extra_path)
        parity = extra.base_index % 2 == (0 if args.split == "extra-a" else 1)
        extra = extra.subset(np.asarray(parity & (extra.offset == 0)))
    for weights, scale in itertools.product(args.weights, scales):
        net = load_model(weights)
        net.info["emotion_guidance"] = scale
        t0 = time.time()
        for split in splits:
            if split.startswith("extra"):
                source, walks = extra_corpus, extra
            else:
                source, walks = corpus, data.subset((data.split == split) & (data.offset == 0))
            emotions = np.tile(walks.emotion.numpy().astype(np.float64), (len(starts), 1))
            seeds = [m for start in starts for m in seed_walks(source, walks.base_index, start)]
            motions = bench.generate_gaits(seeds, [straight(60.0)] * len(seeds), emotions, steps=args.steps,
                                           model=net)
            proba = observer.proba_motions(motions)
            table = bench.accuracy_table(proba.argmax(1), emotions.argmax(1))
            single = single_dominant(emotions)
            untied = bench.accuracy_table(proba[single].argmax(1), emotions[single].argmax(1))
            print(f"{Path(weights).name} w={scale:g} {split} walk seeds (frames {args.seed_frames}), own emotion: "
                  f"{row(table)}; {p_own_row(proba, emotions.argmax(1))}; without tied labels "
                  f"({int((~single).sum())} left out): {row(untied)}", flush=True)
        if not args.no_procedural:
            proc = bench.expressiveness_procedural_seeds(net, observer, args.steps, 10)
            print(f"{Path(weights).name} w={scale:g} procedural seeds, unseen mixtures: "
                  f"{row(proc['unseen_mixture'])}; pure: {row(proc['pure'])}", flush=True)
        print(f"  ({time.time() - t0:.0f} s)", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
