"""The gait network fine-tuned on both real corpora against the shipped weights, on held-out real actors and takes.

    python -m benchmarks.bench_gait_both --nets current=generation/data/weights/gait_net_real.pt \
        acted=var/gait_both/acted.pt soft=var/gait_both/soft.pt [--json docs/benchmarks/gait_both.json]

1. Pose error (seed 000 Table 1 layout, bench_gait_real's measure): the first 9 network steps of a 30-step window
   given, the rest predicted free-running on the true ground track; mean joint error over the body's bounding-box
   diagonal, per network and for the nearest-neighbour continuation from the real training windows (Bandai
   forward locomotion training takes + BML training actors). Test sets: the 6 held-out BML actors (24 walks, loops
   lengthened to 150 frames), the held-out Bandai emotion takes (dataset 1 walk take 2) and all held-out Bandai
   forward locomotion.
2. Emotion carried from held-out actors: each held-out BML walk's first 1.2 s as seed, each of the four emotions
   asked (straight path, 100 steps), read by the calibrated observers (acted and perceived labels).
3. Realism of those walks (stance knee, pelvis bounce, toe skim, speed variability) per asked emotion.
Real capture: Bandai Namco (Kobayashi et al. 2023, CC BY-NC 4.0); BML (Ma, Paterson & Pollick 2006) with
Emotion-Gait labels (STEP, AAAI 2020), research use.
"""
from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np
import torch

from benchmarks.bench_gait_real import generated_from_seeds, prediction_table, recognition
from benchmarks.bench_record import one_thread
from generation.gait.bml_data import bml_clips
from generation.gait.generate import load_model
from generation.gait.real_data import RealAugment, clip_sequences, stage_clips
from generation.mocap.real_corpus import RealCorpora
from generation.quality import calibrated_observer as co
from generation.quality.realism import realism_measures
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS

ROOT = Path(__file__).resolve().parents[1]

KEEP = ("pose_error_body_diag", "pose_error_body_diag_step1", "pose_error_body_diag_later", "rotation_error_deg")


def main(argv=None) -> int:
    one_thread()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nets", nargs="+", required=True, metavar="NAME=PATH")
    ap.add_argument("--json", type=Path, default=ROOT / "docs" / "benchmarks" / "gait_both.json")
    ap.add_argument("--steps", type=int, default=100)
    a = ap.parse_args(argv)
    torch.set_num_threads(1)
    t0 = time.time()
    nets = {k: load_model(v) for k, v in (s.split("=", 1) for s in a.nets)}
    data_cfg = next(iter(nets.values())).config.data
    prefix = data_cfg.prefix_len
    lib = RealAugment(mirror=False, speed_factors=(1.0,), stride_frames=16, offsets=(0,))
    corpora = RealCorpora.from_environ(os.environ)   # $REAL_CORPUS and $BML_CORPUS, else var/mocap/
    train = clip_sequences(stage_clips("pretrain", "train", corpora.bandai) + bml_clips("train", corpora.bml),
                           data_cfg, lib)
    bml_test = bml_clips("test", corpora.bml)
    bandai_test = stage_clips("pretrain", "test", corpora.bandai)
    sets = {"BML held-out actors (6 actors, 24 walks)": bml_test,
            "Bandai held-out emotion takes (dataset 1 walk take 2)": [c for c in bandai_test if c.content == "walk"
                                                                      and c.dataset == "bandai-namco-1"
                                                                      and c.style in CAPTURE_GAIT_EMOTIONS],
            "Bandai held-out forward locomotion (all test takes)": bandai_test}
    res = {"nets": {k: str(v) for k, v in (s.split("=", 1) for s in a.nets)}, "prediction": {}, "carried": {},
           "realism": {}}
    for name, clips in sets.items():
        test = clip_sequences(clips, data_cfg, RealAugment.none())
        table = prediction_table(nets, train, test, prefix)
        res["prediction"][name] = {"windows": len(test), "clips": len(clips),
                                   "methods": {m: {k: round(v[k], 4) for k in KEEP} for m, v in table.items()}}
        print(name, json.dumps({m: v["pose_error_body_diag"] for m, v in res["prediction"][name]["methods"].items()}),
              flush=True)
    observers = {lab: co.train_calibrated_observer(lab) for lab in co.LABEL_VARIANTS}
    res["observer_heldout_recall"] = {lab: o.heldout_recall for lab, o in observers.items()}
    for name, net in nets.items():
        rows = generated_from_seeds(net, bml_test, a.steps)
        res["carried"][name] = {}
        for lab, obs in observers.items():
            rec = recognition(obs, [dict(r) for r in rows])
            res["carried"][name][lab] = {e: v["own"] for e, v in rec["per_class"].items()}
            res["carried"][name][lab + "_as_neutral"] = {e: v["as_neutral"] for e, v in rec["per_class"].items()}
        per = {}
        for e in GAIT_EMOTIONS:
            vals = [realism_measures(r["motion"]) for r in rows if r["asked"] == e]
            per[e] = {k: round(float(np.median([v[k] for v in vals if v[k] is not None])), 3)
                      for k in ("stance_knee_deg", "pelvis_bounce_cm", "toe_skim", "speed_cv")}
        res["realism"][name] = per
        print(name, json.dumps(res["carried"][name]), flush=True)
    res["seconds"] = round(time.time() - t0, 1)
    a.json.parent.mkdir(parents=True, exist_ok=True)
    a.json.write_text(json.dumps(res, indent=1, default=str) + "\n")
    print(f"wrote {a.json} in {res['seconds']} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
