"""Inverse kinematics: global joint positions to local joint rotations on a skeleton.

The solver is analytic and works joint by joint from the root outwards (numpy, batched over frames):
- a joint with two or more children (with non-zero offsets) gets a full orientation: the rotation that best
  maps its children's rest offsets onto the observed directions to those children (weighted Kabsch/Wahba, SVD),
- a joint with one child gets the shortest-arc swing from its rest direction onto the observed direction,
  measured in the parent's frame (zero twist relative to the parent, so twist never jumps from frame to frame
  except when a bone points straight opposite its rest direction, which the body does not do),
- a leaf joint keeps the identity local rotation (it follows its parent).
Only directions are used, so positions with the skeleton's bone lengths are reproduced exactly (to ~1e-12 m);
other positions give the closest pose with the skeleton's bone lengths, and :class:`IKReport` says how far off.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kinematics import np_forward_kinematics
from .motion import Motion, MotionFormatError
from .quaternion import np_qfix, np_qmul, np_qrot
from .skeleton import Skeleton


@dataclass(frozen=True)
class IKReport:
    """Accuracy of an IK solution: distances between FK of the result and the input positions, metres."""

    max_error_m: float
    mean_error_m: float
    per_joint_max_m: tuple[float, ...]

    def __str__(self) -> str:
        return f"IK error max {self.max_error_m:.3g} m, mean {self.mean_error_m:.3g} m"


def _conj(q: np.ndarray) -> np.ndarray:
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def matrix_to_quaternion(m: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) to unit quaternions (..., 4) (w, x, y, z), w >= 0 (Shepperd's method)."""
    m = np.asarray(m, dtype=np.float64)
    tr = np.trace(m, axis1=-2, axis2=-1)
    diag = np.stack([m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]], -1)
    # 4 candidate (unnormalised) quaternions; pick the best-conditioned per matrix
    cands = np.stack([
        np.stack([1 + tr, m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0], m[..., 1, 0] - m[..., 0, 1]], -1),
        np.stack([m[..., 2, 1] - m[..., 1, 2], 1 + 2 * diag[..., 0] - tr, m[..., 0, 1] + m[..., 1, 0],
                  m[..., 0, 2] + m[..., 2, 0]], -1),
        np.stack([m[..., 0, 2] - m[..., 2, 0], m[..., 0, 1] + m[..., 1, 0], 1 + 2 * diag[..., 1] - tr,
                  m[..., 1, 2] + m[..., 2, 1]], -1),
        np.stack([m[..., 1, 0] - m[..., 0, 1], m[..., 0, 2] + m[..., 2, 0], m[..., 1, 2] + m[..., 2, 1],
                  1 + 2 * diag[..., 2] - tr], -1),
    ], -2)                                                     # (..., 4, 4)
    key = np.concatenate([tr[..., None], diag], -1)            # choose by largest of tr, m00, m11, m22
    best = np.argmax(key, axis=-1)
    q = np.take_along_axis(cands, best[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)


def _swing(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Shortest-arc quaternions (..., 4) rotating directions u (..., 3) onto v (..., 3)."""
    u = u / np.maximum(np.linalg.norm(u, axis=-1, keepdims=True), 1e-300)
    v = v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-300)
    dot = (u * v).sum(-1, keepdims=True)
    q = np.concatenate([1.0 + dot, np.cross(u, v)], -1)
    opposite = dot[..., 0] < -1.0 + 1e-12
    if opposite.any():
        axis = np.cross(u, [1.0, 0.0, 0.0])
        small = np.linalg.norm(axis, axis=-1, keepdims=True) < 1e-6
        axis = np.where(small, np.cross(u, [0.0, 0.0, 1.0]), axis)
        q = np.where(opposite[..., None], np.concatenate([np.zeros_like(dot), axis], -1), q)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def _kabsch(rest: np.ndarray, target: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Rotations R (T, 4) minimising sum_k w_k |R rest_k - target_k|^2; rest (K, 3) unit, target (T, K, 3) unit."""
    H = np.einsum("k,ki,tkj->tij", weights, rest, target)     # (T, 3, 3) = sum w r t^T
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(np.einsum("tji,tkj->tik", Vt, U)))
    d = np.where(d == 0, 1.0, d)
    D = np.zeros_like(H)
    D[:, 0, 0] = 1.0
    D[:, 1, 1] = 1.0
    D[:, 2, 2] = d
    R = np.einsum("tji,tjk,tlk->til", Vt, D, U)               # V D U^T
    return matrix_to_quaternion(R)


def solve_rotations(positions: np.ndarray, skeleton: Skeleton, known: np.ndarray | None = None) -> np.ndarray:
    """Local rotations (T, J, 4) whose FK directions match ``positions`` (T, J, 3).

    ``known`` (J,) bool marks joints whose positions are meaningful; unknown children are ignored when
    orienting their parent (a joint with no known child keeps the identity local rotation).
    """
    T, J = positions.shape[0], skeleton.num_joints
    known = np.ones(J, bool) if known is None else np.asarray(known, bool)
    offsets = skeleton.offsets
    lengths = np.linalg.norm(offsets, axis=1)
    children = skeleton.children()
    local = np.zeros((T, J, 4))
    local[..., 0] = 1.0
    glob = np.zeros((T, J, 4))
    for j in range(J):
        p = skeleton.parents[j]
        parent_rot = glob[:, p] if p >= 0 else np.tile([1.0, 0.0, 0.0, 0.0], (T, 1))
        kids = [c for c in children[j] if known[c] and known[j] and lengths[c] > 1e-9]
        if kids:
            # observed child directions in the parent's frame
            d = positions[:, kids] - positions[:, j:j + 1]                      # (T, K, 3)
            d = np_qrot(np.repeat(_conj(parent_rot)[:, None], len(kids), 1), d)
            d = d / np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-300)
            rest = offsets[kids] / lengths[kids, None]
            if len(kids) == 1:
                local[:, j] = _swing(np.broadcast_to(rest[0], (T, 3)), d[:, 0])
            else:
                rank2 = np.linalg.norm(np.cross(rest[:, None], rest[None]), axis=-1).max() > 1e-6
                if rank2:
                    local[:, j] = _kabsch(rest, d, lengths[kids])
                else:  # collinear children: a swing onto their mean direction
                    local[:, j] = _swing(np.broadcast_to(rest[0], (T, 3)), d.mean(1))
        glob[:, j] = np_qmul(parent_rot, local[:, j]) if p >= 0 else local[:, j]
    return np_qfix(local)


