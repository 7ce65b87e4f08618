"""Root travel from the stance foot: walks captured "on a treadmill" (root fixed) get their world travel back.

Some position-only gait data (the BML walks of Emotion-Gait, ``../shared/mocap/emotion-gait-bml``) keep the root
at one point: the body walks in place and the feet move backwards under it. A planted foot does not move in the
world, so the body's world velocity is minus the stance foot's velocity in the root's frame (Kovar, Schreiner &
Gleicher 2002, "Footskate cleanup for motion capture editing", use the same constraint the other way round).

:func:`stance_weights` says how much each foot carries the body in each frame: the lower foot is the stance foot,
blended with a logistic of the height difference (``blend_m``: a few centimetres, so the switch at a contact
change spreads over the double-support frames instead of jumping), then smoothed over ``smooth_frames``.
:func:`reconstruct_root_travel` integrates minus the weighted stance-foot velocity on the ground plane and puts
the weighted stance foot's height back on one level (the pelvis bounce that a fixed root loses). Velocities at
frames where a looped clip jumps (a seam) are replaced by their neighbours' median (:func:`seam_frames`).

:func:`strip_root_travel` does the opposite (the treadmill view of a walk whose travel is known), and
:func:`compare_travel` scores a reconstruction against the truth: mean ground speed, path error and height
bounce. Positions are (T, J, 3), y up, any unit (the results are in the same unit).
"""
from __future__ import annotations

import numpy as np

UP = 1
GROUND = (0, 2)


def _logistic(x: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-np.clip(x, -50.0, 50.0)))


def _smooth(x: np.ndarray, frames: int) -> np.ndarray:
    """Moving average over ``frames`` (odd; edges padded with the end values) along axis 0."""
    if frames <= 1:
        return x
    k = frames // 2
    pad = np.concatenate([np.repeat(x[:1], k, 0), x, np.repeat(x[-1:], k, 0)])
    c = np.cumsum(np.concatenate([np.zeros((1,) + x.shape[1:]), pad]), axis=0)
    return (c[2 * k + 1:] - c[:-2 * k - 1]) / (2 * k + 1)


def stance_weights(feet_y: np.ndarray, blend: float, smooth_frames: int = 3, feet_u: np.ndarray | None = None,
                   speed_blend: float = 1.0) -> np.ndarray:
    """(T, 2) weights of the left and right foot as the stance foot (rows sum to 1).

    The logit of "left is the stance foot" is (y_right - y_left) / blend, plus, given the feet's forward
    velocities, (u_right - u_left) / speed_blend: in the root's frame the stance foot moves backwards and the swing
    foot forwards, which tells them apart in mid-swing, when the swing toe clears the floor by only 1-2 cm.

    Args:
        feet_y: (T, 2) heights of the two feet's lowest joints.
        blend: height difference (same unit) of logit 1.
        smooth_frames: moving-average width of the weights (odd).
        feet_u: (T, 2) the feet's velocities along the body's facing (unit/s), or None (heights only).
        speed_blend: forward-velocity difference (unit/s) of logit 1.
    """
    logit = (feet_y[:, 1] - feet_y[:, 0]) / max(blend, 1e-9)
    if feet_u is not None:
        logit = logit + (feet_u[:, 1] - feet_u[:, 0]) / max(speed_blend, 1e-9)
    w_left = _logistic(logit)
    w = np.stack([w_left, 1.0 - w_left], axis=1)
    w = _smooth(w, smooth_frames)
    return w / w.sum(1, keepdims=True)


def seam_frames(P: np.ndarray, factor: float = 1.6) -> np.ndarray:
    """(T,) bool: frames t whose step P[t] - P[t-1] is more than ``factor`` times larger than both neighbouring
    steps (joint-mean distance): where a looped capture jumps back to its first frame. Frame 0 is never a seam."""
    step = np.linalg.norm(np.diff(P, axis=0), axis=-1).mean(1)          # (T-1,)
    out = np.zeros(len(P), bool)
    for i in range(len(step)):
        prev = step[i - 1] if i > 0 else np.inf
        nxt = step[i + 1] if i + 1 < len(step) else np.inf
        ref = min(prev, nxt) if np.isfinite(min(prev, nxt)) else max(prev, nxt) if np.isfinite(max(prev, nxt)) \
            else np.inf
        out[i + 1] = bool(step[i] > factor * ref and step[i] > 1e-9)
    return out


def loop_period(P: np.ndarray, min_lag: int = 10, tol: float = 1e-5) -> int | None:
    """The smallest lag L >= ``min_lag`` with P[t + L] == P[t] for every t (within ``tol``): a clip that is one
    cycle repeated; None when there is none."""
    for lag in range(min_lag, len(P) - 1):
        if np.abs(P[lag:] - P[:-lag]).max() <= tol:
            return lag
    return None


def facing(P: np.ndarray, hips: tuple[int, int]) -> np.ndarray:
    """(T, 3) unit ground-plane facing from the hip line: (left hip - right hip) x up (left = up x forward)."""
    f = np.cross(P[:, hips[0]] - P[:, hips[1]], np.array([0.0, 1.0, 0.0]))
    f[:, UP] = 0.0
    return f / np.maximum(np.linalg.norm(f, axis=-1, keepdims=True), 1e-12)


