"""Foot planting of the RBF-styled walks (generation.rbf.stylise.plant_walk_feet): quality before/after and how
much of each theme feature survives.

    python -m benchmarks.bench_rbf_feet

Per clip (paper settings, 4 cycles at 25 fps): foot skate and penetration before -> after; for every Table III
feature the RMS displacement from the neutral walk along the feature's axis on the feature's joints (mm),
unplanted styled vs unplanted neutral -> planted styled vs planted neutral; and the distance of the 18 affective
gait features (time means) from the neutral walk's, before -> after. Synthetic neutral base (procedural).
"""
from __future__ import annotations

import sys

import numpy as np

from generation.core.features import affective_features
from generation.quality.metrics import motion_metrics
from generation.rbf.neutral_base import neutral_cycle
from generation.rbf.stylise import neutral_walk, stylise
from generation.rbf.themes import AXES, BODY_PARTS, theme_features

CASES = (("tired", 1.0, 7), ("tired", 0.4, 4), ("tired", -0.7, 10), ("energetic", 1.3, 10),
         ("masculine", -0.7, 10), ("happy", 1.3, 10), ("sad", 1.0, 10), ("feminine", 1.3, 10))
FPS = 25.0


def feature_rms_mm(styled: np.ndarray, base: np.ndarray, skeleton, feature) -> float:
    """RMS displacement (mm) of the feature's joints along its axis between two (T, J, 3) walks."""
    joints = [skeleton.index(n) for n in BODY_PARTS[feature.part]]
    d = styled[:, joints, AXES[feature.axis]] - base[:, joints, AXES[feature.axis]]
    return 1000.0 * float(np.sqrt((d ** 2).mean()))


def case_row(nc, theme: str, weight: float, n: int) -> str:
    sk = nc.skeleton
    base = {p: neutral_walk(nc, fps=FPS, plant=p) for p in (False, True)}
    styled = {p: stylise(nc, theme, weight, n, fps=FPS, plant=p) for p in (False, True)}
    pos = {k: {p: m.positions() for p, m in d.items()} for k, d in (("base", base), ("styled", styled))}
    q = {p: motion_metrics(styled[p]) for p in (False, True)}
    feats = []
    for f in theme_features(theme, n):
        a = feature_rms_mm(pos["styled"][False], pos["base"][False], sk, f)
        b = feature_rms_mm(pos["styled"][True], pos["base"][True], sk, f)
        feats.append(f"{f.rank}:{f.part}/{f.axis} {a:.0f}->{b:.0f}")
    aff = [np.linalg.norm(affective_features(pos["styled"][p], sk).mean(0) - affective_features(
        pos["base"][p], sk).mean(0)) for p in (False, True)]
    return (f"| {theme} w{weight} n{n} | {q[False]['foot_skate_cm_s']:.1f} -> {q[True]['foot_skate_cm_s']:.1f} | "
            f"{q[False]['penetration_cm']:.2f} -> {q[True]['penetration_cm']:.2f} | {aff[0]:.3f} -> {aff[1]:.3f} | "
            f"{'; '.join(feats)} |")


def main() -> int:
    nc = neutral_cycle()
    print("| clip | skate cm/s | penetration cm | affective-feature distance from neutral | "
          "feature RMS displacement from neutral, mm (rank:part/axis before->after) |")
    print("|---|---|---|---|---|")
    for theme, w, n in CASES:
        print(case_row(nc, theme, w, n))
    return 0


if __name__ == "__main__":
    sys.exit(main())
