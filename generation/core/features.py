"""Pose affective features (seed 000 3.2.3, seed 003 Fig. 4) and movement features (seed 000 3.2.4).

Pose affective features are scale-independent geometric quantities of one pose:
- ``ang(p, q, r)``: the angle at joint q between the segments q->p and q->r (radians),
- ``d(p, q)``: the distance between two joints; features are ratios of two distances,
- ``A(p, q, r)``: the area of the triangle p-q-r; features are ratios of two areas.
They do not change when the body is uniformly scaled, translated or rotated (any rotation).

Gait (21-joint skeleton, REFERENCE.md section 1): 11 angles in radians, 4 distance ratios, 3 area ratios = 18.
Gesture (23-joint skeleton, REFERENCE.md section 2): 7 angles divided by pi, 5 distance ratios, 3 area ratios = 15.

The torch functions are differentiable (angles use atan2(|u x v|, u.v), which has finite gradients at 0 and pi;
distances carry a 1e-12 m^2 epsilon inside the square root). The ``np_`` twins call the torch code in float64;
torch is imported when a function first runs, not with this module.

Movement features (numpy, over (..., T, J, 3) sequences): root height deviation, root speed and its low-pass,
root orientation difference, trajectory curvature, stepping phase and foot-step frequency, from foot contacts
detected with height and speed thresholds. See :func:`movement_features` and :func:`detect_foot_contacts`.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.ndimage import gaussian_filter1d

from .quaternion import np_qrot
from .skeleton import GAIT_JOINTS, GESTURE_JOINTS, Skeleton

if TYPE_CHECKING:
    import torch

# ---- feature tables (joint indices as in REFERENCE.md) ----------------------------------------------
GAIT_ANGLES = ((17, 9, 13), (19, 9, 15), (13, 14, 15), (17, 18, 19), (12, 11, 13), (12, 11, 17),
               (12, 0, 2), (12, 0, 6), (8, 0, 4), (1, 2, 3), (5, 6, 7))
GAIT_DISTANCE_RATIOS = (((16, 11), (16, 0)), ((20, 11), (20, 0)), ((16, 20), (11, 0)), ((4, 8), (11, 0)))
GAIT_AREA_RATIOS = (((17, 9, 13), (17, 0, 13)), ((19, 9, 15), (19, 0, 15)), ((20, 11, 16), (8, 0, 4)))

GESTURE_ANGLES = ((0, 2, 6), (9, 4, 6), (13, 4, 6), (0, 10, 4), (0, 14, 4), (8, 9, 10), (12, 13, 14))
GESTURE_DISTANCE_RATIOS = (((10, 0), (10, 4)), ((10, 0), (10, 6)), ((14, 0), (14, 4)), ((14, 0), (14, 6)),
                           ((10, 14), (0, 6)))
GESTURE_AREA_RATIOS = (((10, 0, 14), (10, 4, 14)), ((6, 10, 0), (6, 14, 0)), ((4, 10, 0), (4, 14, 0)))


def _names(joints, angles, dists, areas) -> tuple[str, ...]:
    def n(idx):
        return "-".join(joints[i] for i in idx)

    out = [f"ang:{n(a)}" for a in angles]
    out += [f"dist:{n(a)}/{n(b)}" for a, b in dists]
    out += [f"area:{n(a)}/{n(b)}" for a, b in areas]
    return tuple(out)


#: 18 gait feature names, e.g. ``"ang:right_shoulder-lower_back-left_shoulder"`` (vertex in the middle),
#: ``"dist:left_hand_index-neck/left_hand_index-root"``, ``"area:...-...-.../...-...-..."``.
GAIT_FEATURE_NAMES = _names(GAIT_JOINTS, GAIT_ANGLES, GAIT_DISTANCE_RATIOS, GAIT_AREA_RATIOS)
#: 15 gesture feature names in the same style.
GESTURE_FEATURE_NAMES = _names(GESTURE_JOINTS, GESTURE_ANGLES, GESTURE_DISTANCE_RATIOS, GESTURE_AREA_RATIOS)

_EPS2 = 1e-12  # m^2, keeps sqrt differentiable at zero distance


def _check(positions: torch.Tensor, num_joints: int, what: str) -> torch.Tensor:
    import torch  # heavy: only the torch variants load torch
    if not isinstance(positions, torch.Tensor):
        raise TypeError(f"{what}: expected a torch.Tensor, got {type(positions).__name__}; use the np_ function")
    if positions.dim() < 2 or tuple(positions.shape[-2:]) != (num_joints, 3):
        raise ValueError(f"{what}: positions must be (..., {num_joints}, 3), got {tuple(positions.shape)}")
    return positions


def _angle(P: torch.Tensor, p: int, q: int, r: int) -> torch.Tensor:
    import torch  # heavy: only the torch variants load torch
    u = P[..., p, :] - P[..., q, :]
    v = P[..., r, :] - P[..., q, :]
    cross = torch.linalg.cross(u, v)
    return torch.atan2(torch.sqrt((cross * cross).sum(-1) + _EPS2 * _EPS2), (u * v).sum(-1))


def _dist(P: torch.Tensor, a: int, b: int) -> torch.Tensor:
    import torch  # heavy: only the torch variants load torch
    diff = P[..., a, :] - P[..., b, :]
    return torch.sqrt((diff * diff).sum(-1) + _EPS2)


def _area(P: torch.Tensor, p: int, q: int, r: int) -> torch.Tensor:
    import torch  # heavy: only the torch variants load torch
    cross = torch.linalg.cross(P[..., p, :] - P[..., q, :], P[..., r, :] - P[..., q, :])
    return 0.5 * torch.sqrt((cross * cross).sum(-1) + _EPS2 * _EPS2)


def _features(P, angles, dists, areas, angle_scale: float) -> torch.Tensor:
    import torch  # heavy: only the torch variants load torch
    cols = [_angle(P, *a) * angle_scale for a in angles]
    cols += [_dist(P, *a) / _dist(P, *b) for a, b in dists]
    cols += [_area(P, *a) / _area(P, *b) for a, b in areas]
    return torch.stack(cols, dim=-1)


def gait_affective_features(positions: torch.Tensor) -> torch.Tensor:
    """The 18 gait pose affective features of seed 000 (REFERENCE.md section 1).

    Args:
        positions: (..., 21, 3) joint positions on the gait skeleton (any unit; features are scale-free).

    Returns:
        (..., 18): 11 angles in radians, then 4 distance ratios, then 3 area ratios, in
        :data:`GAIT_FEATURE_NAMES` order. Differentiable.
    """
    P = _check(positions, 21, "gait_affective_features")
    return _features(P, GAIT_ANGLES, GAIT_DISTANCE_RATIOS, GAIT_AREA_RATIOS, 1.0)


def gesture_affective_features(positions: torch.Tensor) -> torch.Tensor:
    """The 15 gesture affective features of seed 003 (REFERENCE.md section 2).

    Args:
        positions: (..., 23, 3) joint positions on the gesture skeleton.

    Returns:
        (..., 15): 7 angles divided by pi (so in [0, 1]), 5 distance ratios, 3 area ratios, in
        :data:`GESTURE_FEATURE_NAMES` order. Differentiable.
    """
    P = _check(positions, 23, "gesture_affective_features")
    return _features(P, GESTURE_ANGLES, GESTURE_DISTANCE_RATIOS, GESTURE_AREA_RATIOS, 1.0 / np.pi)


def np_gait_affective_features(positions: np.ndarray) -> np.ndarray:
    """numpy twin of :func:`gait_affective_features`: (..., 21, 3) -> (..., 18) float64."""
    import torch  # heavy: only the torch variants load torch
    with torch.no_grad():
        return gait_affective_features(torch.as_tensor(np.asarray(positions, dtype=np.float64))).numpy()


def np_gesture_affective_features(positions: np.ndarray) -> np.ndarray:
    """numpy twin of :func:`gesture_affective_features`: (..., 23, 3) -> (..., 15) float64."""
    import torch  # heavy: only the torch variants load torch
    with torch.no_grad():
        return gesture_affective_features(torch.as_tensor(np.asarray(positions, dtype=np.float64))).numpy()


def affective_features(positions: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """Gait or gesture features (numpy) chosen by the skeleton's joint count (21 -> gait, 23 -> gesture)."""
    if skeleton.joints == GAIT_JOINTS:
        return np_gait_affective_features(positions)
    if skeleton.joints == GESTURE_JOINTS:
        return np_gesture_affective_features(positions)
    raise ValueError(f"affective features are defined for the gait and gesture skeletons, not {skeleton.name!r}")


