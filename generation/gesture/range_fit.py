"""Bring a generated gesture's wrist speed and reach into the real captured range of the closest emotion.

The real ranges (``generation/data/gesture_real_ranges.json``: min and max over the seated gesture takes of Bandai
Namco dataset 1 per captured emotion, CC BY-NC 4.0) exist for joyous, sad, angry, proud and neutral; any other
emotion is measured against the captured one closest in valence-arousal-dominance (:func:`closest_captured`,
``protocol.vocabulary.GESTURE_VAD``, Euclidean).

The lever (:func:`scale_amplitude`): every joint's local rotation is moved towards (a < 1) or away from (a > 1) its
own mean over the clip, ``q_mean * (q_mean^-1 q_t)^a``, the root untouched (seated). This scales the excursions of
the gesture about its mean pose, and with them wrist speed and reach, without changing the timing, the text
alignment or the mean posture. Amplitude alone cannot move a gesture's reach when its hands stay near the lap
(reach is mostly mean posture), so a second lever (:func:`flex_shoulders`) swings both upper arms forward (or back)
about the body's left-right axis through the shoulder by one angle, keeping every other joint's local rotation.
:func:`fit_to_range` tries pairs of a shoulder angle (:data:`FLEXION_GRID_DEG`) and an amplitude factor (a log grid
from :data:`MIN_FACTOR` to :data:`MAX_FACTOR`), the smallest change first (:func:`_change`: a factor of 2 counts as
much as 30 degrees), and keeps the first that puts the four statistics (:data:`RANGE_STATS`) inside the range;
where no pair does, the gesture is left as it is (a half-way change would alter it without reaching the real range)
and the record says so. :func:`fit_closest_range` does both steps for a generated gesture and records them in
its metadata (``real_range``).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from generation.core.quaternion import np_qconj, np_qfix, np_qfrom_axis_angle, np_qmul, np_qnormalize, np_qrot
from protocol.vocabulary import GESTURE_VAD

from .real_stats import RANGES_FILE, motion_stats

RANGE_STATS = ("wrist_mean", "wrist_p90", "reach_mean", "reach_p90")
MIN_FACTOR, MAX_FACTOR = 0.25, 3.0
GRID = 41
# shoulder flexion (degrees, + = hands forward), tried smallest first; beyond 45 degrees forward the seated figure
# holds its arms out like a sleepwalker, which no real take does
FLEXION_GRID_DEG = tuple(range(-40, 46, 5))
FLEXION_SCALE_DEG, FACTOR_SCALE = 30.0, 2.0   # equally large changes
SHOULDERS, COLLARS = (8, 12), (7, 11)
HIPS, KNEES = (15, 19), (16, 20)


def closest_captured(emotion: str, captured) -> str:
    """The captured emotion nearest to ``emotion`` in VAD (the emotion itself when captured).

    Raises:
        ValueError: for an emotion without VAD coordinates.
    """
    captured = list(captured)
    if emotion in captured:
        return emotion
    if emotion not in GESTURE_VAD:
        raise ValueError(f"unknown gesture emotion {emotion!r}; expected one of {sorted(GESTURE_VAD)}")
    v = np.asarray(GESTURE_VAD[emotion])
    return min(captured, key=lambda c: float(np.linalg.norm(np.asarray(GESTURE_VAD[c]) - v)))


def _mean_rotation(q: np.ndarray) -> np.ndarray:
    """(J, 4) per-joint mean of (T, J, 4) unit quaternions (sign-aligned to frame 0, averaged, normalised)."""
    aligned = np.where((q * q[:1]).sum(-1, keepdims=True) < 0, -q, q)
    return np_qnormalize(aligned.mean(0))


def _qpow(q: np.ndarray, a: float) -> np.ndarray:
    """Unit quaternions (..., 4) raised to the power a (rotation angle times a, same axis)."""
    q = np.where(q[..., :1] < 0, -q, q)
    w = np.clip(q[..., 0], -1.0, 1.0)
    half = np.arccos(w)
    s = np.sin(half)
    axis = np.where(s[..., None] > 1e-9, q[..., 1:] / np.maximum(s, 1e-12)[..., None], 0.0)
    return np.concatenate([np.cos(a * half)[..., None], axis * np.sin(a * half)[..., None]], -1)


def scale_amplitude(motion: Motion, a: float) -> Motion:
    """The motion with every non-root joint's rotation excursion about its clip mean scaled by ``a`` (> 0)."""
    if not (np.isfinite(a) and a > 0):
        raise ValueError(f"amplitude factor must be a positive number, got {a!r}")
    q = motion.rotations.astype(np.float64)
    mean = _mean_rotation(q)
    rel = np_qmul(np.broadcast_to(np_qconj(mean), q.shape), q)
    out = q.copy()
    out[:, 1:] = np_qmul(np.broadcast_to(mean[1:], q[:, 1:].shape), _qpow(rel[:, 1:], a))
    return Motion(motion.skeleton, np_qfix(np_qnormalize(out)), motion.root_positions, motion.fps,
                  dict(motion.metadata))


def _global_rotations(motion: Motion) -> np.ndarray:
    """(T, J, 4) world rotation of each joint's frame (parents before children, as skeletons store them)."""
    q = motion.rotations.astype(np.float64)
    out = np.empty_like(q)
    for j, parent in enumerate(motion.skeleton.parents):
        out[:, j] = q[:, j] if parent < 0 else np_qmul(out[:, parent], q[:, j])
    return out