def inverse_kinematics(positions: np.ndarray, skeleton: Skeleton, fps: float = 30.0,
                       metadata: dict | None = None) -> tuple[Motion, IKReport]:
    """Fit local rotations on ``skeleton`` to joint positions.

    Args:
        positions: (T, J, 3) global joint positions in metres (y-up), joints in ``skeleton.joints`` order.
        skeleton: the target hierarchy; its bone lengths are kept.
        fps: frame rate of the result.
        metadata: copied into the Motion.

    Returns:
        (Motion with rotations (T, J, 4) and root positions = positions[:, 0], IKReport of FK vs input).
    """
    P = np.asarray(positions, dtype=np.float64)
    if P.ndim == 2:
        P = P[None]
    if P.ndim != 3 or P.shape[1:] != (skeleton.num_joints, 3):
        raise MotionFormatError(f"inverse_kinematics: positions must be (T, {skeleton.num_joints}, 3) for skeleton "
                                f"{skeleton.name!r}, got {np.shape(positions)}")
    if not np.isfinite(P).all():
        raise MotionFormatError("inverse_kinematics: positions contain NaN or infinite values")
    rotations = solve_rotations(P, skeleton)
    motion = Motion(skeleton, rotations, P[:, 0].copy(), fps, dict(metadata or {}))
    return motion, ik_report(motion, P)


def ik_report(motion: Motion, positions: np.ndarray) -> IKReport:
    """Distances between ``motion.positions()`` and ``positions`` (T, J, 3)."""
    err = np.linalg.norm(np_forward_kinematics(motion.rotations, motion.root_positions, motion.skeleton)
                         - positions, axis=-1)
    return IKReport(float(err.max()), float(err.mean()), tuple(float(e) for e in err.max(0)))


