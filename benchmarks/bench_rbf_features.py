"""Seed 004 RBF styliser: effect of each theme on the 18 gait affective features, bone lengths, speed,
and the contact sheet docs/img/rbf_contact_sheet.png.

Run:  OMP_NUM_THREADS=1 python -m benchmarks.bench_rbf_features [--out docs/benchmarks/rbf_features.json]
          [--doc docs/benchmarks/rbf.md] [--sheet docs/img/rbf_contact_sheet.png] [--shapes docs/img/rbf_shapes.png]
          [--base real|procedural]

Writes its figures to the JSON (--out); with --doc it renders them into that page's ``rbf_features.*`` tables
(benchmarks/doc_tables.py; the narrative there is written by hand).

The neutral base is the shipped cycle averaged from real normal walks (``--base real``, the seed004 plan's default;
Bandai Namco, CC BY-NC 4.0, Kobayashi et al. 2023) or the averaged procedural walks (``--base procedural``).

For every theme at w = +0.7 and w = -0.7 (all ten features) it measures, over one cycle, the mean change of
each gait affective feature (generation.core.features.np_gait_affective_features) against the neutral base and
checks the expected directions listed in EXPECTATIONS. It also records the largest bone-length deviation of the
edited positions before and after they are put back onto the skeleton, the same numbers for
generation.core.ik.fit_positions_to_skeleton (direction-only projection) for comparison, the lowest foot height
(ground penetration) of both, and the time per stylised clip.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import torch

from benchmarks import doc_tables
from generation.core.features import GAIT_FEATURE_NAMES, foot_joints, np_gait_affective_features
from generation.rbf.neutral_base import neutral_cycle
from generation.rbf.real_neutral import load_cycle
from generation.rbf.stylise import PAPER_FEATURE_COUNTS, PAPER_WEIGHTS, stylise, stylised_cycle
from generation.rbf.themes import THEME_NAMES, THEMES

WEIGHTS = (0.7, -0.7)

# Expected directions at w = +0.7, from the features each theme uses (Table III); at w = -0.7 the opposite,
# except where marked one-sided. Feature indices (GAIT_FEATURE_NAMES): 4, 5 ang(head, neck, shoulder) shrink
# when the head pitches away from upright in either direction (so they only test +0.7 of sad and tired);
# 8 ang(right_toe, root, left_toe) and 14 d(left_toe, right_toe)/d(neck, root): how far apart the feet are;
# 9 ang(left_hip, left_knee, left_heel): knee angle, its minimum (peak swing flexion) falls with more knee lift
# (its range is not used: a lowered knee straightens the leg to pi at heel strike, which widens the range);
# 13 d(hand tips)/d(neck, root): hand separation, its range grows with the arm swing. "mean" compares cycle
# means (posture), "range" peak-to-peak ranges over the cycle (movement), "min" the cycle minima.
# Each entry: (feature index, aggregate, sign at +0.7, also checked at -0.7, reason).
FEATURE_EXPECTATIONS = {
    "happy": [(13, "range", +1, True, "wrists swing more along Z and X: hands further apart at the extremes"),
              (9, "min", -1, True, "knees swing more along Y: more knee flexion in swing")],
    "sad": [(4, "mean", -1, False, "head and neck tilted down and forward"),
            (5, "mean", -1, False, "head and neck tilted down and forward")],
    "energetic": [(13, "range", +1, True, "elbows, shoulders and wrists swing more: hands further apart"),
                  (9, "min", -1, True, "knees swing more along Y: more knee flexion in swing")],
    "tired": [(4, "mean", -1, False, "head tilted down and forward"),
              (14, "range", -1, True, "decreased ankle swing along Z: shorter toe separation range")],
    "feminine": [(14, "mean", -1, True, "ankles and knees tilted towards the midline: feet closer"),
                 (8, "mean", -1, True, "ankles and knees tilted towards the midline: narrower toe angle")],
    "masculine": [(14, "mean", +1, True, "ankles and knees tilted outwards: feet further apart"),
                  (8, "mean", +1, True, "ankles and knees tilted outwards: wider toe angle")],
}


def _j(skel, name):
    return skel.index(name)


def _pair(skel, base):
    return _j(skel, "left_" + base), _j(skel, "right_" + base)


# Direct geometric measures in the walker frame (metres), unambiguous in sign; (m, J, 3) -> float.
MEASURES = {
    "head_height": lambda P, s: float(P[:, _j(s, "head"), 1].mean()),
    "head_forward": lambda P, s: float((P[:, _j(s, "head"), 2] - P[:, _j(s, "root"), 2]).mean()),
    "hand_swing_z": lambda P, s: float(np.mean([np.ptp(P[:, j, 2] - P[:, 0, 2]) for j in _pair(s, "hand")])),
    "elbow_swing_z": lambda P, s: float(np.mean([np.ptp(P[:, j, 2] - P[:, 0, 2]) for j in _pair(s, "elbow")])),
    "elbow_width": lambda P, s: float(np.mean(P[:, _j(s, "left_elbow"), 0] - P[:, _j(s, "right_elbow"), 0])),
    "heel_width": lambda P, s: float(np.mean(P[:, _j(s, "left_heel"), 0] - P[:, _j(s, "right_heel"), 0])),
    "heel_swing_z": lambda P, s: float(np.mean([np.ptp(P[:, j, 2] - P[:, 0, 2]) for j in _pair(s, "heel")])),
    "heel_lift": lambda P, s: float(np.mean([np.ptp(P[:, j, 1]) for j in _pair(s, "heel")])),
    "knee_lift": lambda P, s: float(np.mean([np.ptp(P[:, j, 1]) for j in _pair(s, "knee")])),
    "hip_sway_x": lambda P, s: float(np.ptp(P[:, 0, 0])),
}
MEASURE_EXPECTATIONS = {
    "happy": [("hand_swing_z", +1), ("knee_lift", +1), ("hip_sway_x", +1), ("head_forward", -1)],
    "sad": [("head_height", -1), ("head_forward", +1)],
    "energetic": [("knee_lift", +1), ("hand_swing_z", +1), ("elbow_swing_z", +1)],
    "tired": [("head_height", -1), ("head_forward", +1), ("heel_swing_z", -1), ("heel_lift", -1)],
    "feminine": [("hip_sway_x", +1), ("heel_width", -1)],
    "masculine": [("heel_width", +1), ("elbow_width", +1), ("heel_lift", +1), ("elbow_swing_z", +1)],
}

LEFT_COLOR, RIGHT_COLOR, MID_COLOR = "#1f5fbf", "#c0392b", "#222222"


def feature_change(neutral_pos: np.ndarray, styled_pos: np.ndarray) -> dict:
    """Mean and range changes of the 18 features over one cycle: (m, 21, 3) x 2 -> dict of (18,) arrays."""
    f0 = np_gait_affective_features(neutral_pos)
    f1 = np_gait_affective_features(styled_pos)
    return {"mean": f1.mean(0) - f0.mean(0), "range": np.ptp(f1, 0) - np.ptp(f0, 0), "min": f1.min(0) - f0.min(0),
            "neutral_mean": f0.mean(0), "neutral_range": np.ptp(f0, 0)}


def evaluate(nc) -> dict:
    from generation.core.ik import fit_positions_to_skeleton

    skel = nc.skeleton
    feet = sum(foot_joints(skel), [])
    neutral_pos = nc.positions()
    base_floor = float(neutral_pos[:, feet, 1].min())
    rows = []
    for theme in THEME_NAMES:
        for w in WEIGHTS:
            r = stylised_cycle(nc, theme, w, 10)
            change = feature_change(r["P"], r["positions"])
            direction_only, _, after_ik = fit_positions_to_skeleton(r["Y"], skel)
            checks = []
            for idx, agg, sign, both, reason in FEATURE_EXPECTATIONS[theme]:
                if w < 0 and not both:
                    continue
                expected = sign if w > 0 else -sign
                value = float(change[agg][idx])
                checks.append({"feature": GAIT_FEATURE_NAMES[idx], "index": idx, "aggregate": agg,
                               "expected_sign": expected, "change": value,
                               "holds": bool(np.sign(value) == expected), "reason": reason})
            measures = []
            for name, sign in MEASURE_EXPECTATIONS[theme]:
                expected = sign if w > 0 else -sign
                value = MEASURES[name](r["positions"], skel) - MEASURES[name](r["P"], skel)
                measures.append({"measure": name, "expected_sign": expected, "change_m": value,
                                 "holds": bool(np.sign(value) == expected)})
            rows.append({
                "theme": theme, "weight": w,
                "mean_change": change["mean"].tolist(), "range_change": change["range"].tolist(),
                "bone_error_before_m": r["before"], "bone_error_after_m": r["after"],
                "fit_residual_max_m": r["residual"],
                "ik_direction_only_after_m": after_ik,
                "lowest_foot_m": float(r["positions"][:, feet, 1].min()) - base_floor,
                "lowest_foot_direction_only_m": float(direction_only[:, feet, 1].min()) - base_floor,
                "ground_lift_m": r["ground_lift"],
                "checks": checks, "measures": measures,
            })
    return {"rows": rows, "neutral_mean": feature_change(neutral_pos, neutral_pos)["neutral_mean"].tolist(),
            "feature_names": list(GAIT_FEATURE_NAMES)}


def timing(nc, build, repeats: int = 7) -> dict:
    """Median wall time of one 4-cycle 30 fps clip (all ten happy features) and of ``build()``ing the neutral base."""
    stylise(nc, "happy", 0.7, 10)  # warm-up
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        clip = stylise(nc, "happy", 0.7, 10, speed=1.0, n_cycles=4, fps=30.0)
        times.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    build()
    base = time.perf_counter() - t0
    return {"stylise_clip_s": float(np.median(times)), "clip_frames": clip.num_frames, "neutral_base_s": base}


def scaling(nc) -> dict:
    """Mean joint displacement from the neutral (cm, fitted skeleton) for the Fig. 7 grid of w x n."""
    out = {}
    for theme in THEME_NAMES:
        grid = []
        for n in PAPER_FEATURE_COUNTS:
            row = []
            for w in PAPER_WEIGHTS:
                r = stylised_cycle(nc, theme, w, n)
                row.append(float(np.linalg.norm(r["positions"] - r["P"], axis=-1).mean() * 100))
            grid.append(row)
        out[theme] = grid
    return out


def summary(result: dict) -> dict:
    """Over every theme and weight: expected directions that hold, the failures, the largest bone-length deviation
    before and after the fit (m) and the lowest foot joint relative to the neutral floor (m)."""
    rows = result["rows"]
    return {"checks_held": sum(c["holds"] for r in rows for c in r["checks"]),
            "checks": sum(len(r["checks"]) for r in rows),
            "measures_held": sum(c["holds"] for r in rows for c in r["measures"]),
            "measures": sum(len(r["measures"]) for r in rows),
            "failed": [f"{r['theme']} w = {r['weight']:+.1f}: {c.get('feature', c.get('measure'))}"
                       for r in rows for k in ("checks", "measures") for c in r[k] if not c["holds"]],
            "bone_error_before_max_m": max(r["bone_error_before_m"] for r in rows),
            "bone_error_after_max_m": max(r["bone_error_after_m"] for r in rows),
            "lowest_foot_m": min(r["lowest_foot_m"] for r in rows),
            "lowest_foot_direction_only_m": min(r["lowest_foot_direction_only_m"] for r in rows)}


# ---- contact sheet --------------------------------------------------------------------------------
def _bones(skel):
    out = []
    for j, p in enumerate(skel.parents):
        if p < 0:
            continue
        name = skel.joints[j]
        color = LEFT_COLOR if name.startswith("left_") else RIGHT_COLOR if name.startswith("right_") else MID_COLOR
        out.append((p, j, color))
    return out


def _draw(ax, pos, bones, a, b, shift=0.0, alpha=1.0):
    for p, j, color in bones:
        ax.plot([pos[p, a] + shift, pos[j, a] + shift], [pos[p, b], pos[j, b]], color=color, lw=1.4, alpha=alpha,
                solid_capstyle="round")
    ax.plot(pos[12, a] + shift, pos[12, b], "o", ms=4, color=MID_COLOR, alpha=alpha)


def contact_sheet(nc, path: Path, weight: float = 0.7, n_poses: int = 5) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    skel = nc.skeleton
    bones = _bones(skel)
    m = nc.num_frames
    frames = np.linspace(0, m, n_poses, endpoint=False).astype(int)
    cols = [("neutral", None), (f"w = +{weight}", weight), (f"w = -{weight}", -weight)]
    fig = plt.figure(figsize=(18, 3.1 * len(THEME_NAMES)), dpi=100)
    outer = fig.add_gridspec(len(THEME_NAMES), 3, wspace=0.06, hspace=0.25)
    for row, theme in enumerate(THEME_NAMES):
        for col, (label, w) in enumerate(cols):
            pos = stylised_cycle(nc, theme, 0.0 if w is None else w, 10)["positions"]  # walker frame
            inner = outer[row, col].subgridspec(1, 2, width_ratios=[3.2, 1], wspace=0.02)
            side = fig.add_subplot(inner[0])
            front = fig.add_subplot(inner[1])
            for k, f in enumerate(frames):
                _draw(side, pos[f], bones, 2, 1, shift=0.55 * k)  # side view: z right, y up
            for f in frames[[0, 2]]:
                _draw(front, pos[f], bones, 0, 1, alpha=0.9 if f == frames[0] else 0.45)
            for ax in (side, front):
                ax.set_aspect("equal")
                ax.set_xticks([])
                ax.set_yticks([])
                ax.set_ylim(-0.05, 1.95)
                for s in ax.spines.values():
                    s.set_visible(False)
            side.set_xlim(-0.55, 0.55 * (n_poses - 1) + 0.55)
            front.set_xlim(-0.5, 0.5)
            side.axhline(0.0, color="#999999", lw=0.6)
            front.axhline(0.0, color="#999999", lw=0.6)
            title = f"{theme}: {label}" if w is not None else f"{theme} row: neutral base"
            side.set_title(title, fontsize=9, loc="left")
            front.set_title("front", fontsize=7)
    fig.suptitle("Seed 004 RBF themes (10 features) on the averaged neutral cycle: side view at 5 phases "
                 "(walker frame, z to the right) and front view; blue = left, red = right", fontsize=11)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)


def shapes_figure(path: Path) -> None:
    """Fig. 4 analogue: the four common shapes and their mirrored versions."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from generation.rbf.basis import mirrored, rbf, shape_params

    t = np.arange(100.0)
    specs = [(1, ()), (2, (40.0,)), (3, (25.0, 75.0)), (4, (25.0, 75.0))]
    names = ["type 1: posture offset", "type 2: one bump", "type 3: two bumps", "type 4: opposing extrema"]
    fig, axes = plt.subplots(1, 4, figsize=(14, 2.8), dpi=110, sharey=True)
    for ax, (shape, mus), name in zip(axes, specs, names):
        params = shape_params(shape, 1.0, mus)
        for i, (a, mu, s2) in enumerate(params):
            ax.plot(t, a * rbf(t, mu, s2, period=100), color=("#1f77b4", "#2ca02c")[i], lw=1.2)
        total = sum(a * rbf(t, mu, s2, period=100) for a, mu, s2 in params)
        mirror = sum(a * rbf(t, mu, s2, period=100) for a, mu, s2 in mirrored(params))
        ax.plot(t, total, color="#d62728", lw=2.0, label="sum")
        ax.plot(t, mirror, color="#d62728", lw=1.0, ls="--", label="mirrored (-alpha)")
        ax.axhline(0, color="#999999", lw=0.6)
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("frame of the 100-frame cycle")
    axes[0].set_ylabel("displacement / alpha")
    axes[0].legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def print_report(result: dict) -> None:
    """The console summary: bone errors and floor per theme and weight, every check, the totals and the timing."""
    base, s, t = result["neutral_base"], result["summary"], result["timing"]
    print(f"neutral base: {base['n_cycles']} cycles, IK error {base['ik_error_max_m'] * 1000:.1f} mm")
    print("theme       w     bone err before -> after (mm)   ik.fit after   lowest foot ours / direction-only (mm)")
    for row in result["rows"]:
        print(f"{row['theme']:10s} {row['weight']:+.1f}   {row['bone_error_before_m'] * 1000:7.1f} -> "
              f"{row['bone_error_after_m'] * 1000:.1e}     {row['ik_direction_only_after_m'] * 1000:.1e}      "
              f"{row['lowest_foot_m'] * 1000:+6.1f} / {row['lowest_foot_direction_only_m'] * 1000:+6.1f}")
        for c in row["checks"]:
            print(f"    {c['aggregate']:5s} {c['feature']:28s} expected {c['expected_sign']:+d} "
                  f"change {c['change']:+.4f} {'OK' if c['holds'] else 'FAILS'}")
        for c in row["measures"]:
            print(f"    {c['measure']:34s} expected {c['expected_sign']:+d} "
                  f"change {c['change_m'] * 1000:+.1f} mm {'OK' if c['holds'] else 'FAILS'}")
    print(f"expected directions hold (18 gait features): {s['checks_held']}/{s['checks']}")
    print(f"expected directions hold (direct measures): {s['measures_held']}/{s['measures']}")
    print(f"timing: stylise 4-cycle clip {t['stylise_clip_s'] * 1000:.1f} ms ({t['clip_frames']} frames), "
          f"neutral base {t['neutral_base_s']:.2f} s")


