"""Quaternion algebra in torch and numpy.

Quaternions are stored as (..., 4) arrays in (w, x, y, z) order, Hamilton convention, acting on
column vectors: ``qrot(q, v)`` rotates v by q. Functions take torch tensors; the ``np_*``
variants take and return numpy arrays (float64 unless float32 is given). torch is imported when a function
first runs, not with this module, so numpy-only callers never load it.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import torch


def qmul(q: torch.Tensor, r: torch.Tensor) -> torch.Tensor:
    """Hamilton product q * r, shapes (..., 4) broadcast."""
    import torch
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
    import torch
    qvec = q[..., 1:]
    uv = torch.cross(qvec.expand(torch.broadcast_shapes(qvec.shape, v.shape)),
                     v.expand(torch.broadcast_shapes(qvec.shape, v.shape)), dim=-1)
    uuv = torch.cross(qvec.expand_as(uv), uv, dim=-1)
    return v + 2.0 * (q[..., :1] * uv + uuv)


def qfrom_axis_angle(axis: torch.Tensor, angle: torch.Tensor) -> torch.Tensor:
    """Quaternion from axis (..., 3) (normalised here) and angle (...) in radians."""
    import torch
    axis = axis / axis.norm(dim=-1, keepdim=True).clamp_min(1e-12)
    half = 0.5 * angle
    return torch.cat((torch.cos(half)[..., None], torch.sin(half)[..., None] * axis), dim=-1)


def qbetween(u: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Shortest-arc unit quaternion rotating direction u (..., 3) onto direction v (..., 3)."""
    import torch
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
    import torch
    out = q.clone()
    dots = (out[..., 1:, :, :] * out[..., :-1, :, :]).sum(-1)
    flips = (torch.cumsum((dots < 0).to(torch.int64), dim=-2) % 2).bool()
    out[..., 1:, :, :] = torch.where(flips[..., None], -out[..., 1:, :, :], out[..., 1:, :, :])
    return out


def qslerp(q0: torch.Tensor, q1: torch.Tensor, t: torch.Tensor | float) -> torch.Tensor:
    """Spherical interpolation between unit quaternions (..., 4) at fraction t (broadcast (...))."""
    import torch
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
    import torch
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
    import torch
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
    import torch
    dot = (q * r).sum(-1).abs().clamp(max=1.0)
    return 2.0 * torch.acos(dot)


def _np(fn):
    def wrapper(*arrays, **kwargs):
        import torch
        tensors = [torch.from_numpy(np.array(a, dtype=np.float64)) if not isinstance(a, (float, int, str))
                   else a for a in arrays]
        return fn(*tensors, **kwargs).numpy()

    wrapper.__name__ = "np_" + fn.__name__
    wrapper.__doc__ = f"numpy version of :func:`{fn.__name__}` (float64)."
    return wrapper


np_qmul = _np(qmul)
np_qconj = _np(qconj)
np_qnormalize = _np(qnormalize)
np_qrot = _np(qrot)
np_qfrom_axis_angle = _np(qfrom_axis_angle)
np_qbetween = _np(qbetween)
np_qfix = _np(qfix)
np_qslerp = _np(qslerp)
np_qeuler = _np(qeuler)
np_qfrom_euler = _np(qfrom_euler)
np_qto_matrix = _np(qto_matrix)
np_qangle = _np(qangle)


def identity(shape: tuple[int, ...] = ()) -> np.ndarray:
    """Identity quaternions of shape (*shape, 4), float64."""
    q = np.zeros(tuple(shape) + (4,))
    q[..., 0] = 1.0
    return q
