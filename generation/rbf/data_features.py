"""Data-driven RBF style features: Gaussian RBFs fitted to real themed walks minus the same dataset's normal walks.

Section VI of Etemad & Arya leaves open how the experts' features compare with features extracted from motion
data. Here, per theme, from the real corpus (Bandai Namco, Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0;
train split only):

1. Representation (the paper's): Cartesian joint trajectories of one gait cycle, time-normalised per cycle
   (contact-based warping, left strike -> 0, right -> m/2, next left -> m), in the walker's frame, divided by
   the walker's height (:func:`generation.rbf.real_neutral.steady_cycles`).
2. Difference: per dataset, mean cycle of the theme's styles (``protocol.vocabulary.CAPTURE_THEMES``) minus the mean
   cycle of the same dataset's normal walks (the corpus has no actor ids; each dataset's takes come from its
   own recording sessions, so a dataset is the closest thing to "the same actors"); then the mean over the
   datasets that have the theme. Shape (m, J, 3) in heights.
3. Fit, per degree of freedom of the paper's 18 joints (54 DOFs): the fewest Gaussian RBFs (1-3, eq. 4, circular
   time) whose least-squares fit explains :data:`FIT_R2` of the difference's variance about zero (else the best
   of three). A DOF whose difference never reaches :data:`MIN_PEAK` heights gets no RBFs.
4. Features: DOFs grouped like Table III's rows (body part x axis, both sides together), ranked by their
   largest amplitude, so "the first n features" means the same as for the experts' themes.

Result: :func:`fit_data_features` -> JSON (:data:`SHIPPED_PATH`, with licence and citation), read by
:func:`load_data_features`; :func:`data_rbfs` gives a theme's first n features per DOF in metres for a walker,
the same form as :func:`generation.rbf.stylise.theme_rbfs`.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from protocol.vocabulary import CAPTURE_THEMES

from .basis import MAX_RBFS_PER_DOF, rbf_sum, validate_params
from .real_neutral import steady_cycles
from .themes import AXES, BODY_PARTS, THEME_NAMES

SHIPPED_PATH = Path(__file__).resolve().parents[1] / "data" / "rbf" / "data_features.json"
MIN_PEAK = 0.004  # heights: 0.7 cm on a 1.75 m walker; smaller real differences are left out
FIT_R2 = 0.95
SIGMA_BOUNDS_CYCLES = (0.04, 4.0)  # from a sharp bump (4 of 100 frames) to a flat posture offset (shape 1)
PART_OF = {joint: part for part, joints in BODY_PARTS.items() for joint in joints}
PAPER_JOINTS = tuple(PART_OF)


def theme_styles(theme: str) -> tuple[str, ...]:
    """The corpus styles that stand for a theme (``protocol.vocabulary.CAPTURE_THEMES``)."""
    if theme not in THEME_NAMES:
        raise ValueError(f"unknown theme {theme!r}; expected one of {list(THEME_NAMES)}")
    return tuple(style for style, t in CAPTURE_THEMES.items() if t == theme)


def _mean_cycle(clips: list, m: int) -> tuple[np.ndarray | None, int]:
    cycles = [c.positions[:-1] for clip in clips for c in steady_cycles(clip.motion, m, clip.name)]
    return (np.mean(cycles, axis=0) if cycles else None), len(cycles)


def theme_difference(clips: list, theme: str, m: int = 100) -> tuple[np.ndarray, list[dict]]:
    """Mean themed cycle minus mean normal cycle, per dataset, averaged over datasets.

    Args:
        clips: :class:`generation.mocap.real_corpus.CorpusClip` walks (content ``walk``) incl. normal ones.
        theme: one of the six themes.

    Returns:
        (m, J, 3) difference in heights (walker's frame), and per dataset used {dataset, styles, takes, cycles,
        normal_takes, normal_cycles}.

    Raises:
        ValueError: when no dataset has both themed and normal walks with steady cycles.
    """
    styles = theme_styles(theme)
    diffs, info = [], []
    for dataset in sorted({c.dataset for c in clips}):
        themed = [c for c in clips if c.dataset == dataset and c.style in styles]
        normal = [c for c in clips if c.dataset == dataset and c.style == "normal"]
        if not themed or not normal:
            continue
        mt, nt = _mean_cycle(themed, m)
        mn, nn = _mean_cycle(normal, m)
        if mt is None or mn is None:
            continue
        diffs.append(mt - mn)
        info.append({"dataset": dataset, "styles": sorted({c.style for c in themed}), "takes": len(themed),
                     "cycles": nt, "normal_takes": len(normal), "normal_cycles": nn})
    if not diffs:
        raise ValueError(f"no dataset has both {theme} walks (styles {list(styles)}) and normal walks with steady "
                         "cycles")
    return np.mean(diffs, axis=0), info


def _residual(x: np.ndarray, t: np.ndarray, y: np.ndarray, m: int) -> np.ndarray:
    return rbf_sum(t, x.reshape(-1, 3), period=m) - y


def fit_dof(y: np.ndarray, r2: float = FIT_R2) -> tuple[np.ndarray, float]:
    """Fewest Gaussian RBFs (1..3) fitting a periodic difference y (m,); returns (M, 3) params and the R^2.

    R^2 is 1 - SSE / sum(y^2) (variance about zero: an offset counts as signal). Each added RBF starts at the
    largest remaining residual; the fit is a bounded least-squares (scipy) over all RBFs together.
    """
    from scipy.optimize import least_squares

    y = np.asarray(y, dtype=np.float64)
    m = y.size
    t = np.arange(m, dtype=np.float64)
    lo_s, hi_s = (SIGMA_BOUNDS_CYCLES[0] * m) ** 2, (SIGMA_BOUNDS_CYCLES[1] * m) ** 2
    total = float((y * y).sum())
    if total == 0.0:
        return np.zeros((0, 3)), 1.0
    params = np.zeros((0, 3))
    best = (params, 0.0)
    for _ in range(MAX_RBFS_PER_DOF):
        residual = y - rbf_sum(t, params, period=m) if len(params) else y
        if not params.size:
            start = np.array([[y.mean(), m / 2.0, hi_s / 4.0]]) if abs(y.mean()) > 0.5 * np.abs(y).max() else None
        else:
            start = None
        if start is None:
            k = int(np.argmax(np.abs(residual)))
            start = np.array([[residual[k], float(k), (0.12 * m) ** 2]])
        x0 = np.concatenate([params, start]).reshape(-1)
        n = len(x0) // 3
        lower = np.tile([-np.inf, -m, lo_s], n)
        upper = np.tile([np.inf, 2.0 * m, hi_s], n)
        x0 = np.clip(x0, lower + 1e-9, upper - 1e-9)
        fit = least_squares(_residual, x0, bounds=(lower, upper), args=(t, y, m))
        params = fit.x.reshape(-1, 3)
        params[:, 1] = params[:, 1] % m
        score = 1.0 - float((fit.fun ** 2).sum()) / total
        if score > best[1]:
            best = (params.copy(), score)
        if score >= r2:
            break
    return best


def fit_theme(diff: np.ndarray, joints: tuple[str, ...], min_peak: float = MIN_PEAK) -> list[dict]:
    """Fit every DOF of the paper's joints; returns one dict per DOF with RBFs: joint, axis, rbfs, r2, peak.

    Args:
        diff: (m, J, 3) difference in heights (:func:`theme_difference`).
        joints: the skeleton's joint names, in ``diff``'s order.
    """
    out = []
    for joint in PAPER_JOINTS:
        j = joints.index(joint)
        for axis, a in AXES.items():
            y = diff[:, j, a]
            peak = float(np.abs(y).max())
            if peak < min_peak:
                continue
            params, r2 = fit_dof(y)
            out.append({"joint": joint, "axis": axis, "part": PART_OF[joint], "rbfs": params.tolist(), "r2": r2,
                        "peak": peak, "mean": float(y.mean())})
    return out


def ranked_features(dofs: list[dict]) -> list[tuple[str, str]]:
    """(part, axis) groups of fitted DOFs ranked by their largest peak difference (Table III's rows)."""
    peak: dict[tuple[str, str], float] = {}
    for d in dofs:
        key = (d["part"], d["axis"])
        peak[key] = max(peak.get(key, 0.0), d["peak"])
    return sorted(peak, key=lambda k: -peak[k])


def fit_data_features(clips: list, joints: tuple[str, ...], m: int = 100) -> dict:
    """Data-driven features of all six themes from corpus walks: the JSON-ready dict that :func:`save_data_features`
    writes."""
    first = clips[0].motion.metadata if clips else {}
    themes = {}
    for theme in THEME_NAMES:
        diff, info = theme_difference(clips, theme, m)
        dofs = fit_theme(diff, joints)
        themes[theme] = {"sources": info, "dofs": dofs,
                         "features": [list(k) for k in ranked_features(dofs)]}
    return {"cycle_frames": m, "units": "alpha in walker heights, mu in frames of the cycle, sigma2 in frames^2",
            "min_peak": MIN_PEAK, "fit_r2": FIT_R2, "split": "train",
            "licence": first.get("licence", "CC BY-NC 4.0"), "citation": first.get("citation", ""),
            "dataset_url": first.get("source_url", ""), "themes": themes}


def save_data_features(features: dict, path: str | Path = SHIPPED_PATH) -> None:
    """Write features (:func:`fit_data_features`) as JSON, floats rounded to 6 decimals."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(_rounded(features), indent=1) + "\n", encoding="utf-8")


def _rounded(value, digits: int = 6):
    """Floats rounded to ``digits`` decimals (1e-6 heights is 2 micrometres), recursively."""
    if isinstance(value, float):
        return round(value, digits)
    if isinstance(value, dict):
        return {k: _rounded(v, digits) for k, v in value.items()}
    if isinstance(value, list):
        return [_rounded(v, digits) for v in value]
    return value


def load_data_features(path: str | Path = SHIPPED_PATH) -> dict:
    """Read data-driven features (default: the shipped file); checks the themes and the RBF rows."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"data-driven RBF features {path} not found; build them with "
                                "`python -m generation.rbf features --corpus CORPUS --out PATH`")
    data = json.loads(path.read_text(encoding="utf-8"))
    missing = set(THEME_NAMES) - set(data.get("themes", {}))
    if missing:
        raise ValueError(f"{path}: no data-driven features for themes {sorted(missing)}")
    for theme, entry in data["themes"].items():
        for d in entry["dofs"]:
            validate_params(np.asarray(d["rbfs"]).reshape(-1, 3), f"{path}: {theme} {d['joint']} {d['axis']}")
    return data


