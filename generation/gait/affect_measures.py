"""Five measures of how a walk carries its emotion, the same on generated and real walks (21-joint gait skeleton).

Per walk (``walk_measures``), lengths divided by the skeleton's height so bodies of different size compare:

- ``speed``: mean ground speed of the pelvis, heights per second;
- ``arm_swing``: fore-aft peak-to-peak of each wrist relative to the pelvis along the walker's heading, per 2 s window
  (one stride or more), mean over windows and both wrists, heights;
- ``elbow_deg``: mean elbow angle (shoulder-elbow-wrist), degrees (180 = straight arm);
- ``head_pitch_deg``: mean forward lean of the neck-to-head segment from vertical, degrees (positive = head forward);
- ``bounce``: vertical peak-to-peak of the pelvis per 2 s window, mean over windows, heights.

The heading is the direction of the pelvis's ground velocity smoothed over 0.5 s, so curved paths measure like
straight ones. :func:`difference` gives a - b per measure.
"""
from __future__ import annotations

import numpy as np

from generation.core.motion import Motion
from generation.core.skeleton import GAIT_JOINTS
from generation.core.windows import windows

MEASURES = ("speed", "arm_swing", "elbow_deg", "head_pitch_deg", "bounce")
WINDOW_S = 2.0
HOP_S = 0.5
HEADING_SMOOTH_S = 0.5


def _headings(root: np.ndarray, fps: float) -> np.ndarray:
    """(T, 2) unit ground-plane (x, z) heading per frame from the smoothed pelvis velocity."""
    v = np.gradient(root[:, [0, 2]], axis=0)
    k = max(1, int(round(HEADING_SMOOTH_S * fps)))
    kernel = np.ones(k) / k
    v = np.stack([np.convolve(np.pad(v[:, i], (k, k), mode="edge"), kernel, mode="same")[k:-k] for i in range(2)], -1)
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    fallback = np.array([0.0, 1.0])
    return np.where(n > 1e-9, v / np.maximum(n, 1e-12), fallback)


def _angle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    u, w = a - b, c - b
    cos = (u * w).sum(-1) / np.maximum(np.linalg.norm(u, axis=-1) * np.linalg.norm(w, axis=-1), 1e-12)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def walk_measures(motion: Motion) -> dict[str, float]:
    """The five measures of one walk (see the module docstring).

    Raises:
        ValueError: when the motion is not on the 21-joint gait skeleton or shorter than 0.5 s.
    """
    if tuple(motion.skeleton.joints) != GAIT_JOINTS:
        raise ValueError(f"walk measures need the 21-joint gait skeleton, got {motion.skeleton.name!r}")
    if motion.num_frames < max(2, int(0.5 * motion.fps)):
        raise ValueError(f"walk measures need at least 0.5 s, got {motion.num_frames} frames at {motion.fps} fps")
    P = motion.positions()
    h = motion.skeleton.height if motion.skeleton.height > 0 else 1.75
    J = list(GAIT_JOINTS)
    root = P[:, J.index("root")]
    head_dir = _headings(root, motion.fps)
    speed = np.linalg.norm(np.diff(root[:, [0, 2]], axis=0), axis=-1).mean() * motion.fps / h
    wins = windows(motion.num_frames, int(round(WINDOW_S * motion.fps)), int(round(HOP_S * motion.fps)),
                   whole_if_short=True)
    swings = []
    for side in ("left", "right"):
        rel = P[:, J.index(f"{side}_hand"), :] - root
        fwd = rel[:, 0] * head_dir[:, 0] + rel[:, 2] * head_dir[:, 1]
        swings.append(np.mean([np.ptp(fwd[s]) for s in wins]))
    elbows = [_angle(P[:, J.index(f"{s}_shoulder")], P[:, J.index(f"{s}_elbow")], P[:, J.index(f"{s}_hand")]).mean()
              for s in ("left", "right")]
    seg = P[:, J.index("head")] - P[:, J.index("neck")]
    forward = seg[:, 0] * head_dir[:, 0] + seg[:, 2] * head_dir[:, 1]
    pitch = np.degrees(np.arctan2(forward, seg[:, 1])).mean()
    bounce = np.mean([np.ptp(root[s, 1]) for s in wins]) / h
    return {"speed": float(speed), "arm_swing": float(np.mean(swings) / h), "elbow_deg": float(np.mean(elbows)),
            "head_pitch_deg": float(pitch), "bounce": float(bounce)}


def mean_measures(motions: list[Motion]) -> dict[str, float]:
    """Mean of :func:`walk_measures` over walks."""
    if not motions:
        raise ValueError("mean_measures needs at least one walk")
    rows = [walk_measures(m) for m in motions]
    return {k: float(np.mean([r[k] for r in rows])) for k in MEASURES}


def difference(a: dict, b: dict) -> dict[str, float]:
    """a - b per measure."""
    return {k: float(a[k] - b[k]) for k in MEASURES}
