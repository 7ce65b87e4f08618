"""Small numpy rigging helpers shared by the procedural generators and the networks' data code:
eases, axis-angle and yaw quaternions, frame alignment, analytic two-bone IK, hinge-chain rotations and
global-to-local rotations. Angles in radians, positions in metres, quaternions (w, x, y, z)."""
from __future__ import annotations

import numpy as np

from .ik import matrix_to_quaternion
from .quaternion import np_qconj, np_qfrom_axis_angle, np_qmul

Y_AXIS = np.array([0.0, 1.0, 0.0])


def smoothstep(x):
    """Cubic ease 3x^2 - 2x^3 on [0, 1] (clipped)."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def minjerk(x):
    """Minimum-jerk ease 10x^3 - 15x^4 + 6x^5 on [0, 1] (clipped)."""
    x = np.clip(x, 0.0, 1.0)
    return x ** 3 * (10.0 - 15.0 * x + 6.0 * x * x)


def axis_angle(axis, angle) -> np.ndarray:
    """Quaternions (..., 4) for rotations by ``angle`` (...) about a fixed ``axis`` (3,)."""
    angle = np.asarray(angle, dtype=np.float64)
    return np_qfrom_axis_angle(np.broadcast_to(np.asarray(axis, dtype=np.float64), angle.shape + (3,)), angle)


def yaw_quat(heading) -> np.ndarray:
    """Rotation about +y by ``heading`` (radians, 0 = facing +z, + toward +x)."""
    return axis_angle(Y_AXIS, heading)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def frame_rotation(rest_dir, rest_hint, dir_, hint) -> np.ndarray:
    """Rotation (..., 4) taking the frame (rest_dir, rest_hint) onto (dir_, hint).

    Each frame is the orthonormal basis made of the unit direction, the hint made orthogonal to
    it, and their cross product; the rotation maps the first basis onto the second.
    """
    def basis(a, b):
        a = _unit(np.asarray(a, dtype=np.float64))
        b = np.asarray(b, dtype=np.float64)
        b = _unit(b - (b * a).sum(-1, keepdims=True) * a)
        return np.stack([a, b, np.cross(a, b)], axis=-1)  # columns

    b0 = basis(rest_dir, rest_hint)
    b1 = basis(dir_, hint)
    b0, b1 = np.broadcast_arrays(b0, b1)
    return matrix_to_quaternion(b1 @ np.swapaxes(b0, -1, -2))


def two_bone_ik(root, target, len_upper, len_lower, pole):
    """Analytic two-bone IK: the middle joint position for a chain root -> mid -> end.

    Args:
        root: (..., 3) first joint (hip/shoulder) positions.
        target: (..., 3) desired end (ankle/wrist) positions.
        len_upper, len_lower: bone lengths in metres.
        pole: (..., 3) direction the middle joint bends toward (knee forward, elbow back/out).

    Returns:
        mid (..., 3), end (..., 3) reachable end position (= target when reachable), reach (...)
        ratio |target - root| / (len_upper + len_lower).
    """
    d_vec = target - root
    dist = np.linalg.norm(d_vec, axis=-1)
    u = d_vec / np.maximum(dist, 1e-9)[..., None]
    d = np.clip(dist, abs(len_upper - len_lower) + 1e-6, (len_upper + len_lower) * (1.0 - 1e-9))
    cos_a = np.clip((len_upper ** 2 + d ** 2 - len_lower ** 2) / (2.0 * len_upper * d), -1.0, 1.0)
    sin_a = np.sqrt(1.0 - cos_a ** 2)
    n = pole - (pole * u).sum(-1, keepdims=True) * u
    n = _unit(n)
    mid = root + len_upper * (cos_a[..., None] * u + sin_a[..., None] * n)
    end = root + d[..., None] * u
    return mid, end, dist / (len_upper + len_lower)


def hinge_rotations(root, mid, end, offset_upper, offset_lower, rest_bend, fallback_bend):
    """Global rotations (..., 4) of the upper and lower bone of a hinge chain (thigh-shin, upper arm-forearm).

    Args:
        root, mid, end: (..., 3) joint positions (hip, knee, ankle) from :func:`two_bone_ik`.
        offset_upper, offset_lower: (3,) rest offsets of ``mid`` and ``end``.
        rest_bend: (3,) direction, in the rest frame, toward which the lower bone bends (-z for
            knees, +z for elbows).
        fallback_bend: (..., 3) bend direction used when the chain is straight.

    The lower bone's frame is the upper one turned about the hinge axis, so there is no twist
    between them and no flip when the lower bone points along the bend direction.
    """
    u = _unit(mid - root)
    f = _unit(end - mid)
    b = f - (f * u).sum(-1, keepdims=True) * u
    fb = fallback_bend - (fallback_bend * u).sum(-1, keepdims=True) * u
    b = _unit(b + 1e-4 * _unit(fb))
    ce = (f * u).sum(-1, keepdims=True)
    se = (f * b).sum(-1, keepdims=True)
    q_upper = frame_rotation(offset_upper, rest_bend, u, b)
    q_lower = frame_rotation(offset_lower, rest_bend, f, -se * u + ce * b)
    return q_upper, q_lower


def locals_from_globals(global_rot: np.ndarray, parents) -> np.ndarray:
    """Local rotations (..., J, 4) from global ones: R_local[j] = R_global[parent]^-1 R_global[j]."""
    local = global_rot.copy()
    for j, p in enumerate(parents):
        if p >= 0:
            local[..., j, :] = np_qmul(np_qconj(global_rot[..., p, :]), global_rot[..., j, :])
    return local
