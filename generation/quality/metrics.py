"""Motion measures for the quality record of a clip (numpy; positions in metres, y-up, floor at y = 0).

Every function takes a :class:`generation.core.motion.Motion` or its (T, J, 3) positions and returns plain floats.
"""
from __future__ import annotations

import numpy as np

from generation.core.features import foot_joints, foot_skate
from generation.core.motion import Motion


def penetration_cm(positions: np.ndarray, skeleton) -> float:
    """Depth of the lowest foot joint below the floor y = 0 over the clip, centimetres (0 when none goes below)."""
    left, right = foot_joints(skeleton)
    feet = left + right
    if not feet:
        return 0.0
    return max(0.0, -100.0 * float(positions[:, feet, 1].min()))


def mean_jerk(positions: np.ndarray, fps: float) -> float:
    """Mean joint jerk, m/s^3: the norm of the third finite difference of every joint's position times fps^3,
    averaged over joints and frames (0 for clips shorter than 4 frames)."""
    if positions.shape[0] < 4:
        return 0.0
    d3 = np.diff(positions, n=3, axis=0) * fps ** 3
    return float(np.linalg.norm(d3, axis=-1).mean())


def bone_error_mm(positions: np.ndarray, skeleton) -> float:
    """Largest deviation of a bone's length from the skeleton's, millimetres (0 for rigid forward kinematics)."""
    parents = np.asarray(skeleton.parents)
    child = np.nonzero(parents >= 0)[0]
    if child.size == 0:
        return 0.0
    lengths = np.linalg.norm(positions[:, child] - positions[:, parents[child]], axis=-1)
    return 1000.0 * float(np.abs(lengths - skeleton.bone_lengths()[child]).max())


def motion_metrics(motion: Motion) -> dict:
    """The motion part of a clip's quality record.

    Returns ``foot_skate_cm_s`` (mean ground-plane speed of the feet while in contact, see
    :func:`generation.core.features.foot_skate`; its contact detector requires a slow foot, so a foot sliding
    faster than 0.45 m/s is not counted: :mod:`generation.quality.realism`'s ``skate_cm_s`` and ``skate_ratio``
    use height-only contact), ``penetration_cm``, ``jerk`` (m/s^3) and ``bone_error_mm``.
    """
    P = motion.positions()
    sk = motion.skeleton
    skate = foot_skate(P, motion.fps, sk) if P.shape[0] >= 3 and any(foot_joints(sk)) else {"mean_m_s": 0.0}
    return {"foot_skate_cm_s": 100.0 * float(skate["mean_m_s"]), "penetration_cm": penetration_cm(P, sk),
            "jerk": mean_jerk(P, motion.fps), "bone_error_mm": bone_error_mm(P, sk)}