# ---- foot contacts ----------------------------------------------------------------------------------
#: Contact thresholds for a 1.75 m body; both scale with skeleton.height / 1.75.
CONTACT_HEIGHT_M = 0.05   # foot joint within 5 cm of its lowest height in the clip
CONTACT_SPEED_M_S = 0.45  # and moving slower than 0.45 m/s on the ground plane


def foot_joints(skeleton: Skeleton) -> tuple[list[int], list[int]]:
    """Indices of the (left, right) foot joints: every joint named left_/right_ + heel, ankle, foot or toe."""
    keys = ("heel", "ankle", "foot", "toe")
    left = [j for j, n in enumerate(skeleton.joints) if n.startswith("left_") and any(k in n for k in keys)]
    right = [j for j, n in enumerate(skeleton.joints) if n.startswith("right_") and any(k in n for k in keys)]
    if not left or not right:
        raise ValueError(f"skeleton {skeleton.name!r} has no left_/right_ heel, ankle, foot or toe joints")
    return left, right


def _check_sequence(positions, skeleton: Skeleton, fps: float, what: str) -> np.ndarray:
    P = np.asarray(positions, dtype=np.float64)
    if P.ndim < 3 or P.shape[-2:] != (skeleton.num_joints, 3):
        raise ValueError(f"{what}: positions must be (..., T, {skeleton.num_joints}, 3), got {P.shape}")
    if P.shape[-3] < 2:
        raise ValueError(f"{what}: need at least 2 frames, got {P.shape[-3]}")
    if not fps > 0:
        raise ValueError(f"{what}: fps must be positive, got {fps}")
    return P