def data_rbfs(theme: str, n_features: int, height: float, cycle_frames: int,
              features: dict | None = None) -> dict[tuple[str, str], np.ndarray]:
    """A theme's first ``n_features`` data-driven features per DOF, in metres for a walker of ``height``.

    Returns {(joint, axis): (M, 3) rows (alpha metres, mu frames, sigma2 frames^2)}, mu and sigma2 rescaled to
    a cycle of ``cycle_frames`` frames: the form of :func:`generation.rbf.stylise.theme_rbfs`.
    """
    data = features or load_data_features()
    if theme not in data["themes"]:
        raise ValueError(f"unknown theme {theme!r}; expected one of {sorted(data['themes'])}")
    entry = data["themes"][theme]
    ranked = [tuple(k) for k in entry["features"]]
    if isinstance(n_features, bool) or not isinstance(n_features, int) or not 0 <= n_features:
        raise ValueError(f"n_features must be a non-negative integer, got {n_features!r}")
    keep = set(ranked[:n_features])
    k = cycle_frames / float(data["cycle_frames"])
    out = {}
    for d in entry["dofs"]:
        if (d["part"], d["axis"]) not in keep or not d["rbfs"]:
            continue
        p = np.asarray(d["rbfs"], dtype=np.float64).reshape(-1, 3)
        out[(d["joint"], d["axis"])] = np.column_stack([p[:, 0] * height, p[:, 1] * k, p[:, 2] * k * k])
    return out
