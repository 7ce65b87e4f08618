"""Realism measures of a walk, computed the same way on generated and on real captured motion.

All measures take a :class:`generation.core.motion.Motion` (or its (T, J, 3) positions, fps and skeleton) on a
skeleton with named legs (``left_/right_`` hip, knee, heel or ankle, toe; the 21-joint gait skeleton, onto which
the real takes are retargeted). Positions in metres, y-up, floor at y = 0.

**Near-floor foot (contact by height only).** A foot's height in frame t is the smallest height of its foot joints
(heel/ankle and toe) above that joint's own lowest height in the clip; the foot is *near the floor* for the frame
pair (t, t+1) when that height is below :data:`CONTACT_HEIGHT_M` (5 cm for a 1.75 m body, scaled with the
skeleton's height) in both frames. Its speed for the pair is the ground-plane (x, z) speed of the lowest of its
joints. The contact is **not** gated on speed: a foot sliding on the floor is in contact (the stance detector
of :func:`generation.core.features.detect_foot_contacts` requires the foot to be slow, so it never sees a slide).

This follows the foot-skating evaluation of recent motion-diffusion work: GMD (Karunratanakul et al., "Guided
Motion Diffusion for Controllable Human Motion Synthesis", ICCV 2023; its evaluation code's
``calculate_skating_ratio``, used since by later text-to-motion papers): a foot is in contact when it is below
5 cm in two adjacent frames, and it skates when it then moves faster than 0.5 m/s on the ground plane, both in
that frame and on average over a 5-frame window at 20 fps (0.25 s). Two changes, both documented here: the height
is measured above each joint's own lowest height in the clip rather than above y = 0 (joint centres sit at
rig-dependent heights above the sole, and sinking or floating is the ``penetration`` check's job), and both feet's
heel and toe joints are used (GMD uses the toe joints of SMPL).

Measures (:func:`realism_measures`):

- ``skate_cm_s``: mean ground-plane speed of near-floor feet, cm/s (the "foot sliding" of motion-synthesis
  evaluations: how fast feet move while they are on the floor; a planted foot gives 0).
- ``skate_ratio``: GMD's foot-skating ratio, the share of frame pairs in which at least one foot is near the floor
  and faster than 0.5 m/s, instantaneously and over 0.25 s (0..1).
- ``toe_skim``: the share of near-floor foot frame pairs in which that foot moves faster than 0.5 m/s (0..1):
  feet that skim the floor instead of stepping on it.
- ``stance_knee_deg``: mean knee flexion (180 degrees minus the hip-knee-heel angle) over stance frames: frames
  where the foot is near the floor *and* slower than 0.5 m/s (here the foot does stand, so a speed gate is right).
- ``pelvis_bounce_cm``: the root's vertical oscillation: root height minus its slow trend (Gaussian low-pass,
  sigma 0.5 s, which keeps slopes and sitting down out), then the peak-to-peak over 1 s windows (hop 0.5 s; a
  step, one vertical cycle of the pelvis, lasts 0.4-0.8 s), the median over windows, cm.
- ``speed_cv``: coefficient of variation (std / mean) of the ground-plane root speed averaged over 1 s windows
  (hop 0.5 s; one window holds about a stride, so the within-stride surge cancels): how much the walking speed
  changes over the clip. Real takes start and stop inside the clip; that is part of their variability.

A measure that cannot be computed (no near-floor frame, no stance frame, a clip shorter than a window, a root that
does not move) is None.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.ndimage import gaussian_filter1d, uniform_filter1d

from generation.core.foot_contact import legs
from generation.core.motion import Motion
from generation.core.skeleton import REFERENCE_HEIGHT_M, Skeleton
from generation.core.windows import windows

#: Near-floor height (GMD: 5 cm) for a 1.75 m body; scaled with skeleton.height / 1.75.
CONTACT_HEIGHT_M = 0.05
#: Ground-plane foot speed above which a near-floor foot skates / skims (GMD: 0.5 m/s).
SKATE_SPEED_M_S = 0.5
#: GMD's averaging window (5 frames at 20 fps).
SKATE_WINDOW_S = 0.25
#: Gaussian sigma of the slow root-height trend removed before the bounce is measured.
BOUNCE_TREND_SIGMA_S = 0.5
#: Window and hop of the bounce and speed-variability measures.
WINDOW_S = 1.0
HOP_S = 0.5
#: Below this mean window speed (m/s) the speed variability is not defined (the body stands).
MIN_MEAN_SPEED_M_S = 0.1

MEASURES = ("skate_cm_s", "skate_ratio", "toe_skim", "stance_knee_deg", "pelvis_bounce_cm", "speed_cv")
"""The realism measures, in the quality record's (and clips.csv's ``qa_``) order."""

UNITS = {"skate_cm_s": "cm/s", "skate_ratio": "share of frames", "toe_skim": "share of near-floor foot frames",
         "stance_knee_deg": "degrees", "pelvis_bounce_cm": "cm", "speed_cv": "std/mean"}


def _scale(skeleton: Skeleton) -> float:
    return skeleton.height / REFERENCE_HEIGHT_M if skeleton.height > 0 else 1.0


def _check(positions: np.ndarray, fps: float, skeleton: Skeleton) -> np.ndarray:
    P = np.asarray(positions, dtype=np.float64)
    if P.ndim != 3 or P.shape[1:] != (skeleton.num_joints, 3):
        raise ValueError(f"realism: positions must be (T, {skeleton.num_joints}, 3), got {P.shape}")
    if P.shape[0] < 2:
        raise ValueError(f"realism: need at least 2 frames, got {P.shape[0]}")
    if not fps > 0:
        raise ValueError(f"realism: fps must be positive, got {fps}")
    return P


def foot_floor(positions: np.ndarray, fps: float, skeleton: Skeleton) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Near-floor feet and their speeds (see the module docstring).

    Returns:
        height (T, 2) metres of each foot (left, right) above its clip ground; speed (T-1, 2) m/s ground-plane
        speed of the foot's lowest joint from frame t to t+1; near (T-1, 2) bool: the foot is near the floor in
        frames t and t+1.
    """
    P = _check(positions, fps, skeleton)
    T = len(P)
    thr = CONTACT_HEIGHT_M * _scale(skeleton)
    heights, speeds = [], []
    for leg in legs(skeleton):
        F = P[:, [leg.ankle, leg.toe]]                                  # (T, 2 joints, 3)
        rel = F[..., 1] - F[..., 1].min(axis=0)                         # (T, 2 joints)
        low = np.argmin(rel, axis=1)                                    # the joint nearest its own ground
        heights.append(rel[np.arange(T), low])
        rows = np.arange(T - 1)
        step = F[1:, :, [0, 2]][rows, low[:-1]] - F[:-1, :, [0, 2]][rows, low[:-1]]
        speeds.append(np.linalg.norm(step, axis=-1) * fps)
    height, speed = np.stack(heights, -1), np.stack(speeds, -1)
    near = (height[:-1] < thr) & (height[1:] < thr)
    return height, speed, near


