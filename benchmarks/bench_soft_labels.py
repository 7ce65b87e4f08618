"""What soft labels change: the gait network fine-tuned on real takes with SIMULATED perceived shares (soft labels,
as seed 000 section 3.2.2 trained on annotators' shares) against the same takes with their acted labels (hard).

    python -m benchmarks.bench_soft_labels [--epochs 6] [--json docs/benchmarks/soft_labels.json]

The rated set: the real takes shipped in generation/data/mocap/bandai-namco/ (Bandai Namco Research Motion
Dataset 1, Kobayashi et al. 2023, CC BY-NC 4.0: one happy, sad, angry and normal walk), each given a SIMULATED
perceived share vector shaped after how often annotators' majority perceives the acted emotion in real walks
(REFERENCE.md section 5, BML: happy 0.57, sad 0.70, angry 0.13, neutral 0.57). Both runs start from the shipped
weights (``--init``), train the same epochs on the same windows and differ only in the emotion targets (hard:
one-hot of the acted label; soft: the simulated shares), through ``--soft-labels`` (hard labels as a clip_norms.csv
of one-hot shares). Then each network (and the shipped one) walks with the four pure emotion vectors and with
happy/neutral mixtures (a, 0, 0, 1 - a), and the real-capture observer (trained on the same shipped takes here,
as no corpus file is built: ``OBSERVERS.gait("real")``) reads the walks: its mean probabilities per input, and the
mixture response (observed P(happy) against the input share a). Nothing here is data from people.
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks.bench_record import record
from generation.mocap.real_corpus import RealCorpora
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, CLIP_NORMS_COLUMNS, GAIT_EMOTIONS

SIMULATED_SHARES = {          # (happy, sad, angry, neutral) perceived, per acted emotion: SIMULATED
    "happy": (0.57, 0.03, 0.05, 0.35),
    "sad": (0.02, 0.70, 0.03, 0.25),
    "angry": (0.25, 0.02, 0.13, 0.60),
    "neutral": (0.25, 0.13, 0.05, 0.57),
}
MIXTURES = (0.0, 0.25, 0.5, 0.75, 1.0)


def _norms_csv(path: Path, shares: dict[str, tuple], n_ratings: int = 20) -> None:
    rows = []
    for clip_id, v in shares.items():
        top = GAIT_EMOTIONS[int(np.argmax(v))]
        rows.append({"clip_id": clip_id, "modality": "gait", "section_type": "emotion_choice",
                     "question": "perceived", "n_ratings": n_ratings, "intended": "", "top_label": top,
                     "top_share": max(v), **{c: "" for c in CLIP_NORMS_COLUMNS[8:]},
                     **{f"share_{e}": x for e, x in zip(GAIT_EMOTIONS, v)}})
    pd.DataFrame(rows)[[*CLIP_NORMS_COLUMNS, *[f"share_{e}" for e in GAIT_EMOTIONS]]].to_csv(path, index=False)


def rated_takes(folder: Path) -> tuple[Path, Path, Path]:
    """Write the shipped emotion takes as motions/<sim clip id>.bvh and two clip_norms.csv: the SIMULATED shares
    (soft) and one-hot acted labels (hard). Returns (motions dir, soft csv, hard csv)."""
    from generation.plans.clipgen import write_motion_bvh
    from generation.quality.real_observer import shipped_clips

    motions = folder / "motions"
    soft, hard = {}, {}
    for clip in shipped_clips():
        emotion = CAPTURE_GAIT_EMOTIONS.get(clip.style)
        if emotion is None:
            continue
        clip_id = f"sim-rated-{emotion}"
        write_motion_bvh(clip.motion, motions, clip_id)
        soft[clip_id] = SIMULATED_SHARES[emotion]
        hard[clip_id] = tuple(float(e == emotion) for e in GAIT_EMOTIONS)
    (folder / "simulated-soft").mkdir(exist_ok=True)
    (folder / "hard").mkdir(exist_ok=True)
    _norms_csv(folder / "simulated-soft" / "clip_norms.csv", soft)
    _norms_csv(folder / "hard" / "clip_norms.csv", hard)
    return motions, folder / "simulated-soft" / "clip_norms.csv", folder / "hard" / "clip_norms.csv"


def readings(weights: Path, observer, steps: int = 200, seeds: int = 2) -> dict:
    """Observer's mean probabilities for walks generated with each pure emotion and each happy/neutral mixture."""
    from generation.core.paths import straight
    from generation.gait.generate import generate_gaits, load_model

    net = load_model(weights)
    inputs = {f"pure_{e}": tuple(float(e == x) for x in GAIT_EMOTIONS) for e in GAIT_EMOTIONS}
    inputs.update({f"happy_{a:.2f}": (a, 0.0, 0.0, 1 - a) for a in MIXTURES})
    names = [k for k in inputs for _ in range(seeds)]
    emotions = np.array([inputs[k] for k in names])
    walks = generate_gaits([None] * len(names), [straight(14.0)] * len(names), emotions, steps=steps, model=net,
                           rng_seed=0)
    out = {}
    for name in inputs:
        p = np.mean([observer.proba(w) for w, n in zip(walks, names) if n == name], axis=0)
        out[name] = {e: round(float(x), 3) for e, x in zip(GAIT_EMOTIONS, p)}
    return out


def main(argv=None) -> dict:
    from generation.gait.train import DEFAULT_WEIGHTS
    from generation.gait.train import main as train_main
    from generation.quality.observers import OBSERVERS

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--epochs", type=int, default=6)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    observer = OBSERVERS.gait("real", corpora=RealCorpora.from_environ(os.environ))
    result = {"benchmark": "bench_soft_labels (SIMULATED perceived shares of real takes)", "epochs": args.epochs,
              "simulated_shares": SIMULATED_SHARES, "observer": observer.source}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        motions, soft_csv, hard_csv = rated_takes(tmp)
        runs = {"shipped": Path(DEFAULT_WEIGHTS)}
        for kind, csv in (("hard", hard_csv), ("soft", soft_csv)):
            out = tmp / f"{kind}.pt"
            t0 = time.perf_counter()
            train_main(["--soft-labels", str(csv), "--motions", str(motions), "--init", str(DEFAULT_WEIGHTS),
                        "--out", str(out), "--epochs", str(args.epochs), "--checkpoint", str(tmp / f"{kind}.ckpt"),
                        "--quiet", "--norms-study", f"simulated-{kind}-labels-of-shipped-takes"])
            result[f"train_{kind}_s"] = round(time.perf_counter() - t0, 1)
            runs[kind] = out
            if kind == "soft":
                import torch
                saved = torch.load(out, weights_only=False)
                rec = saved["corpus"]["soft_labels"]
                result["soft_weights_record"] = {k: rec[k] for k in ("study", "n_clips", "n_ratings", "sha256")}
        result["readings"] = {name: readings(path, observer) for name, path in runs.items()}
    return record(result, args.json)


if __name__ == "__main__":
    main()