def reconstruct_root_travel(P: np.ndarray, fps: float, feet: tuple[list[int], list[int]], blend: float,
                            smooth_frames: int = 3, hips: tuple[int, int] | None = None,
                            speed_blend: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """The world translation (T, 3) to add to every joint of a walk seen with its root fixed, and the stance
    weights (T, 2).

    Ground plane: v_body(t) = -(w_l v_l(t) + w_r v_r(t)), v_f the central-difference velocity of foot f's lowest
    joint on the ground plane, integrated from 0 at frame 0 (trapezoid). Height: minus the weighted stance foot's
    height, shifted so that its median over the clip is 0 (the stance foot stays on one level; the floor is left
    to the caller). Velocities at :func:`seam_frames` are replaced by the median of the frames around them.

    Args:
        P: (T, J, 3) positions with the root (nearly) fixed, y up.
        fps: frames per second (only scales the velocities, which are integrated back: the path does not depend
            on it).
        feet: joint indices of the left foot's and right foot's joints (heel, toe, ...): per frame each foot's
            lowest joint is its contact point.
        blend: see :func:`stance_weights` (same unit as P).
        hips: left and right hip joint indices: the feet's forward velocities (along :func:`facing`) join the
            stance weights with ``speed_blend`` (unit/s); None: heights only.
    """
    T = len(P)
    if T < 3:
        raise ValueError(f"root travel: need at least 3 frames, got {T}")
    lowest = []
    for joints in feet:
        Y = P[:, joints, UP]
        k = np.argmin(Y, axis=1)
        lowest.append(P[np.arange(T), np.asarray(joints)[k]])
    F = np.stack(lowest, axis=1)                                        # (T, 2, 3)
    V = np.gradient(F, axis=0) * fps                                    # (T, 2, 3)
    seam = seam_frames(P)
    bad = seam | np.roll(seam, -1)                                      # both frames around a jump
    bad[-1] &= seam[-1]
    if bad.any():
        good = np.flatnonzero(~bad)
        for t in np.flatnonzero(bad):
            near = good[np.argsort(np.abs(good - t))[:4]]
            V[t] = np.median(V[near], axis=0)
    U = None if hips is None else (V * facing(P, hips)[:, None, :]).sum(-1)
    w = stance_weights(F[:, :, UP], blend, smooth_frames, U, speed_blend)
    v_body = -(w[:, :, None] * V).sum(1)                                # (T, 3)
    out = np.zeros((T, 3))
    g = list(GROUND)
    out[1:, g] = np.cumsum(0.5 * (v_body[1:, g] + v_body[:-1, g]), axis=0) / fps
    h = (w * F[:, :, UP]).sum(1)
    out[:, UP] = -(h - np.median(h))
    return out, w


def strip_root_travel(P: np.ndarray, root: int = 0) -> np.ndarray:
    """(T, J, 3): the walk seen with its root fixed at its first frame's position (all three axes, as in the BML
    walks), i.e. P minus the root's displacement from frame 0."""
    return P - (P[:, root] - P[:1, root])[:, None, :]


def compare_travel(true_root: np.ndarray, rec_root: np.ndarray, fps: float) -> dict:
    """A reconstructed root path against the true one (both (T, 3), same unit; the reconstruction is compared
    from the same start point).

    Returns: ``speed_true``, ``speed_rec`` (mean ground speed, unit/s), ``speed_error_pct`` (100 (rec - true) /
    true), ``distance_true`` (ground path length), ``path_rms`` (RMS ground distance between the two paths after
    putting both at the start point), ``path_rms_pct`` (of the distance travelled), ``end_error_pct`` (end-point
    distance, % of the distance travelled), ``heading_error_deg`` (angle between the start-to-end directions),
    ``bounce_true``, ``bounce_rec`` (median peak-to-peak height over 1 s windows)."""
    g = list(GROUND)
    a = true_root[:, g] - true_root[0, g]
    b = rec_root[:, g] - rec_root[0, g]
    sp_a = np.linalg.norm(np.diff(a, axis=0), axis=-1)
    sp_b = np.linalg.norm(np.diff(b, axis=0), axis=-1)
    dist = float(sp_a.sum())
    speed_true, speed_rec = float(sp_a.mean() * fps), float(sp_b.mean() * fps)
    d = np.linalg.norm(a - b, axis=-1)
    ang_a, ang_b = np.arctan2(a[-1, 1], a[-1, 0]), np.arctan2(b[-1, 1], b[-1, 0])
    heading = float(np.degrees(np.abs((ang_b - ang_a + np.pi) % (2 * np.pi) - np.pi)))

    def bounce(y):
        n = max(2, int(round(fps)))
        if len(y) <= n:
            return float(np.ptp(y))
        return float(np.median([np.ptp(y[s:s + n]) for s in range(0, len(y) - n + 1, max(1, n // 2))]))

    return {"speed_true": speed_true, "speed_rec": speed_rec,
            "speed_error_pct": 100.0 * (speed_rec - speed_true) / max(speed_true, 1e-9),
            "distance_true": dist, "path_rms": float(np.sqrt((d ** 2).mean())),
            "path_rms_pct": 100.0 * float(np.sqrt((d ** 2).mean())) / max(dist, 1e-9),
            "end_error_pct": 100.0 * float(d[-1]) / max(dist, 1e-9), "heading_error_deg": heading,
            "bounce_true": bounce(true_root[:, UP]), "bounce_rec": bounce(rec_root[:, UP])}