def main(argv=None) -> int:
    import datetime
    import os
    import platform
    import shlex

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=doc_tables.area_files("rbf_features")[0],
                        help="write all numbers as JSON here")
    parser.add_argument("--doc", type=Path, default=None, help="render the rbf_features tables marked in this page")
    parser.add_argument("--sheet", type=Path, default=Path("docs/img/rbf_contact_sheet.png"))
    parser.add_argument("--shapes", type=Path, default=Path("docs/img/rbf_shapes.png"))
    parser.add_argument("--base", choices=("real", "procedural"), default="real",
                        help="neutral base: averaged real normal walks (shipped) or averaged procedural walks")
    args = parser.parse_args(argv)
    torch.set_num_threads(1)
    warnings.filterwarnings("ignore", message="The given NumPy array is not writable")
    build = load_cycle if args.base == "real" else neutral_cycle
    nc = build()
    threads = f"OMP_NUM_THREADS={os.environ['OMP_NUM_THREADS']} " if "OMP_NUM_THREADS" in os.environ else ""
    result = {"machine": f"{platform.machine()} {platform.system()}, {os.cpu_count()} CPUs (shared), no GPU",
              "date": datetime.date.today().isoformat(),
              "command": threads + shlex.join(["python", "-m", "benchmarks.bench_rbf_features",
                                               *(sys.argv[1:] if argv is None else argv)]),
              **evaluate(nc)}
    result["summary"] = summary(result)
    result["base_function"] = ("generation.rbf.real_neutral.load_cycle()" if args.base == "real"
                               else "generation.rbf.neutral_base.neutral_cycle()")
    result["timing"] = timing(nc, build)
    result["neutral_base"] = {k: v for k, v in nc.metadata.items()}
    result["movement_share_top10"] = {t: 100.0 * sum(f.kind == "swing" for f in THEMES[t]) / 10 for t in THEMES}
    result["scaling"] = scaling(nc)
    result["scaling_axes"] = {"n": list(PAPER_FEATURE_COUNTS), "w": list(PAPER_WEIGHTS)}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {args.out}")
    if args.doc:
        print(f"{args.doc} tables:", ", ".join(doc_tables.update_doc("rbf_features", args.out, args.doc))
              or "none marked")
    args.sheet.parent.mkdir(parents=True, exist_ok=True)
    contact_sheet(nc, args.sheet)
    shapes_figure(args.shapes)
    print_report(result)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
