"""Expert (Table III) versus data-driven RBF features of a theme, degree of freedom by degree of freedom.

Both feature sets are evaluated at w = 1 over one cycle of the neutral base, as displacements divided by the
walker's height, on the DOFs each edits itself (the experts' own edits before propagation, the data's fitted DOFs).
Per DOF (joint x axis):

- ``expert_peak`` / ``data_peak``: the signed value at each curve's largest magnitude (heights);
- ``sign_agree``: the data curve has the expert's sign at the expert's peak frame (does the real style move that
  way where the expert moves most);
- ``peak_shift``: circular distance between the two peak frames, share of the cycle (None when either curve is
  flat, i.e. a posture offset whose peak time means nothing: peak-to-peak under 25 % of its largest magnitude);
- ``ratio``: data amplitude / expert amplitude; ``corr``: Pearson correlation of the two curves (None if flat).

``used_overlap`` compares which DOFs each uses at the level of Table III's rows: of the experts' ten body part x
axis features, how many are among the data's first ten.
"""
from __future__ import annotations

import numpy as np

from generation.core.motion import Motion

from .basis import rbf_sum
from .data_features import data_rbfs, load_data_features
from .stylise import theme_rbfs, walker_frame_positions
from .themes import AXES, BODY_PARTS, theme_features

FLAT_SHARE = 0.25


def _curves(dofs: dict, m: int, height: float) -> dict[tuple[str, str], np.ndarray]:
    t = np.arange(m, dtype=np.float64)
    return {k: rbf_sum(t, p, period=m) / height for k, p in dofs.items()}


def _flat(y: np.ndarray) -> bool:
    return float(np.ptp(y)) < FLAT_SHARE * float(np.abs(y).max())


def _peak(y: np.ndarray) -> tuple[int, float]:
    k = int(np.argmax(np.abs(y)))
    return k, float(y[k])


def compare_theme(neutral: Motion, theme: str, data: dict | None = None, n_data: int = 10,
                  intensities: str = "calibrated") -> dict:
    """Per-DOF comparison of a theme's expert features (all ten) with its first ``n_data`` data-driven features.

    Returns {"rows": [per DOF dict, largest first], "expert_features": [(part, axis)], "data_features":
    [(part, axis)], "used_overlap": int, "sign_agreement": share of shared DOFs, "median_ratio": float | None}.
    """
    data = data or load_data_features()
    skel = neutral.skeleton
    P, _ = walker_frame_positions(neutral)
    m, h = P.shape[0], skel.height
    expert = _curves(theme_rbfs(P, skel, theme, 10, intensities=intensities), m, h)
    found = _curves(data_rbfs(theme, n_data, h, m, data), m, h)
    rows = []
    for key in sorted(set(expert) | set(found), key=lambda k: (k[0], AXES[k[1]])):
        e, d = expert.get(key), found.get(key)
        row = {"joint": key[0], "axis": key[1], "expert_peak": None, "data_peak": None, "sign_agree": None,
               "peak_shift": None, "ratio": None, "corr": None}
        if e is not None:
            row["expert_peak"] = _peak(e)[1]
        if d is not None:
            row["data_peak"] = _peak(d)[1]
        if e is not None and d is not None:
            ke, pe = _peak(e)
            kd, _ = _peak(d)
            row["sign_agree"] = bool(np.sign(d[ke]) == np.sign(pe))
            row["ratio"] = float(np.abs(d).max() / max(np.abs(e).max(), 1e-12))
            if not _flat(e) and not _flat(d):
                shift = abs(ke - kd) % m
                row["peak_shift"] = min(shift, m - shift) / m
                row["corr"] = float(np.corrcoef(e, d)[0, 1])
        rows.append(row)
    rows.sort(key=lambda r: -max(abs(r["expert_peak"] or 0.0), abs(r["data_peak"] or 0.0)))
    expert_rows = list(dict.fromkeys((f.part, f.axis) for f in theme_features(theme, None, intensities)))
    data_rows = [tuple(k) for k in data["themes"][theme]["features"][:n_data]]
    shared = [r for r in rows if r["sign_agree"] is not None]
    ratios = [r["ratio"] for r in shared]
    return {"rows": rows, "expert_features": expert_rows, "data_features": data_rows,
            "used_overlap": len(set(expert_rows) & set(data_rows)),
            "sign_agreement": (sum(r["sign_agree"] for r in shared) / len(shared)) if shared else None,
            "shared_dofs": len(shared), "median_ratio": float(np.median(ratios)) if ratios else None}


def part_label(part: str, axis: str) -> str:
    """'wrists Z' style label of a (body part, axis) row; the part must be one of the paper's eleven."""
    if part not in BODY_PARTS:
        raise ValueError(f"unknown body part {part!r}")
    return f"{part.replace('_', ' ')} {axis}"