def _clean_runs(mask: np.ndarray) -> np.ndarray:
    """Fill 1-frame gaps, then drop 1-frame runs, along the last axis."""
    m = mask.copy()
    gap = ~m[..., 1:-1] & m[..., :-2] & m[..., 2:]
    m[..., 1:-1] |= gap
    lone = m[..., 1:-1] & ~m[..., :-2] & ~m[..., 2:]
    m[..., 1:-1] &= ~lone
    return m


def detect_foot_contacts(positions: np.ndarray, fps: float, skeleton: Skeleton,
                         height_threshold: float | None = None, speed_threshold: float | None = None) -> np.ndarray:
    """Frames where each foot touches the ground.

    A foot is in contact when at least one of its joints (heel/ankle/toe) is within ``height_threshold`` of
    that joint's lowest height in the clip (the clip's ground for that joint) and moves slower than
    ``speed_threshold`` on the ground plane (the smaller of the backward and forward difference speeds, so the
    first and last frames of a stance count as still). Defaults are :data:`CONTACT_HEIGHT_M` and
    :data:`CONTACT_SPEED_M_S` scaled by ``skeleton.height / 1.75``. One-frame gaps are filled and one-frame
    contacts dropped.

    Args:
        positions: (..., T, J, 3) metres, y-up.
        fps: frames per second.
        skeleton: gives the foot joints (see :func:`foot_joints`) and body height.

    Returns:
        (..., T, 2) bool, columns (left, right).
    """
    P = _check_sequence(positions, skeleton, fps, "detect_foot_contacts")
    scale = skeleton.height / 1.75
    h_thr = CONTACT_HEIGHT_M * scale if height_threshold is None else height_threshold
    v_thr = CONTACT_SPEED_M_S * scale if speed_threshold is None else speed_threshold
    out = []
    for side in foot_joints(skeleton):
        F = P[..., side, :]                                   # (..., T, K, 3)
        height = F[..., 1]
        floor = height.min(axis=-2, keepdims=True)            # per joint, over time
        low = height - floor < h_thr
        step = np.linalg.norm(np.diff(F[..., [0, 2]], axis=-3), axis=-1) * fps      # (..., T-1, K)
        back = np.concatenate([step[..., :1, :], step], axis=-2)
        fwd = np.concatenate([step, step[..., -1:, :]], axis=-2)
        speed = np.minimum(back, fwd)   # a frame at the edge of a stance counts as still
        slow = speed < v_thr
        out.append(_clean_runs((low & slow).any(axis=-1)))
    return np.stack(out, axis=-1)


