"""Calibrated intensities of seed 004's expert features: w = 1 reproduces real actors' style differences.

The experts' features (Table III: body part, axis, posture or movement, sign, Fig. 4 shape) are kept; only their
amplitudes are fitted, on real capture (Bandai Namco Research Motion Dataset 1 and 2, Kobayashi et al. 2023,
arXiv:2306.08861, CC BY-NC 4.0; straight walks):

1. **Measures.** Table III's rows of a theme fall into groups of one body part x axis x kind (masculine's two
   "Shoulders: increased swing along Z" rows are one group). A group's measure on one cycle (m, J, 3) in walker
   heights, walker's frame (:func:`group_measure`): for each joint of the part its trajectory on the axis (relative to
   the pelvis; the pelvis itself as it is), then for a posture feature the cycle mean (times the side's sign for
   "R along +X, L along -X" rows) and for a movement feature the peak-to-peak; averaged over the part's joints and
   the joints that follow them on that axis (:func:`_group_sides`: a shoulder's swing along Z carries the arm).
2. **Real difference** (:func:`real_differences`): per dataset, the mean over the themed takes of the per-take mean
   of per-cycle measures (steady cycles, :func:`generation.rbf.real_neutral.steady_cycles`) minus the same for the
   same dataset's normal walks (the corpus has no actor ids; a dataset's takes come from its own actors), averaged
   over the datasets that have the theme. Computed separately on the training split (to fit) and on the held-out
   takes (val and test, to check).
3. **Fit** (:func:`calibrate_theme`): one non-negative factor per group multiplying the visual intensities of its
   rows, fitted by bounded non-linear least squares on the measures of the stylised cycle after the skeleton fit
   (:func:`generation.rbf.stylise.stylised_cycle` on the neutral base, w = 1) against the training targets. A
   factor is capped at :data:`MAX_FACTOR`. Where the real actors move the other way
   than the experts' sign, the factor is 0 (the feature is kept, at zero amplitude) and the row says so.

The result (:func:`calibrate`) is the JSON of :data:`generation.rbf.themes.CALIBRATED_PATH`, with the licence and
citation of the data, every row's visual and calibrated intensity, the training and held-out real differences and
the w = 1 difference reached.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from generation.core.skeleton import GAIT_JOINTS, gait_skeleton
from protocol.vocabulary import CAPTURE_THEMES

from .data_features import _rounded
from .neutral_base import NormalisedCycle, normalise_cycle
from .observer import walker_of
from .real_neutral import steady_cycles
from .stylise import stylised_cycle
from .themes import BODY_PARTS, THEME_NAMES, THEMES, Feature

MODELLED = frozenset(j for joints in BODY_PARTS.values() for j in joints)  # the paper's 18 joints
MAX_FACTOR = 6.0  # no calibrated amplitude more than 6x the visual one (keeps a walk a walk)
MEASURE_FLOOR = 0.005  # heights (9 mm at 1.75 m): residuals of smaller real differences count as this large
MAX_EVALUATIONS = 200
HELDOUT_SPLITS = ("val", "test")


def theme_groups(theme: str, feats: tuple[Feature, ...] | None = None) -> list[tuple[str, str, str]]:
    """(part, axis, kind) groups of a theme's Table III rows (or of ``feats``), in first-rank order."""
    return list(dict.fromkeys((f.part, f.axis, f.kind) for f in (THEMES[theme] if feats is None else feats)))


def _group_sides(theme: str, group: tuple[str, str, str], feats: tuple[Feature, ...] | None = None
                 ) -> dict[str, int]:
    """joint -> sign of a group's measure: the part's joints (per-side sign for "R along +X, L along -X" rows, else
    +1) and the joints that follow them on that axis when the edit is applied (their children without an edit of
    their own on that axis in this theme, transitively; not the pelvis's children: see
    :func:`generation.rbf.stylise.rbf_displacement`), so the measure covers what the feature moves: a shoulder's
    swing along Z carries the arm."""
    rows = THEMES[theme] if feats is None else feats
    f: Feature = [g for g in rows if (g.part, g.axis, g.kind) == group][0]
    if f.kind == "tilt" and f.side_signs:
        signs = {j: s for j, s in f.joint_signs()}
    else:
        signs = {j: 1 for j in BODY_PARTS[f.part]}
    edited = {(j, g.axis) for g in rows for j in BODY_PARTS[g.part]}
    names, parents = GAIT_JOINTS, gait_skeleton().parents
    for j, p in enumerate(parents):
        if p > 0 and names[p] in signs and names[j] not in signs and names[j] in MODELLED \
                and (names[j], f.axis) not in edited:
            signs[names[j]] = signs[names[p]]
    return signs


