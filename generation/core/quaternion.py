"""Quaternion algebra in torch and numpy.

Quaternions are stored as (..., 4) arrays in (w, x, y, z) order, Hamilton convention, acting on
column vectors: ``qrot(q, v)`` rotates v by q. Functions take torch tensors; the ``np_*``
variants take and return float64 numpy arrays and are written in numpy (the same formulas, step by step), so
numpy callers never load torch; the torch functions import torch when they first run.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import torch


def qmul(q: torch.Tensor, r: torch.Tensor) -> torch.Tensor:
    """Hamilton product q * r, shapes (..., 4) broadcast."""
    import torch  # heavy: only the torch functions load torch
    w1, x1, y1, z1 = q.unbind(-1)
    w2, x2, y2, z2 = r.unbind(-1)
    return torch.stack(
        (
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ),
        dim=-1,
    )


def qconj(q: torch.Tensor) -> torch.Tensor:
    """Conjugate (the inverse of a unit quaternion), (..., 4)."""
    return q * q.new_tensor([1.0, -1.0, -1.0, -1.0])


def qnormalize(q: torch.Tensor, eps: float = 1e-8) -> torch.Tensor:
    """Scale (..., 4) to unit length."""
    return q / q.norm(dim=-1, keepdim=True).clamp_min(eps)


def qrot(q: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Rotate vectors v (..., 3) by unit quaternions q (..., 4); leading shapes broadcast."""
    import torch  # heavy: only the torch functions load torch
    qvec = q[..., 1:]
    uv = torch.cross(qvec.expand(torch.broadcast_shapes(qvec.shape, v.shape)),
                     v.expand(torch.broadcast_shapes(qvec.shape, v.shape)), dim=-1)
    uuv = torch.cross(qvec.expand_as(uv), uv, dim=-1)
    return v + 2.0 * (q[..., :1] * uv + uuv)


def qfrom_axis_angle(axis: torch.Tensor, angle: torch.Tensor) -> torch.Tensor:
    """Quaternion from axis (..., 3) (normalised here) and angle (...) in radians."""
    import torch  # heavy: only the torch functions load torch
    axis = axis / axis.norm(dim=-1, keepdim=True).clamp_min(1e-12)
    half = 0.5 * angle
    return torch.cat((torch.cos(half)[..., None], torch.sin(half)[..., None] * axis), dim=-1)


