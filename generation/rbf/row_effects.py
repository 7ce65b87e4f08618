"""Which body part x axis x kind groups real styled walks change most: effect sizes to choose rows of our own from.

For a theme, every group of the paper's 11 body parts x X/Y/Z x tilt (posture) / swing (movement) is measured on
real takes as :mod:`generation.rbf.calibrate` measures a row's group (walker heights; tilt: mean offset relative to
the pelvis, swing: peak-to-peak), as if the theme had a row on it (:func:`candidate_feature`: the measure of a group
depends on which joints follow its part, which depends on the theme's other rows). Per dataset of the Bandai Namco
walks with the theme: the style's takes minus the same dataset's normal takes (per take: mean over its steady
cycles), and the effect size d = difference / pooled between-take standard deviation (takes' spread about
their own dataset-and-style mean, pooled over the style's and the normal takes of every dataset with the theme:
dataset 1 has one training take per style). A group is *consistent*
when every dataset with the theme moves it the same way.

Paired parts on X are measured outward ("R along -X, L along +X": positive = wider); other groups along +axis.
"""
from __future__ import annotations

import numpy as np

from . import calibrate as C
from .real_neutral import steady_cycles
from .themes import AXES, BODY_PARTS, OUTWARD, Feature, all_features

KINDS = ("tilt", "swing")


def candidate_feature(part: str, axis: str, kind: str, rank: int = 99) -> Feature:
    """A row on one group, signed so that its measure is positive for +axis (tilt; outward for a paired part on X)
    or for more swing; intensity 0.01 (only its group matters here)."""
    paired = len(BODY_PARTS[part]) == 2
    if kind == "tilt":
        sides = dict(OUTWARD) if paired and axis == "X" else {}
        return Feature(rank, part, axis, "tilt", 1, 1, 0.01, sides, source="ours")
    return Feature(rank, part, axis, "swing", 1, 2, 0.01, source="ours")


def all_groups() -> list[tuple[str, str, str]]:
    """Every (part, axis, kind) of the paper's body parts: 11 x 3 x 2 = 66, in BODY_PARTS order."""
    return [(p, a, k) for p in BODY_PARTS for a in AXES for k in KINDS]


def _feats_with(theme: str, group: tuple[str, str, str]) -> tuple[Feature, ...]:
    """The theme's rows (Table III and ours), plus a candidate row on ``group`` if none of them is on it."""
    feats = all_features(theme)
    if any((f.part, f.axis, f.kind) == group for f in feats):
        return feats
    return feats + (candidate_feature(*group),)


def group_sign(theme: str, group: tuple[str, str, str]) -> int:
    """+1, or -1 where the theme's own row on ``group`` is measured inward (its side signs point to the midline),
    so that every group's number reads as +axis / outward / more swing."""
    feats = _feats_with(theme, group)
    f = next(g for g in feats if (g.part, g.axis, g.kind) == group)
    if f.kind == "tilt" and f.side_signs and f.side_signs != OUTWARD:
        return -1
    return 1


def take_measures(clips: list, theme: str, groups: list, m: int = 100) -> dict[str, np.ndarray]:
    """{clip name: (G,) mean over the take's steady cycles of each group's measure, heights} for the walk takes of
    ``clips``; takes without a steady cycle are left out."""
    feats = {g: _feats_with(theme, g) for g in groups}
    signs = np.array([group_sign(theme, g) for g in groups])
    out = {}
    for c in clips:
        cycles = steady_cycles(c.motion, m, c.name)
        if not cycles:
            continue
        joints = tuple(c.motion.skeleton.joints)
        per = [[C.group_measure(cy.positions[:-1], joints, theme, g, feats[g]) for g in groups] for cy in cycles]
        out[c.name] = signs * np.mean(per, axis=0)
    return out


def group_effects(clips: list, theme: str, splits: tuple[str, ...] = ("train",), m: int = 100,
                  groups: list | None = None) -> list[dict]:
    """Real style-minus-normal difference and effect size of every group (default :func:`all_groups`) for ``theme``.

    Args:
        clips: CorpusClips (gait skeleton, content walk) of both datasets.
        splits: which takes (default train).

    Returns:
        one dict per group: part, axis, kind, covered (a row of the theme, Table III or ours, is on it), difference
        (mean over datasets, heights), effect (mean over datasets of d), consistent (same sign in every dataset),
        datasets: [{dataset, difference, effect, takes, normal_takes}].
    """
    groups = all_groups() if groups is None else groups
    styles = C.theme_styles(theme)
    covered = {(f.part, f.axis, f.kind) for f in all_features(theme)}
    per_ds, residuals = [], []
    for dataset in sorted({c.dataset for c in clips}):
        mine = [c for c in clips if c.dataset == dataset and c.split in splits and c.content == "walk"]
        themed = list(take_measures([c for c in mine if c.style in styles], theme, groups, m).values())
        normal = list(take_measures([c for c in mine if c.style == "normal"], theme, groups, m).values())
        if not themed or not normal:
            continue
        t, n = np.array(themed), np.array(normal)
        residuals += [t - t.mean(axis=0), n - n.mean(axis=0)]
        per_ds.append((dataset, t.mean(axis=0) - n.mean(axis=0), len(t), len(n)))
    dof = sum(len(r) for r in residuals) - len(residuals)
    if not per_ds or dof < 1:
        raise ValueError(f"no dataset has {theme} and normal walks in splits {list(splits)} (or too few takes)")
    pooled = np.maximum(np.sqrt(sum((r ** 2).sum(axis=0) for r in residuals) / dof), 1e-9)
    per_ds = [(ds, diff, diff / pooled, nt, nn) for ds, diff, nt, nn in per_ds]
    out = []
    for i, g in enumerate(groups):
        diffs = np.array([d[1][i] for d in per_ds])
        out.append({"part": g[0], "axis": g[1], "kind": g[2], "covered": g in covered,
                    "difference": float(diffs.mean()), "effect": float(np.mean([d[2][i] for d in per_ds])),
                    "consistent": bool(np.all(diffs > 0) or np.all(diffs < 0)),
                    "datasets": [{"dataset": d[0], "difference": float(d[1][i]), "effect": float(d[2][i]),
                                  "takes": d[3], "normal_takes": d[4]} for d in per_ds]})
    return out