def group_measure(positions: np.ndarray, joints: tuple[str, ...], theme: str, group: tuple[str, str, str],
                  feats: tuple[Feature, ...] | None = None) -> float:
    """A group's measure on one cycle (see the module docstring), in walker heights.

    Args:
        positions: (m, J, 3) one cycle in the walker's frame divided by the walker's height.
        joints: joint names in ``positions``' order.
        feats: the theme's rows (default Table III's; :mod:`generation.rbf.extended` adds ours).
    """
    part, axis, kind = group
    a = "XYZ".index(axis)
    root = joints.index("root")
    values = []
    for joint, sign in _group_sides(theme, group, feats).items():
        j = joints.index(joint)
        traj = positions[:, j, a] if j == root else positions[:, j, a] - positions[:, root, a]
        values.append(sign * float(traj.mean()) if kind == "tilt" else float(np.ptp(traj)))
    return float(np.mean(values))


def theme_measures(positions: np.ndarray, joints: tuple[str, ...], theme: str,
                   feats: tuple[Feature, ...] | None = None) -> np.ndarray:
    """(G,) measures of all of a theme's groups (:func:`theme_groups` order) on one cycle (m, J, 3) in heights."""
    return np.array([group_measure(positions, joints, theme, g, feats) for g in theme_groups(theme, feats)])


def _take_measures(clip, theme: str, m: int, feats: tuple[Feature, ...] | None = None) -> np.ndarray | None:
    cycles = steady_cycles(clip.motion, m, clip.name)
    if not cycles:
        return None
    joints = tuple(clip.motion.skeleton.joints)
    return np.mean([theme_measures(c.positions[:-1], joints, theme, feats) for c in cycles], axis=0)


def theme_styles(theme: str) -> tuple[str, ...]:
    """Corpus styles that stand for ``theme`` (``protocol.vocabulary.CAPTURE_THEMES``)."""
    return tuple(s for s, t in CAPTURE_THEMES.items() if t == theme)


def real_differences(clips: list, theme: str, splits: tuple[str, ...], m: int = 100,
                     feats: tuple[Feature, ...] | None = None) -> tuple[np.ndarray, list[dict]]:
    """(G,) real style-minus-normal differences of ``theme``'s group measures on the takes of ``splits``.

    Args:
        clips: CorpusClips (gait skeleton, straight walks) of both datasets, any split.
        feats: the theme's rows (default Table III's).

    Returns:
        the differences (mean over datasets that have the theme in ``splits``) and per dataset {dataset, styles,
        takes, normal_takes, normal_splits, difference}. A dataset without a normal take with cycles in ``splits``
        uses its normal takes of all splits (``normal_splits`` says which).

    Raises:
        ValueError: when no dataset has themed and normal takes with steady cycles in ``splits``.
    """
    styles = theme_styles(theme)
    diffs, info = [], []
    for dataset in sorted({c.dataset for c in clips}):
        mine = [c for c in clips if c.dataset == dataset and c.split in splits and c.content == "walk"]
        themed = [v for v in (_take_measures(c, theme, m, feats) for c in mine if c.style in styles) if v is not None]
        normal = [v for v in (_take_measures(c, theme, m, feats) for c in mine if c.style == "normal") if v is not None]
        normal_splits = list(splits)
        if themed and not normal:
            # dataset 1's one held-out normal take is 1 s long (no cycle): its actor's other normal take stands in
            normal = [v for v in (_take_measures(c, theme, m, feats) for c in clips if c.dataset == dataset
                                  and c.content == "walk" and c.style == "normal") if v is not None]
            normal_splits = sorted({c.split for c in clips if c.dataset == dataset and c.style == "normal"})
        if not themed or not normal:
            continue
        d = np.mean(themed, axis=0) - np.mean(normal, axis=0)
        diffs.append(d)
        info.append({"dataset": dataset, "styles": sorted({c.style for c in mine if c.style in styles}),
                     "takes": len(themed), "normal_takes": len(normal), "normal_splits": normal_splits,
                     "difference": d.tolist()})
    if not diffs:
        raise ValueError(f"no dataset has {theme} (styles {list(styles)}) and normal walks in splits {list(splits)}")
    return np.mean(diffs, axis=0), info


