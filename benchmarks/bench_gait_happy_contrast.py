"""Is seed 000's generated happy apart from its generated neutral as far as real happy is from real neutral?

Measures (:mod:`generation.gait.affect_measures`: speed, arm swing, elbow angle, head pitch, pelvis bounce, lengths
/ height) of:
- the seed000 plan's pure and dominant (share >= 0.8) gait_net clips, generated as the plan asks (30 fps), per emotion,
  and the readings of both shipped calibrated observers (acted and perceived labels,
  :func:`generation.quality.calibrated_observer.load_shipped_observer`);
- real walks: Bandai Namco dataset 1 (one actor; happy, sad, angry, normal, both takes of at least 2 s) and the BML
  actors whose walk was perceived happy (each against the same actor's acted-neutral walk, when that one was not
  perceived happy).

    OMP_NUM_THREADS=1 python -m benchmarks.bench_gait_happy_contrast [--json docs/benchmarks/gait_happy_contrast.json]

About 15 s on the 2-core machine (10 clips of 10 s).
"""
from __future__ import annotations

import argparse
import json
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from generation.gait.affect_measures import MEASURES, difference, mean_measures, walk_measures
from generation.mocap.real_corpus import DEFAULT_BML_PATH, DEFAULT_PATH, load_real_corpus
from protocol.vocabulary import GAIT_EMOTIONS


def plan_rows(plan_name: str = "seed000") -> list[dict]:
    from generation.plans.clipgen import make_motion, resolve
    from generation.plans.schema import load_plan
    from generation.quality.calibrated_observer import load_shipped_observer

    observers = {k: load_shipped_observer(k) for k in ("acted", "perceived")}
    rows = []
    for e in load_plan(plan_name).entries:
        if e.generator != "gait_net" or e.inputs.transition is not None:
            continue
        emotion = np.asarray(e.inputs.emotion, float)
        if emotion.max() < 0.8:
            continue
        m = make_motion(resolve(e)[0], fps=30.0)
        rows.append({"id": e.id, "emotion": GAIT_EMOTIONS[int(emotion.argmax())],
                     "read": {k: o.observe(m)[0] for k, o in observers.items() if o is not None},
                     "measures": walk_measures(m)})
    return rows


def bandai_rows(path) -> dict:
    clips = [c for c in load_real_corpus(path, skeleton="gait", contents=["walk"], styles=["happy", "sad", "angry",
                                                                                           "normal"])
             if c.dataset == "bandai-namco-1" and c.motion.num_frames >= 60]
    style = {"happy": "happy", "sad": "sad", "angry": "angry", "normal": "neutral"}
    return {style[s]: mean_measures([c.motion for c in clips if c.style == s]) for s in style}


def bml_happy_difference(path) -> tuple[dict, int]:
    by = defaultdict(dict)
    for c in load_real_corpus(path):
        by[c.motion.metadata.get("performer", c.name)][c.style] = c
    diffs = []
    for walks in by.values():
        neutral = walks.get("neutral")
        if neutral is None or neutral.motion.metadata.get("perceived_label") == "happy":
            continue
        for c in walks.values():
            if c.motion.metadata.get("perceived_label") == "happy":
                diffs.append(difference(walk_measures(c.motion), walk_measures(neutral.motion)))
    return {k: float(np.mean([d[k] for d in diffs])) for k in MEASURES}, len(diffs)


def render(res: dict) -> str:
    g = res["generated_mean"]
    lines = ["| measure | generated happy - neutral | Bandai dataset 1 happy - normal | BML perceived happy - own "
             f"neutral ({res['bml_walks']} walks) | generated at least as far as both |", "|---|---|---|---|---|"]
    for k in MEASURES:
        gen = g["happy"][k] - g["neutral"][k]
        ban = res["bandai"]["happy"][k] - res["bandai"]["neutral"][k]
        bml = res["bml_happy_minus_neutral"][k]
        ok = all(abs(gen) >= abs(r) and np.sign(gen) == np.sign(r) for r in (ban, bml))
        lines.append(f"| {k} | {gen:+.3f} | {ban:+.3f} | {bml:+.3f} | {'yes' if ok else '**no**'} |")
    lines += ["", "| emotion | clips | read as asked: acted observer | perceived observer |", "|---|---|---|---|"]
    for e in GAIT_EMOTIONS:
        mine = [r for r in res["clips"] if r["emotion"] == e]
        lines.append(f"| {e} | {len(mine)} | " + " | ".join(
            f"{sum(r['read'].get(k) == e for r in mine)} of {len(mine)}" for k in ("acted", "perceived")) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default="docs/benchmarks/gait_happy_contrast.json")
    ap.add_argument("--corpus", default=str(DEFAULT_PATH))
    ap.add_argument("--bml", default=str(DEFAULT_BML_PATH))
    args = ap.parse_args(argv)
    t0 = time.time()
    rows = plan_rows()
    mean = {e: {k: float(np.mean([r["measures"][k] for r in rows if r["emotion"] == e])) for k in MEASURES}
            for e in GAIT_EMOTIONS}
    bml, n = bml_happy_difference(args.bml)
    res = {"date": "2026-12-06", "machine": "2-core shared CPU, no GPU", "clips": rows, "generated_mean": mean,
           "bandai": bandai_rows(args.corpus), "bml_happy_minus_neutral": bml, "bml_walks": n}
    res["seconds"] = time.time() - t0
    Path(args.json).write_text(json.dumps(res, indent=1) + "\n", encoding="utf-8")
    print(render(res))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