# ---- movement features ------------------------------------------------------------------------------
#: Gaussian low-pass (sigma in seconds) giving s-bar from s.
LOWPASS_SIGMA_S = 0.25
#: Width (Gaussian sigma, seconds) of the local quadratic fit of the root path used for delta and kappa;
#: damps the ~1 Hz lateral sway of the pelvis at each step while keeping turns.
PATH_SIGMA_S = 0.5
#: A touch-down counts only after the foot was off the ground this long (seconds); drops contact flicker.
MIN_SWING_S = 0.15
_MIN_SPEED = 0.05  # m/s; below this the trajectory tangent is undefined and delta, kappa are set to 0


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2 * np.pi) - np.pi


def facing_directions(positions: np.ndarray, skeleton: Skeleton, root_rotations: np.ndarray | None = None):
    """Heading angle of the body on the ground plane, radians about +y (0 = facing +z, +pi/2 = facing +x).

    With ``root_rotations`` (..., T, 4) the facing is the root's local +z axis rotated by the root rotation;
    otherwise the hips' left-right vector (left_hip - right_hip) crossed with up.
    Returns (..., T).
    """
    if root_rotations is not None:
        fwd = np_qrot(root_rotations, np.broadcast_to([0.0, 0.0, 1.0], np.shape(root_rotations)[:-1] + (3,)).copy())
    else:
        left = positions[..., skeleton.index("left_hip"), :] - positions[..., skeleton.index("right_hip"), :]
        fwd = np.cross(left, np.array([0.0, 1.0, 0.0]))
    return np.arctan2(fwd[..., 0], fwd[..., 2])


def _touch_downs(contact: np.ndarray, min_swing: int, cyclic: bool) -> np.ndarray:
    """Frames where a foot lands after at least ``min_swing`` frames off the ground (T,) bool -> indices."""
    T = contact.shape[0]
    if cyclic:
        ext = np.concatenate([contact, contact, contact])
        return np.array([t - T for t in _touch_downs(ext, min_swing, False) if T <= t < 2 * T], dtype=int)
    off_run = np.zeros(T, int)  # length of the off-ground run ending just before t
    run = 0
    for t in range(T):
        off_run[t] = run
        run = 0 if contact[t] else run + 1
    onsets = np.nonzero(contact[1:] & ~contact[:-1])[0] + 1
    return onsets[off_run[onsets] >= min_swing]


def _phase_from_contacts(contacts: np.ndarray, min_swing: int = 1, cyclic: bool = False) -> np.ndarray:
    """(T, 2) bool -> (T,) unwrapped phase: 0 (mod 2pi) at left touch-downs, pi at right, linear in between."""
    T = contacts.shape[0]
    if cyclic:
        ext = _phase_from_contacts(np.concatenate([contacts] * 3), min_swing, False)
        return ext[T:2 * T]
    events = []
    for side, target in ((0, 0.0), (1, np.pi)):
        events += [(int(t), target) for t in _touch_downs(contacts[:, side], min_swing, False)]
    events.sort()
    if not events:
        return np.zeros(T)
    times, values = [], []
    for t, target in events:
        if times and t == times[-1]:
            continue  # both feet touch down on one frame: keep the first
        if not values:
            v = target
        else:
            v = values[-1] + ((target - values[-1]) % (2 * np.pi) or 2 * np.pi)
        times.append(t)
        values.append(v)
    times_a, values_a = np.array(times, float), np.array(values)
    if len(times) == 1:
        return np.full(T, values_a[0])
    frames = np.arange(T, dtype=float)
    phase = np.interp(frames, times_a, values_a)
    # extrapolate linearly before the first and after the last touch-down with the nearest rate
    r0 = (values_a[1] - values_a[0]) / (times_a[1] - times_a[0])
    r1 = (values_a[-1] - values_a[-2]) / (times_a[-1] - times_a[-2])
    phase = np.where(frames < times_a[0], values_a[0] + r0 * (frames - times_a[0]), phase)
    phase = np.where(frames > times_a[-1], values_a[-1] + r1 * (frames - times_a[-1]), phase)
    return phase