def clip_cycles(clip, m: int = 100) -> tuple[list[NormalisedCycle], str]:
    """A clip's cycles and how they were cut: its steady cycles (``steady``); else, for a clip that is one cycle
    repeated (metadata ``loop_period_frames`` p, the BML walks), the frames 0..p as one cycle with its midpoint as
    the right strike (``loop``; tilt means and swing peak-to-peaks do not depend on where the cycle starts); else
    ([], ``none``)."""
    cycles = steady_cycles(clip.motion, m, clip.name)
    if cycles:
        return cycles, "steady"
    p = int(clip.motion.metadata.get("loop_period_frames") or 0)
    if 2 <= p < clip.motion.num_frames:
        motion = clip.motion
        return [normalise_cycle(motion.positions(), motion.skeleton, motion.fps, (0, p // 2, p), m, clip.name)], "loop"
    return [], "none"


def walker_differences(clips: list, theme: str, styles: tuple[str, ...], neutral: tuple[str, ...] = ("neutral",),
                       m: int = 100, feats: tuple[Feature, ...] | None = None) -> list[dict]:
    """Per walker (:func:`generation.rbf.observer.walker_of`) with walks of ``styles`` and of ``neutral``: its
    styled minus its own neutral walks, on ``theme``'s group measures and tempo (cycles: :func:`clip_cycles`).

    Returns [{"walker", "difference": (G,) list, walker heights, "speed_ratio", "stride_ratio", "cadence_ratio"
    (styled / neutral; speed = stride / duration, cadence = 1 / duration), "cycles": {clip name: how cut}}], sorted
    by walker.
    """
    per: dict[str, dict[str, list]] = {}
    for c in clips:
        if c.content != "walk" or c.style not in styles + neutral:
            continue
        cycles, how = clip_cycles(c, m)
        if not cycles:
            continue
        joints = tuple(c.motion.skeleton.joints)
        measures = np.mean([theme_measures(cy.positions[:-1], joints, theme, feats) for cy in cycles], axis=0)
        gait = (np.mean([cy.stride for cy in cycles]), np.mean([cy.duration_s for cy in cycles]))
        key = "styled" if c.style in styles else "neutral"
        per.setdefault(walker_of(c), {"styled": [], "neutral": [], "cycles": {}})
        per[walker_of(c)][key].append((measures, gait))
        per[walker_of(c)]["cycles"][c.name] = how
    out = []
    for walker in sorted(per):
        d = per[walker]
        if not d["styled"] or not d["neutral"]:
            continue
        (s_t, d_t), (s_n, d_n) = (np.mean([g for _, g in d[k]], axis=0) for k in ("styled", "neutral"))
        diff = np.mean([x for x, _ in d["styled"]], axis=0) - np.mean([x for x, _ in d["neutral"]], axis=0)
        out.append({"walker": walker, "difference": diff.tolist(), "speed_ratio": float((s_t / d_t) / (s_n / d_n)),
                    "stride_ratio": float(s_t / s_n), "cadence_ratio": float(d_n / d_t), "cycles": d["cycles"]})
    return out


def _intensities(theme: str, factors: np.ndarray) -> dict[int, float]:
    groups = theme_groups(theme)
    return {f.rank: f.intensity * float(factors[groups.index((f.part, f.axis, f.kind))]) for f in THEMES[theme]}


def generated_measures(base: Motion, theme: str, intensities, weight: float = 1.0,
                       feats: tuple[Feature, ...] | None = None, bent_arms: bool | None = None) -> np.ndarray:
    """(G,) group measures of the stylised cycle minus the base's, heights (skeleton fit, no foot planting);
    ``feats``: whose groups to measure (default Table III's); ``bent_arms``: as
    :func:`generation.rbf.stylise.stylised_cycle` (default: with the ``extended`` and ``pooled`` sets)."""
    out = stylised_cycle(base, theme, weight, len(THEMES[theme]), intensities=intensities, bent_arms=bent_arms)
    joints = tuple(base.skeleton.joints)
    h = base.skeleton.height
    return (theme_measures(out["positions"] / h, joints, theme, feats)
            - theme_measures(out["P"] / h, joints, theme, feats))


def calibrate_theme(base: Motion, theme: str, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Non-negative factors (G,) on the visual intensities whose w = 1 edit reaches ``target`` (G,) heights.

    Bounded non-linear least squares (scipy ``least_squares``, factors in [0, :data:`MAX_FACTOR`]) on the measures
    of the fitted cycle (bones cannot stretch, so a head moved forward also drops: the measures are not linear in
    the factors), each residual divided by max(|target|, :data:`MEASURE_FLOOR`), started from the non-negative
    linear solution of the gain matrix. Returns the factors and the measures reached (G,).
    """
    from scipy.optimize import least_squares, nnls

    groups = theme_groups(theme)
    n = len(groups)
    G = np.zeros((n, n))
    for h in range(n):
        one = np.zeros(n)
        one[h] = 1.0
        G[:, h] = generated_measures(base, theme, _intensities(theme, one))
    scale = np.maximum(np.abs(target), MEASURE_FLOOR)
    x0 = np.clip(nnls(G / scale[:, None], target / scale)[0], 1e-3, MAX_FACTOR - 1e-3)
    fit = least_squares(lambda x: (generated_measures(base, theme, _intensities(theme, x)) - target) / scale, x0,
                        bounds=(0.0, MAX_FACTOR), diff_step=1e-2, xtol=1e-4, ftol=1e-4, max_nfev=MAX_EVALUATIONS)
    factors = fit.x
    return factors, generated_measures(base, theme, _intensities(theme, factors))


def calibrate(clips: list, base: Motion, m: int = 100) -> dict:
    """Calibrated intensities of all six themes: the JSON-ready dict of
    :data:`generation.rbf.themes.CALIBRATED_PATH` (see the module docstring)."""
    first = clips[0].motion.metadata if clips else {}
    themes = {}
    for theme in THEME_NAMES:
        groups = theme_groups(theme)
        train, train_info = real_differences(clips, theme, ("train",), m)
        heldout, held_info = real_differences(clips, theme, HELDOUT_SPLITS, m)
        factors, reached = calibrate_theme(base, theme, train)
        visual = generated_measures(base, theme, "visual")
        calibrated = _intensities(theme, factors)
        alone = [generated_measures(base, theme, _intensities(theme, np.eye(len(groups))[i]))[i]
                 for i in range(len(groups))]  # each group's own change at its visual intensity
        rows = []
        for f in THEMES[theme]:
            g = groups.index((f.part, f.axis, f.kind))
            rows.append({"rank": f.rank, "feature": f.describe(), "group": g, "visual": f.intensity,
                         "calibrated": calibrated[f.rank], "factor": float(factors[g])})
        group_rows = [{"part": p, "axis": a, "kind": k, "measure": "mean offset" if k == "tilt" else "peak-to-peak",
                       "real_train": float(train[i]), "real_heldout": float(heldout[i]),
                       "visual_w1": float(visual[i]), "calibrated_w1": float(reached[i]),
                       "expert_sign_agrees": bool(train[i] * alone[i] > 0)}
                      for i, (p, a, k) in enumerate(groups)]
        themes[theme] = {"features": rows, "groups": group_rows,
                         "sources": {"train": train_info, "heldout": held_info}}
    return {"method": "generation.rbf.calibrate: per body part x axis x kind, non-negative factors on the visual "
                      "intensities so that w = 1 reproduces real style-minus-normal differences (train split)",
            "units": "intensity: amplitude / walker height; measures: walker heights",
            "base": base.metadata.get("generator", "") + (" (real)" if base.metadata.get("captured_base") else ""),
            "max_factor": MAX_FACTOR, "fit_split": "train", "check_splits": list(HELDOUT_SPLITS),
            "licence": first.get("licence", "CC BY-NC 4.0"), "citation": first.get("citation", ""),
            "dataset_url": first.get("source_url", ""), "themes": themes}


def save_calibration(data: dict, path) -> None:
    """Write :func:`calibrate`'s dict as JSON (floats rounded to 6 decimals)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(_rounded(data), indent=1) + "\n", encoding="utf-8")
