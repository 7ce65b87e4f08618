"""Do the generated gestures move like the real captured gestures of the closest emotion?

For every ``gesture_net`` clip of the demo and seed003 plans (generated as the plan asks, 30 fps), the wrist speed
(faster wrist: clip mean and 90th percentile, m/s) and reach (farther wrist from the trunk axis: mean and 90th
percentile, m) of :func:`generation.gesture.real_stats.motion_stats`, against the real captured range
(``generation/data/gesture_real_ranges.json``: Bandai Namco dataset 1 seated gestures, CC BY-NC 4.0) of the captured
emotion closest in valence-arousal-dominance (``protocol.vocabulary.GESTURE_VAD``, Euclidean) to the clip's emotion:
**before** = the network's output (``real_range: off``), **after** = with the default ``real_range: closest``
(:mod:`generation.gesture.range_fit`: the upper arms swung forward or back and the amplitude about the mean pose
scaled, by the smallest change that gets the clip into the range).

    OMP_NUM_THREADS=1 python -m benchmarks.bench_gesture_closest_range \
        [--json docs/benchmarks/gesture_closest_range.json]

About 10 s on the 2-core machine.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from generation.gesture.real_range import load_ranges

STATS = ("wrist_mean", "wrist_p90", "reach_mean", "reach_p90")


def plan_rows(plans=("demo", "seed003")) -> list[dict]:
    from generation.plans.clipgen import make_motion, resolve
    from generation.plans.schema import load_plan

    ranges = load_ranges()["ranges"]
    rows = []
    for plan in plans:
        for e in load_plan(plan).entries:
            if e.generator != "gesture_net":
                continue
            entry, _ = resolve(e)
            motion = make_motion(entry, fps=30.0)
            rec = motion.metadata.get("real_range")
            if rec is None:  # the fallback generator ran: nothing was fitted
                continue
            ref = rec["reference_emotion"]
            inside_before = {k: ranges[ref][k][0] <= rec["before"][k] <= ranges[ref][k][1] for k in STATS}
            inside = {k: ranges[ref][k][0] <= rec["after"][k] <= ranges[ref][k][1] for k in STATS}
            rows.append({"plan": plan, "id": e.id, "emotion": e.inputs["emotion_label"], "closest_captured": ref,
                         "factor": rec["factor"], "shoulder_flexion_deg": rec.get("shoulder_flexion_deg", 0.0),
                         "before": rec["before"], "stats": rec["after"],
                         "inside_before": inside_before, "inside": inside})
    return rows


def render(rows: list[dict], ranges: dict) -> str:
    lines = ["| plan | clip | emotion | closest captured | amplitude factor | shoulders forward (deg) | "
             + " | ".join(STATS) + " |", "|---|---|---|---|---|---|" + "---|" * len(STATS)]
    for r in rows:
        cells = []
        for k in STATS:
            lo, hi = ranges[r["closest_captured"]][k]
            mark = "" if r["inside"][k] else " **out**"
            changed = r["factor"] != 1.0 or r["shoulder_flexion_deg"] != 0.0
            was = f" (was {r['before'][k]:.3f})" if changed else ""
            cells.append(f"{r['stats'][k]:.3f}{was} [{lo:.3f}, {hi:.3f}]{mark}")
        lines.append(f"| {r['plan']} | {r['id']} | {r['emotion']} | {r['closest_captured']} | {r['factor']:.2f} | "
                     f"{r['shoulder_flexion_deg']:+.0f} | "
                     + " | ".join(cells) + " |")
    n = len(rows)
    inside_all = sum(all(r["inside"].values()) for r in rows)
    before = sum(all(r["inside_before"].values()) for r in rows)
    lines += ["", f"Clips with all four statistics inside the closest emotion's real range: before {before} of {n}, "
              f"after {inside_all} of {n}."]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default="docs/benchmarks/gesture_closest_range.json")
    args = ap.parse_args(argv)
    t0 = time.time()
    rows = plan_rows()
    ranges = load_ranges()["ranges"]
    res = {"date": "2026-12-06", "machine": "2-core shared CPU, no GPU", "rows": rows, "seconds": time.time() - t0}
    Path(args.json).write_text(json.dumps(res, indent=1) + "\n", encoding="utf-8")
    print(render(rows, ranges))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