def _local_quadratic(y: np.ndarray, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """Gaussian-weighted local quadratic fit of (..., T, C) signals at every frame (window +-4 sigma).

    Returns the first and second derivatives (per frame, per frame^2) of the fit, each (..., T, C). Unlike a
    plain Gaussian average this keeps the curvature of a quadratic path right up to the clip's ends.
    """
    T = y.shape[-2]
    half = int(min(np.ceil(4 * sigma), T - 1))
    S = np.zeros((5, T))
    Y = np.zeros((3,) + y.shape)
    for d in range(-half, half + 1):
        w = np.exp(-0.5 * (d / sigma) ** 2)
        lo, hi = max(0, -d), min(T, T - d)                 # frames t with 0 <= t + d < T
        for m in range(5):
            S[m, lo:hi] += w * float(d) ** m
        for m in range(3):
            Y[m][..., lo:hi, :] += w * float(d) ** m * y[..., lo + d:hi + d, :]
    M = np.stack([np.stack([S[0], S[1], S[2]], -1), np.stack([S[1], S[2], S[3]], -1),
                  np.stack([S[2], S[3], S[4]], -1)], -2)                           # (T, 3, 3)
    M[:, 2, 2] += 1e-9 * S[4] + 1e-12                                             # 2-frame clips: c -> 0
    rhs = np.moveaxis(Y, 0, -2)                                                   # (..., T, 3, C)
    coef = np.linalg.solve(np.broadcast_to(M, rhs.shape[:-2] + (3, 3)), rhs)      # (..., T, 3, C)
    return coef[..., 1, :], 2.0 * coef[..., 2, :]


def movement_features(positions: np.ndarray, fps: float, skeleton: Skeleton,
                      root_rotations: np.ndarray | None = None, contacts: np.ndarray | None = None,
                      cyclic: bool = False) -> dict:
    """Root and stepping features of seed 000 section 3.2.4.

    Args:
        positions: (..., T, J, 3) metres, y-up; joint 0 is the root.
        fps: frames per second.
        skeleton: the hierarchy (foot and hip joints are found by name).
        root_rotations: optional (..., T, 4) root quaternions; when given they define the facing direction.
        contacts: optional (..., T, 2) foot contacts; detected with :func:`detect_foot_contacts` when omitted.
        cyclic: the clip is one loopable cycle (frame T follows frame T-1 by frame 0); touch-downs across the
            seam are then found and the step phase needs no extrapolation.

    Returns:
        dict of (..., T) float64 arrays:
        - ``root_height_dev`` h: root height minus its mean over the clip (m).
        - ``root_speed`` s: ground-plane root speed (m/s), backward difference (frame 0 copies frame 1).
        - ``root_speed_lowpass`` s-bar: s through a Gaussian low-pass, sigma :data:`LOWPASS_SIGMA_S` s.
        - ``orientation_diff`` delta: signed angle from the facing direction to the trajectory tangent, radians
          in [-pi, pi) (positive = the path heads to the body's left). The tangent is taken from the low-pass root
          path (Gaussian-weighted local quadratic fit, sigma :data:`PATH_SIGMA_S` s, damping the step sway);
          0 where the root moves slower than 0.05 m/s.
        - ``curvature`` kappa: signed curvature of the same fitted ground path (1/m, positive = turning left);
          abs() gives the paper's unsigned value; 0 where the root moves slower than 0.05 m/s.
        - ``step_phase`` theta in [0, 2pi): 0 at left touch-downs, pi at right touch-downs, linear in between
          and extrapolated at the ends with the nearest step rate; constant when fewer than two touch-downs are
          seen (0 when none). A touch-down is a contact onset after at least :data:`MIN_SWING_S` s off the
          ground (a missed opposite touch-down makes the phase advance by 2pi instead of pi).
        - ``step_frequency`` omega = theta_t - theta_{t-1} of the unwrapped phase (rad/frame; frame 0 copies 1).
    """
    P = _check_sequence(positions, skeleton, fps, "movement_features")
    root = P[..., 0, :]                                       # (..., T, 3)
    T = P.shape[-3]
    y = root[..., 1]
    out = {"root_height_dev": y - y.mean(axis=-1, keepdims=True)}

    ground = root[..., [0, 2]]                                # (..., T, 2) (x, z)
    step = np.diff(ground, axis=-2)
    speed = np.linalg.norm(step, axis=-1) * fps
    speed = np.concatenate([speed[..., :1], speed], axis=-1)
    out["root_speed"] = speed
    sigma = LOWPASS_SIGMA_S * fps
    out["root_speed_lowpass"] = gaussian_filter1d(speed, sigma, axis=-1, mode="nearest")

    vel, acc = _local_quadratic(ground, PATH_SIGMA_S * fps)   # (..., T, 2) m/frame, m/frame^2 as (x, z)
    path_speed = np.linalg.norm(vel, axis=-1)                 # m/frame
    moving = path_speed * fps > _MIN_SPEED
    heading = np.arctan2(vel[..., 0], vel[..., 1])           # about +y: atan2(x, z)
    facing = facing_directions(P, skeleton, root_rotations)
    out["orientation_diff"] = np.where(moving, _wrap(heading - facing), 0.0)
    # signed curvature of a ground path (x(t), z(t)) turning about +y: (z' x'' - x' z'') / |v|^3
    cross = vel[..., 1] * acc[..., 0] - vel[..., 0] * acc[..., 1]
    out["curvature"] = np.where(moving, cross / np.maximum(path_speed, 1e-12) ** 3, 0.0)

    if contacts is None:
        contacts = detect_foot_contacts(P, fps, skeleton)
    contacts = np.asarray(contacts, dtype=bool)
    if contacts.shape != P.shape[:-2] + (2,):
        raise ValueError(f"movement_features: contacts must be {P.shape[:-2] + (2,)}, got {contacts.shape}")
    flat = contacts.reshape(-1, T, 2)
    min_swing = max(1, int(round(MIN_SWING_S * fps)))
    phase = np.stack([_phase_from_contacts(c, min_swing, cyclic) for c in flat]).reshape(P.shape[:-3] + (T,))
    out["step_phase"] = np.mod(phase, 2 * np.pi)
    omega = np.diff(phase, axis=-1)
    out["step_frequency"] = np.concatenate([omega[..., :1], omega], axis=-1)
    return out


def foot_skate(positions: np.ndarray, fps: float, skeleton: Skeleton, contacts: np.ndarray | None = None) -> dict:
    """How much feet slide while they are on the ground.

    For every pair of consecutive frames where a foot is in contact (given, or from
    :func:`detect_foot_contacts`), the ground-plane displacement of that foot's lowest joint times fps.

    Args:
        positions: (T, J, 3) metres.
        fps: frames per second.
        skeleton: gives the foot joints.
        contacts: optional (T, 2) bool.

    Returns:
        dict with ``mean_m_s`` and ``max_m_s`` (slide speed over contact frames), ``contact_share`` (fraction of
        foot-frames in contact) and ``n_contact_frames`` (number of contact frame pairs measured).
    """
    P = _check_sequence(positions, skeleton, fps, "foot_skate")
    if P.ndim != 3:
        raise ValueError(f"foot_skate: positions must be (T, J, 3), got {P.shape}")
    if contacts is None:
        contacts = detect_foot_contacts(P, fps, skeleton)
    speeds = []
    for side, joints in enumerate(foot_joints(skeleton)):
        F = P[:, joints]                                       # (T, K, 3)
        lowest = np.argmin(F[1:, :, 1], axis=1)                # (T-1,) lowest joint at frame t
        rows = np.arange(len(F) - 1)
        step = F[1:][rows, lowest][:, [0, 2]] - F[:-1][rows, lowest][:, [0, 2]]
        both = contacts[1:, side] & contacts[:-1, side]       # in contact at t-1 and t
        speeds.append(np.linalg.norm(step, axis=-1)[both] * fps)
    allv = np.concatenate(speeds)
    return {"mean_m_s": float(allv.mean()) if allv.size else 0.0, "max_m_s": float(allv.max()) if allv.size else 0.0,
            "contact_share": float(np.mean(contacts)), "n_contact_frames": int(allv.size)}