def knee_flexion_deg(positions: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """(T, 2) knee flexion of the (left, right) leg, degrees: 180 minus the angle at the knee between the thigh
    (knee -> hip) and the shin (knee -> heel/ankle); 0 = straight leg."""
    P = np.asarray(positions, dtype=np.float64)
    out = []
    for leg in legs(skeleton):
        u = P[:, leg.hip] - P[:, leg.knee]
        v = P[:, leg.ankle] - P[:, leg.knee]
        ang = np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), (u * v).sum(-1))
        out.append(180.0 - np.degrees(ang))
    return np.stack(out, -1)


def _windows(T: int, fps: float) -> list[slice]:
    """1 s windows with 0.5 s hop over T frames (none when the clip is shorter than a window)."""
    return windows(T, max(2, int(round(WINDOW_S * fps))), int(round(HOP_S * fps)), to_end=False)


def pelvis_bounce_cm(positions: np.ndarray, fps: float) -> float | None:
    """Median over 1 s windows of the peak-to-peak detrended root height, cm (None when shorter than 1 s)."""
    y = np.asarray(positions, dtype=np.float64)[:, 0, 1]
    wins = _windows(len(y), fps)
    if not wins:
        return None
    detrended = y - gaussian_filter1d(y, BOUNCE_TREND_SIGMA_S * fps, mode="nearest")
    return 100.0 * float(np.median([np.ptp(detrended[s]) for s in wins]))


def speed_cv(positions: np.ndarray, fps: float) -> float | None:
    """Coefficient of variation of the root's ground-plane speed averaged over 1 s windows (None when shorter
    than two windows or when the body barely moves)."""
    root = np.asarray(positions, dtype=np.float64)[:, 0, :][:, [0, 2]]
    v = np.linalg.norm(np.diff(root, axis=0), axis=-1) * fps           # (T-1,)
    wins = _windows(len(v), fps)
    if len(wins) < 2:
        return None
    means = np.array([v[s].mean() for s in wins])
    if means.mean() < MIN_MEAN_SPEED_M_S:
        return None
    return float(means.std() / means.mean())


def realism_measures_positions(positions: np.ndarray, fps: float, skeleton: Skeleton) -> dict:
    """The realism measures (:data:`MEASURES`; floats or None) of (T, J, 3) positions at ``fps``."""
    P = _check(positions, fps, skeleton)
    _, speed, near = foot_floor(P, fps, skeleton)
    avg = uniform_filter1d(speed, size=max(1, int(round(SKATE_WINDOW_S * fps))), axis=0, mode="nearest")
    fast = speed > SKATE_SPEED_M_S
    skating = (near & fast & (avg > SKATE_SPEED_M_S)).any(axis=1)
    knee = knee_flexion_deg(P, skeleton)
    stance = near & ~fast                                              # (T-1, 2): frames t of the pair
    out = {
        "skate_cm_s": 100.0 * float(speed[near].mean()) if near.any() else None,
        "skate_ratio": float(skating.mean()),
        "toe_skim": float(fast[near].mean()) if near.any() else None,
        "stance_knee_deg": float(knee[:-1][stance].mean()) if stance.any() else None,
        "pelvis_bounce_cm": pelvis_bounce_cm(P, fps),
        "speed_cv": speed_cv(P, fps),
    }
    return {k: (None if v is None or not math.isfinite(v) else v) for k, v in out.items()}


def realism_measures(motion: Motion) -> dict:
    """The realism measures (:data:`MEASURES`; floats or None) of a Motion (see the module docstring)."""
    return realism_measures_positions(motion.positions(), motion.fps, motion.skeleton)


__all__ = ["CONTACT_HEIGHT_M", "MEASURES", "SKATE_SPEED_M_S", "UNITS", "foot_floor", "knee_flexion_deg",
           "pelvis_bounce_cm", "realism_measures", "realism_measures_positions", "speed_cv"]