def fit_positions_to_skeleton(positions: np.ndarray, skeleton: Skeleton) -> tuple[np.ndarray, float, float]:
    """Make positions exactly representable on the skeleton (bone lengths and rigid joint groups restored).

    Used after Cartesian edits (e.g. the RBF styliser) that stretch bones. The positions are solved with the
    IK of this module and put back through FK from the same root position, so: every bone gets its rest length;
    a bone below a single-child joint keeps its observed direction exactly; the children of a branching joint
    (hips around the pelvis, shoulders and neck around the spine) move as one rigid group turned to fit the
    observed directions best (weighted Kabsch). Bones of zero observed length keep the parent's orientation.

    Args:
        positions: (..., J, 3) metres.
        skeleton: gives parents and offsets.

    Returns:
        (fitted positions (..., J, 3), largest |bone length - rest length| before, and after, in metres).
    """
    P = np.asarray(positions, dtype=np.float64)
    if P.ndim < 2 or P.shape[-2:] != (skeleton.num_joints, 3):
        raise ValueError(f"fit_positions_to_skeleton: positions must be (..., {skeleton.num_joints}, 3), "
                         f"got {P.shape}")
    flat = P.reshape(-1, skeleton.num_joints, 3)
    rotations = solve_rotations(flat, skeleton)
    out = np_forward_kinematics(rotations, flat[:, 0], skeleton).reshape(P.shape)
    return out, _max_length_deviation(P, skeleton), _max_length_deviation(out, skeleton)


def _max_length_deviation(P: np.ndarray, skeleton: Skeleton) -> float:
    parents = list(skeleton.parents[1:])
    lengths = np.linalg.norm(P[..., 1:, :] - P[..., parents, :], axis=-1)
    return float(np.abs(lengths - skeleton.bone_lengths()[1:]).max())


def bend_limb_to_target(positions: np.ndarray, skeleton: Skeleton, end: str, target: np.ndarray) -> np.ndarray:
    """Move a two-bone chain (e.g. hip-knee-heel) so its end reaches ``target``, keeping bone lengths.

    The upper joint (the end's grandparent) stays where it is; the middle joint bends in the plane through the
    upper joint, the target and the current middle joint (so a knee keeps bending the way it bent); the end and
    everything below it move rigidly with the end. Out-of-reach targets are approached along the same line.

    Args:
        positions: (T, J, 3) positions consistent with the skeleton (e.g. from FK), metres.
        skeleton: gives parents and bone lengths.
        end: name of the chain's end joint (its parent is the middle joint, the grandparent the upper one).
        target: (T, 3) desired end positions, metres.

    Returns:
        New (T, J, 3) positions (a copy).
    """
    P = np.array(positions, dtype=np.float64)
    e = skeleton.index(end)
    m = skeleton.parents[e]
    u_idx = skeleton.parents[m] if m >= 0 else -1
    if u_idx < 0:
        raise ValueError(f"bend_limb_to_target: {end!r} needs a parent and a grandparent")
    lengths = skeleton.bone_lengths()
    l1, l2 = lengths[m], lengths[e]
    H = P[:, u_idx]
    to_target = np.asarray(target, dtype=np.float64) - H
    dist = np.linalg.norm(to_target, axis=-1, keepdims=True)
    axis = to_target / np.maximum(dist, 1e-12)
    dist = np.clip(dist, abs(l1 - l2) + 1e-6, l1 + l2 - 1e-6)
    cos_a = np.clip((l1 * l1 + dist * dist - l2 * l2) / (2 * l1 * dist), -1.0, 1.0)
    pole = P[:, m] - H
    perp = pole - (pole * axis).sum(-1, keepdims=True) * axis
    n = np.linalg.norm(perp, axis=-1, keepdims=True)
    # a straight chain has no bend plane: fall back to the previous frame's, or the rest bend direction
    fallback = np.cross(axis, np.array([1.0, 0.0, 0.0]))
    perp = np.where(n > 1e-6 * l1, perp / np.maximum(n, 1e-12), fallback / np.maximum(
        np.linalg.norm(fallback, axis=-1, keepdims=True), 1e-12))
    knee = H + l1 * (cos_a * axis + np.sqrt(1 - cos_a ** 2) * perp)
    new_end = H + dist * axis
    below = _descendants(skeleton, e)
    shift = new_end - P[:, e]
    P[:, m] = knee
    P[:, e] = new_end
    for j in below:
        P[:, j] += shift
    return P


def _descendants(skeleton: Skeleton, j: int) -> list[int]:
    out, stack, kids = [], [j], skeleton.children()
    while stack:
        for c in kids[stack.pop()]:
            out.append(c)
            stack.append(c)
    return out