def _forward_swing_axis(P: np.ndarray) -> np.ndarray:
    """(T, 3) unit world axis about which a positive rotation swings a hanging arm forward: the left-right axis
    (right to left shoulder), signed so that axis x down points where the seated figure faces (hips to knees)."""
    lateral = P[:, SHOULDERS[0]] - P[:, SHOULDERS[1]]
    lateral /= np.maximum(np.linalg.norm(lateral, axis=-1, keepdims=True), 1e-9)
    facing = (P[:, list(KNEES)] - P[:, list(HIPS)]).mean(1)
    swing = np.cross(lateral, np.array([0.0, -1.0, 0.0]))
    sign = np.sign((swing * facing).sum(-1).mean()) or 1.0
    return lateral * sign


def flex_shoulders(motion: Motion, degrees: float) -> Motion:
    """The motion with both upper arms rotated ``degrees`` forward (negative: back) about the body's left-right
    axis through each shoulder, frame by frame; the rest of the body and the arms' own bends unchanged."""
    if not np.isfinite(degrees):
        raise ValueError(f"shoulder flexion must be a finite angle in degrees, got {degrees!r}")
    if degrees == 0:
        return motion
    G = _global_rotations(motion)
    axis = _forward_swing_axis(motion.positions())
    out = motion.rotations.astype(np.float64).copy()
    for shoulder, collar in zip(SHOULDERS, COLLARS, strict=True):
        local_axis = np_qrot(np_qconj(G[:, collar]), axis)
        offset = np_qfrom_axis_angle(local_axis, np.full(len(axis), np.radians(degrees)))
        out[:, shoulder] = np_qmul(offset, out[:, shoulder])
    return Motion(motion.skeleton, np_qfix(np_qnormalize(out)), motion.root_positions, motion.fps,
                  dict(motion.metadata))


def _change(degrees: float, factor: float) -> float:
    """How much a (shoulder angle, amplitude factor) pair changes a gesture: squared steps of
    :data:`FLEXION_SCALE_DEG` and of factor :data:`FACTOR_SCALE`."""
    return (degrees / FLEXION_SCALE_DEG) ** 2 + (np.log(factor) / np.log(FACTOR_SCALE)) ** 2


def _excess(stats: dict, bounds: dict) -> float:
    total = 0.0
    for k in RANGE_STATS:
        lo, hi = bounds[k]
        v = max(stats[k], 1e-6)
        if v < lo:
            total += np.log(lo / v) ** 2
        elif v > hi:
            total += np.log(v / hi) ** 2
    return float(total)


def fit_to_range(motion: Motion, bounds: dict) -> tuple[Motion, dict]:
    """Flex the shoulders and scale the gesture's amplitude so that its :data:`RANGE_STATS` lie inside ``bounds``
    ({stat: [lo, hi]}), by the smallest change (:func:`_change`) that does.

    Returns the motion (the input itself when it is already inside, or when nothing gets it inside) and a record
    {"factor", "shoulder_flexion_deg", "inside", "before": stats, "after": stats}.
    """
    before = motion_stats(motion)
    unchanged = {"factor": 1.0, "shoulder_flexion_deg": 0.0, "inside": _excess(before, bounds) == 0.0,
                 "before": _pick(before), "after": _pick(before)}
    if unchanged["inside"]:
        return motion, unchanged
    grid = [(float(d), float(f)) for d in FLEXION_GRID_DEG for f in np.geomspace(MIN_FACTOR, MAX_FACTOR, GRID)]
    pairs = sorted(grid, key=lambda pair: _change(*pair))
    posed = {}
    for degrees, f in pairs:
        if degrees not in posed:
            posed[degrees] = flex_shoulders(motion, degrees)
        cand = scale_amplitude(posed[degrees], f)
        stats = motion_stats(cand)
        if _excess(stats, bounds) == 0.0:
            return cand, {"factor": f, "shoulder_flexion_deg": degrees, "inside": True, "before": _pick(before),
                          "after": _pick(stats)}
    return motion, unchanged


def fit_closest_range(motion: Motion, emotion: str, ranges: dict | None = None) -> Motion:
    """:func:`fit_to_range` against the real range of :func:`closest_captured` (``emotion``); the record, the
    reference emotion and the ranges' licence go into ``metadata["real_range"]``. ``ranges``: the content of
    :data:`generation.gesture.real_stats.RANGES_FILE` (default: read from it)."""
    data = ranges or read_ranges()
    captured = [k for k in data["ranges"] if k != "all"]
    ref = closest_captured(emotion, captured)
    out, record = fit_to_range(motion, data["ranges"][ref])
    out = Motion(out.skeleton, out.rotations, out.root_positions, out.fps, dict(out.metadata))
    out.metadata["real_range"] = {"reference_emotion": ref, **record, "licence": data.get("licence"),
                                  "citation": data.get("citation")}
    return out


def read_ranges(path: str | Path = RANGES_FILE) -> dict:
    """The shipped real ranges ({"ranges": {emotion or "all": {stat: [min, max]}}, "licence", ...}), read without
    torch (:func:`generation.gesture.real_range.load_ranges` is the training loss's reader)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no real gesture ranges (python -m generation.quality.real_gestures "
                                "--write-ranges writes them from the real corpus)")
    data = json.loads(path.read_text(encoding="utf-8"))
    if "all" not in data.get("ranges", {}):
        raise ValueError(f"{path}: expected an object with 'ranges' holding at least 'all'")
    return data


def _pick(stats: dict) -> dict:
    return {k: float(stats[k]) for k in RANGE_STATS}