def qbetween(u: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Shortest-arc unit quaternion rotating direction u (..., 3) onto direction v (..., 3)."""
    import torch  # heavy: only the torch functions load torch
    u = u / u.norm(dim=-1, keepdim=True).clamp_min(1e-12)
    v = v / v.norm(dim=-1, keepdim=True).clamp_min(1e-12)
    dot = (u * v).sum(-1, keepdim=True)
    cross = torch.cross(u, v, dim=-1)
    q = torch.cat((1.0 + dot, cross), dim=-1)
    # Opposite vectors: rotate by pi about any axis orthogonal to u.
    opposite = (dot[..., 0] < -1.0 + 1e-7)
    if opposite.any():
        ortho = torch.cross(u, u.new_tensor([1.0, 0.0, 0.0]).expand_as(u), dim=-1)
        small = ortho.norm(dim=-1, keepdim=True) < 1e-6
        ortho = torch.where(small, torch.cross(u, u.new_tensor([0.0, 1.0, 0.0]).expand_as(u), dim=-1), ortho)
        q = torch.where(opposite[..., None], torch.cat((torch.zeros_like(dot), ortho), dim=-1), q)
    return qnormalize(q)


def qfix(q: torch.Tensor) -> torch.Tensor:
    """Flip signs along time (dim -3 of (..., T, J, 4)) so consecutive quaternions have w-continuity."""
    import torch  # heavy: only the torch functions load torch
    out = q.clone()
    dots = (out[..., 1:, :, :] * out[..., :-1, :, :]).sum(-1)
    flips = (torch.cumsum((dots < 0).to(torch.int64), dim=-2) % 2).bool()
    out[..., 1:, :, :] = torch.where(flips[..., None], -out[..., 1:, :, :], out[..., 1:, :, :])
    return out


def qslerp(q0: torch.Tensor, q1: torch.Tensor, t: torch.Tensor | float) -> torch.Tensor:
    """Spherical interpolation between unit quaternions (..., 4) at fraction t (broadcast (...))."""
    import torch  # heavy: only the torch functions load torch
    t = torch.as_tensor(t, dtype=q0.dtype, device=q0.device)
    dot = (q0 * q1).sum(-1, keepdim=True)
    q1 = torch.where(dot < 0, -q1, q1)
    dot = dot.abs().clamp(max=1.0)
    theta = torch.acos(dot)
    sin_theta = torch.sin(theta)
    t = t[..., None] if t.dim() > 0 else t
    linear = sin_theta < 1e-6
    w0 = torch.where(linear, 1.0 - t, torch.sin((1.0 - t) * theta) / sin_theta.clamp_min(1e-12))
    w1 = torch.where(linear, t * torch.ones_like(theta), torch.sin(t * theta) / sin_theta.clamp_min(1e-12))
    return qnormalize(w0 * q0 + w1 * q1)


_EULER_AXES = {"x": 0, "y": 1, "z": 2}


def qeuler(q: torch.Tensor, order: str = "zyx", eps: float = 1e-7) -> torch.Tensor:
    """Unit quaternions (..., 4) to Euler angles (..., 3) in radians, intrinsic axes in ``order``.

    ``order`` names the axes as they are applied to a vector last-to-first, as in QuaterNet:
    the result [a, b, c] satisfies q = R_order[0](a) * R_order[1](b) * R_order[2](c) for "xyz"
    style orders. Supported: xyz, yzx, zxy, xzy, yxz, zyx.
    """
    import torch  # heavy: only the torch functions load torch
    q0, q1, q2, q3 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    if order == "xyz":
        x = torch.atan2(2 * (q0 * q1 - q2 * q3), 1 - 2 * (q1 * q1 + q2 * q2))
        y = torch.asin(torch.clamp(2 * (q1 * q3 + q0 * q2), -1 + eps, 1 - eps))
        z = torch.atan2(2 * (q0 * q3 - q1 * q2), 1 - 2 * (q2 * q2 + q3 * q3))
    elif order == "yzx":
        x = torch.atan2(2 * (q0 * q1 - q2 * q3), 1 - 2 * (q1 * q1 + q3 * q3))
        y = torch.atan2(2 * (q0 * q2 - q1 * q3), 1 - 2 * (q2 * q2 + q3 * q3))
        z = torch.asin(torch.clamp(2 * (q1 * q2 + q0 * q3), -1 + eps, 1 - eps))
    elif order == "zxy":
        x = torch.asin(torch.clamp(2 * (q0 * q1 + q2 * q3), -1 + eps, 1 - eps))
        y = torch.atan2(2 * (q0 * q2 - q1 * q3), 1 - 2 * (q1 * q1 + q2 * q2))
        z = torch.atan2(2 * (q0 * q3 - q1 * q2), 1 - 2 * (q1 * q1 + q3 * q3))
    elif order == "xzy":
        x = torch.atan2(2 * (q0 * q1 + q2 * q3), 1 - 2 * (q1 * q1 + q3 * q3))
        y = torch.atan2(2 * (q0 * q2 + q1 * q3), 1 - 2 * (q2 * q2 + q3 * q3))
        z = torch.asin(torch.clamp(2 * (q0 * q3 - q1 * q2), -1 + eps, 1 - eps))
    elif order == "yxz":
        x = torch.asin(torch.clamp(2 * (q0 * q1 - q2 * q3), -1 + eps, 1 - eps))
        y = torch.atan2(2 * (q1 * q3 + q0 * q2), 1 - 2 * (q1 * q1 + q2 * q2))
        z = torch.atan2(2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3))
    elif order == "zyx":
        x = torch.atan2(2 * (q0 * q1 + q2 * q3), 1 - 2 * (q1 * q1 + q2 * q2))
        y = torch.asin(torch.clamp(2 * (q0 * q2 - q1 * q3), -1 + eps, 1 - eps))
        z = torch.atan2(2 * (q0 * q3 + q1 * q2), 1 - 2 * (q2 * q2 + q3 * q3))
    else:
        raise ValueError(f"unsupported Euler order {order!r}")
    return torch.stack((x, y, z), dim=-1)


def qfrom_euler(angles: torch.Tensor, order: str = "zyx") -> torch.Tensor:
    """Euler angles (..., 3) = (x, y, z) radians to quaternions, composed as order[0]*order[1]*order[2].

    Inverse of :func:`qeuler` for the same order.
    """
    unit = {
        "x": angles.new_tensor([1.0, 0.0, 0.0]),
        "y": angles.new_tensor([0.0, 1.0, 0.0]),
        "z": angles.new_tensor([0.0, 0.0, 1.0]),
    }
    result = None
    for axis in order:
        r = qfrom_axis_angle(unit[axis].expand(angles.shape), angles[..., _EULER_AXES[axis]])
        result = r if result is None else qmul(result, r)
    return result


def qto_matrix(q: torch.Tensor) -> torch.Tensor:
    """Unit quaternions (..., 4) to rotation matrices (..., 3, 3)."""
    import torch  # heavy: only the torch functions load torch
    w, x, y, z = q.unbind(-1)
    return torch.stack(
        (
            1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
        ),
        dim=-1,
    ).reshape(q.shape[:-1] + (3, 3))


def qangle(q: torch.Tensor, r: torch.Tensor) -> torch.Tensor:
    """Geodesic angle in radians between unit quaternions (..., 4), in [0, pi]."""
    import torch  # heavy: only the torch functions load torch
    dot = (q * r).sum(-1).abs().clamp(max=1.0)
    return 2.0 * torch.acos(dot)


# ---- numpy versions (float64; the same formulas as the torch functions above) ---------------------------
def _f64(a) -> np.ndarray:
    return np.asarray(a, dtype=np.float64)


def np_qmul(q, r) -> np.ndarray:
    """numpy version of :func:`qmul` (float64)."""
    w1, x1, y1, z1 = np.moveaxis(_f64(q), -1, 0)
    w2, x2, y2, z2 = np.moveaxis(_f64(r), -1, 0)
    return np.stack((w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2), axis=-1)


def np_qconj(q) -> np.ndarray:
    """numpy version of :func:`qconj` (float64)."""
    return _f64(q) * np.array([1.0, -1.0, -1.0, -1.0])


def np_qnormalize(q, eps: float = 1e-8) -> np.ndarray:
    """numpy version of :func:`qnormalize` (float64)."""
    q = _f64(q)
    return q / np.maximum(np.sqrt((q * q).sum(-1, keepdims=True)), eps)


def np_qrot(q, v) -> np.ndarray:
    """numpy version of :func:`qrot` (float64)."""
    q, v = _f64(q), _f64(v)
    qvec = q[..., 1:]
    shape = np.broadcast_shapes(qvec.shape, v.shape)
    uv = np.cross(np.broadcast_to(qvec, shape), np.broadcast_to(v, shape))
    uuv = np.cross(np.broadcast_to(qvec, uv.shape), uv)
    return v + 2.0 * (q[..., :1] * uv + uuv)


def np_qfrom_axis_angle(axis, angle) -> np.ndarray:
    """numpy version of :func:`qfrom_axis_angle` (float64)."""
    axis, angle = _f64(axis), _f64(angle)
    axis = axis / np.maximum(np.sqrt((axis * axis).sum(-1, keepdims=True)), 1e-12)
    half = 0.5 * angle
    return np.concatenate((np.cos(half)[..., None], np.sin(half)[..., None] * axis), axis=-1)


def np_qbetween(u, v) -> np.ndarray:
    """numpy version of :func:`qbetween` (float64)."""
    u, v = _f64(u), _f64(v)
    u = u / np.maximum(np.sqrt((u * u).sum(-1, keepdims=True)), 1e-12)
    v = v / np.maximum(np.sqrt((v * v).sum(-1, keepdims=True)), 1e-12)
    dot = (u * v).sum(-1, keepdims=True)
    q = np.concatenate((1.0 + dot, np.cross(u, v)), axis=-1)
    opposite = dot[..., 0] < -1.0 + 1e-7
    if opposite.any():
        ortho = np.cross(u, np.broadcast_to([1.0, 0.0, 0.0], u.shape))
        small = np.sqrt((ortho * ortho).sum(-1, keepdims=True)) < 1e-6
        ortho = np.where(small, np.cross(u, np.broadcast_to([0.0, 1.0, 0.0], u.shape)), ortho)
        q = np.where(opposite[..., None], np.concatenate((np.zeros_like(dot), ortho), axis=-1), q)
    return np_qnormalize(q)


def np_qfix(q) -> np.ndarray:
    """numpy version of :func:`qfix` (float64): signs flipped along time (axis -3 of (..., T, J, 4))."""
    out = _f64(q).copy()
    dots = (out[..., 1:, :, :] * out[..., :-1, :, :]).sum(-1)
    flips = (np.cumsum(dots < 0, axis=-2) % 2).astype(bool)
    out[..., 1:, :, :] = np.where(flips[..., None], -out[..., 1:, :, :], out[..., 1:, :, :])
    return out


def np_qslerp(q0, q1, t) -> np.ndarray:
    """numpy version of :func:`qslerp` (float64)."""
    q0, q1, t = _f64(q0), _f64(q1), _f64(t)
    dot = (q0 * q1).sum(-1, keepdims=True)
    q1 = np.where(dot < 0, -q1, q1)
    dot = np.minimum(np.abs(dot), 1.0)
    theta = np.arccos(dot)
    sin_theta = np.sin(theta)
    t = t[..., None] if t.ndim > 0 else t
    linear = sin_theta < 1e-6
    safe = np.maximum(sin_theta, 1e-12)
    w0 = np.where(linear, 1.0 - t, np.sin((1.0 - t) * theta) / safe)
    w1 = np.where(linear, t * np.ones_like(theta), np.sin(t * theta) / safe)
    return np_qnormalize(w0 * q0 + w1 * q1)


def np_qeuler(q, order: str = "zyx", eps: float = 1e-7) -> np.ndarray:
    """numpy version of :func:`qeuler` (float64)."""
    q = _f64(q)
    q0, q1, q2, q3 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]

    def asin(a):
        return np.arcsin(np.clip(a, -1 + eps, 1 - eps))

    if order == "xyz":
        x, y, z = (np.arctan2(2 * (q0 * q1 - q2 * q3), 1 - 2 * (q1 * q1 + q2 * q2)), asin(2 * (q1 * q3 + q0 * q2)),
                   np.arctan2(2 * (q0 * q3 - q1 * q2), 1 - 2 * (q2 * q2 + q3 * q3)))
    elif order == "yzx":
        x, y, z = (np.arctan2(2 * (q0 * q1 - q2 * q3), 1 - 2 * (q1 * q1 + q3 * q3)),
                   np.arctan2(2 * (q0 * q2 - q1 * q3), 1 - 2 * (q2 * q2 + q3 * q3)), asin(2 * (q1 * q2 + q0 * q3)))
    elif order == "zxy":
        x, y, z = (asin(2 * (q0 * q1 + q2 * q3)), np.arctan2(2 * (q0 * q2 - q1 * q3), 1 - 2 * (q1 * q1 + q2 * q2)),
                   np.arctan2(2 * (q0 * q3 - q1 * q2), 1 - 2 * (q1 * q1 + q3 * q3)))
    elif order == "xzy":
        x, y, z = (np.arctan2(2 * (q0 * q1 + q2 * q3), 1 - 2 * (q1 * q1 + q3 * q3)),
                   np.arctan2(2 * (q0 * q2 + q1 * q3), 1 - 2 * (q2 * q2 + q3 * q3)), asin(2 * (q0 * q3 - q1 * q2)))
    elif order == "yxz":
        x, y, z = (asin(2 * (q0 * q1 - q2 * q3)), np.arctan2(2 * (q1 * q3 + q0 * q2), 1 - 2 * (q1 * q1 + q2 * q2)),
                   np.arctan2(2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3)))
    elif order == "zyx":
        x, y, z = (np.arctan2(2 * (q0 * q1 + q2 * q3), 1 - 2 * (q1 * q1 + q2 * q2)), asin(2 * (q0 * q2 - q1 * q3)),
                   np.arctan2(2 * (q0 * q3 + q1 * q2), 1 - 2 * (q2 * q2 + q3 * q3)))
    else:
        raise ValueError(f"unsupported Euler order {order!r}")
    return np.stack((x, y, z), axis=-1)


def np_qfrom_euler(angles, order: str = "zyx") -> np.ndarray:
    """numpy version of :func:`qfrom_euler` (float64)."""
    angles = _f64(angles)
    unit = {"x": [1.0, 0.0, 0.0], "y": [0.0, 1.0, 0.0], "z": [0.0, 0.0, 1.0]}
    result = None
    for axis in order:
        r = np_qfrom_axis_angle(np.broadcast_to(unit[axis], angles.shape), angles[..., _EULER_AXES[axis]])
        result = r if result is None else np_qmul(result, r)
    return result


def np_qto_matrix(q) -> np.ndarray:
    """numpy version of :func:`qto_matrix` (float64)."""
    q = _f64(q)
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack((1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                     2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                     2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)),
                    axis=-1).reshape(q.shape[:-1] + (3, 3))


def np_qangle(q, r) -> np.ndarray:
    """numpy version of :func:`qangle` (float64)."""
    dot = np.minimum(np.abs((_f64(q) * _f64(r)).sum(-1)), 1.0)
    return 2.0 * np.arccos(dot)


def identity(shape: tuple[int, ...] = ()) -> np.ndarray:
    """Identity quaternions of shape (*shape, 4), float64."""
    q = np.zeros(tuple(shape) + (4,))
    q[..., 0] = 1.0
    return q
