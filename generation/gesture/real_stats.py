"""Motion statistics of seated gestures, computed the same way on real captured and on generated ones, and the real
captured range of each gesture emotion.

Per clip (:func:`gesture_stats`, joint positions (T, 23, 3) metres on the gesture skeleton, seated, at ``fps``):

- ``wrist_mean``, ``wrist_p90``: the faster wrist's speed per frame pair (m/s), its clip mean and 90th percentile;
- ``elbow_mean``, ``elbow_p90``: the same for the faster elbow;
- ``reach_mean``, ``reach_p90``: the farther wrist's distance from the trunk axis (the segment root-neck), metres;
- ``lean_mean``: trunk lean, the angle of root->neck from vertical (degrees), clip mean; ``lean_range``: its 95th
  minus 5th percentile (degrees);
- ``head_speed``: mean angular speed of the head's direction (root->head... the neck->head vector), degrees/s;
- ``hold_share``: share of frame pairs where both wrists move slower than :data:`HOLD_SPEED` (holds and rests).

The real clips they are compared with (seated dataset-1 gesture takes of the Bandai Namco Research Motion Dataset)
are loaded by :mod:`generation.quality.real_gestures`, which also writes their per-emotion ranges to
:data:`RANGES_FILE` for the training loss (:mod:`generation.gesture.real_range`).
"""
from __future__ import annotations

import numpy as np

from generation.core.motion import Motion

from .config import GENERATION_DIR, TRAIN_FPS

RANGES_FILE = GENERATION_DIR / "data" / "gesture_real_ranges.json"

STATS_FPS = TRAIN_FPS  # the network's rate: real clips are resampled to it before measuring
HOLD_SPEED = 0.10  # m/s
STAT_NAMES = ("wrist_mean", "wrist_p90", "elbow_mean", "elbow_p90", "reach_mean", "reach_p90", "lean_mean",
              "lean_range", "head_speed", "hold_share")
WRISTS, ELBOWS = (10, 14), (9, 13)
ROOT, NECK, HEAD = 0, 5, 6


def _faster(P: np.ndarray, joints, fps: float) -> np.ndarray:
    """(T-1,) speed (m/s) of the faster of ``joints`` per frame pair."""
    return np.linalg.norm(np.diff(P[:, list(joints)], axis=0), axis=-1).max(1) * fps


def trunk_distance(P: np.ndarray, joint: int) -> np.ndarray:
    """(T,) distance (m) of ``joint`` from the trunk axis, the segment root-neck, of positions P (T, 23, 3)."""
    a, b, p = P[:, ROOT], P[:, NECK], P[:, joint]
    ab = b - a
    t = np.clip(((p - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-12), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=-1)


def gesture_stats(P: np.ndarray, fps: float) -> dict[str, float]:
    """The statistics of the module docstring for one clip: P (T, 23, 3) metres, T >= 3, at ``fps``."""
    P = np.asarray(P, dtype=np.float64)
    if P.ndim != 3 or P.shape[1:] != (23, 3) or len(P) < 3:
        raise ValueError(f"expected gesture-skeleton positions (T >= 3, 23, 3), got {P.shape}")
    wrist, elbow = _faster(P, WRISTS, fps), _faster(P, ELBOWS, fps)
    both = np.linalg.norm(np.diff(P[:, list(WRISTS)], axis=0), axis=-1).max(1) * fps
    reach = np.maximum(trunk_distance(P, WRISTS[0]), trunk_distance(P, WRISTS[1]))
    trunk = P[:, NECK] - P[:, ROOT]
    lean = np.degrees(np.arccos(np.clip(trunk[:, 1] / np.linalg.norm(trunk, axis=-1), -1.0, 1.0)))
    head = P[:, HEAD] - P[:, NECK]
    head = head / np.linalg.norm(head, axis=-1, keepdims=True)
    head_speed = np.degrees(np.arccos(np.clip((head[1:] * head[:-1]).sum(-1), -1.0, 1.0))) * fps
    return {"wrist_mean": float(wrist.mean()), "wrist_p90": float(np.percentile(wrist, 90)),
            "elbow_mean": float(elbow.mean()), "elbow_p90": float(np.percentile(elbow, 90)),
            "reach_mean": float(reach.mean()), "reach_p90": float(np.percentile(reach, 90)),
            "lean_mean": float(lean.mean()), "lean_range": float(np.percentile(lean, 95) - np.percentile(lean, 5)),
            "head_speed": float(head_speed.mean()), "hold_share": float((both < HOLD_SPEED).mean())}


def motion_stats(motion: Motion, fps: float = STATS_FPS) -> dict[str, float]:
    """:func:`gesture_stats` of a gesture Motion resampled to ``fps``."""
    m = motion.resample(fps) if abs(motion.fps - fps) > 1e-9 else motion
    return gesture_stats(m.positions(), m.fps)


def real_ranges(rows: list[dict], stats=STAT_NAMES) -> dict[str, dict[str, tuple[float, float]]]:
    """Per gesture emotion (and "all" over every row): {stat: (min, max)} over the real clips of rows."""
    out: dict[str, dict[str, tuple[float, float]]] = {}
    groups = {"all": rows}
    for r in rows:
        if r.get("emotion"):
            groups.setdefault(r["emotion"], []).append(r)
    for name, group in groups.items():
        out[name] = {k: (float(min(r[k] for r in group)), float(max(r[k] for r in group))) for k in stats}
    return out


def in_range_shares(rows: list[dict], ranges: dict, stats=STAT_NAMES) -> dict[str, dict[str, float]]:
    """Per emotion of ``rows`` that ``ranges`` has (``real_ranges``'s {emotion: {stat: (min, max)}}), per statistic,
    the share of its rows ({"emotion", stat: value, ...}, e.g. generated clips) inside the real [min, max]."""
    out: dict[str, dict[str, float]] = {}
    for e in dict.fromkeys(str(r["emotion"]) for r in rows):
        if e in ranges and e != "all":
            group = [r for r in rows if r["emotion"] == e]
            out[e] = {k: float(np.mean([ranges[e][k][0] <= r[k] <= ranges[e][k][1] for r in group])) for k in stats}
    return out


def mean_share(shares: dict[str, dict[str, float]]) -> float:
    """The share over all (emotion, statistic) cells of :func:`in_range_shares` (each cell weighted alike)."""
    cells = [v for per in shares.values() for v in per.values()]
    return float(np.mean(cells)) if cells else float("nan")
