"""Retargeting by joint names, the one path: source joint positions onto the gait or gesture skeleton with IK.

Source positions are mapped by joint name onto ours (:func:`generation.mocap.rigs.auto_joint_map` unless a map is
given), scaled by our leg length / the source's (thigh + shin, median over frames) so strides and root heights fit
our legs, unmapped joints interpolated between mapped neighbours, and solved with
:func:`generation.core.ik.solve_rotations`; the root is moved so our hips land on the source's, and two-bone IK of
the legs puts the feet where the source's are. :func:`solve_onto` does it on global positions (the importer,
:mod:`generation.mocap.importer`, for any file); :func:`retarget` on a Motion (the captured DeepMimic walks).
"""
from __future__ import annotations

import numpy as np

from generation.core.ik import bend_limb_to_target, solve_rotations
from generation.core.kinematics import np_forward_kinematics
from generation.core.motion import Motion
from generation.core.quaternion import np_qto_matrix
from generation.core.skeleton import Skeleton

from .rigs import auto_joint_map


def leg_length(P: np.ndarray, index: dict[str, int], end: str) -> float:
    """Median over frames of thigh + shin length, mean of the sides present (P (T, J, 3) or (J, 3))."""
    P = P.reshape(-1, P.shape[-2], 3)
    sides = []
    for s in ("left", "right"):
        hip, knee, foot = (index.get(f"{s}_hip"), index.get(f"{s}_knee"), index.get(f"{s}_{end}"))
        if None in (hip, knee, foot):
            continue
        sides.append(np.median(np.linalg.norm(P[:, hip] - P[:, knee], axis=-1)
                               + np.linalg.norm(P[:, knee] - P[:, foot], axis=-1)))
    return float(np.mean(sides)) if sides else 0.0


def _place_source(P_src: np.ndarray, names, target: Skeleton, joint_map: dict[str, str], scale: float):
    """Source positions (T, K, 3) times ``scale`` on the target's joints: (T, J, 3), known (J,), mapped indices."""
    idx = {n: k for k, n in enumerate(names)}
    T, J = len(P_src), target.num_joints
    P = np.zeros((T, J, 3))
    known = np.zeros(J, bool)
    for ours, theirs in joint_map.items():
        P[:, target.index(ours)] = P_src[:, idx[theirs]] * scale
        known[target.index(ours)] = True
    return P, known, np.flatnonzero(known)


def _solve(P: np.ndarray, known: np.ndarray, mapped: np.ndarray, target: Skeleton, joint_map: dict[str, str],
           fit: bool = False, foot_ik: bool = True) -> tuple[Motion, float]:
    """IK of placed positions onto ``target`` (with ``foot_ik``, feet put on the source's): (Motion at fps 1, max
    mapped error m). With ``fit`` the target first takes the source's rest geometry (:func:`fit_proportions`)."""
    P = P.copy()
    known = known.copy()
    fill_unmapped_joints(P, known, target)
    if fit:
        target = fit_proportions(P, known, target)
    rotations = solve_rotations(P, target, known)
    P[:, 0] = align_root_to_hips(rotations, P, known, target)
    if foot_ik:
        rotations = place_feet_on_source(rotations, P, known, target, joint_map)
    motion = Motion(target, rotations, P[:, 0].copy(), 1.0, {})
    err = np.linalg.norm(motion.positions()[:, mapped] - P[:, mapped], axis=-1)
    return motion, float(err.max())


def leg_scale(P_src: np.ndarray, names, target: Skeleton, joint_map: dict[str, str]) -> float:
    """Our leg length / the source's (thigh + shin, median over frames; 1 when the source's legs are not mapped)."""
    idx = {n: k for k, n in enumerate(names)}
    end = "heel" if "left_heel" in target.joints else "ankle"
    src_leg = leg_length(P_src, {ours: idx[theirs] for ours, theirs in joint_map.items()}, end)
    tgt_leg = leg_length(target.rest_positions(), {n: j for j, n in enumerate(target.joints)}, end)
    return tgt_leg / src_leg if src_leg > 1e-6 else 1.0


def solve_onto(P_src: np.ndarray, names, target: Skeleton, joint_map: dict[str, str],
               proportions: str = "ours", foot_ik: bool = True) -> tuple[Motion, float, float, float]:
    """Mapped source positions (T, K, 3), metres, y-up -> a Motion on our joints.

    The import check always solves onto our joints with the source's bone lengths
    (:func:`fit_proportions`): its largest error over mapped joints says whether the file was read and solved
    right (millimetres for a right reading; bone-length changes within a take and rest directions that differ
    from ours add a few). ``proportions="source"`` returns that motion (the actor's body); ``"ours"`` moves it
    onto ``target``'s own lengths: positions scaled by :func:`leg_scale`, feet put where the scaled source's are
    (``foot_ik=False``: directions only).

    Returns:
        (Motion at fps 1, scale applied to the source positions, import error m, retarget error m): the import
        error of the source-proportioned solve, and the largest mapped-joint distance of the returned motion.
    """
    P, known, mapped = _place_source(P_src, names, target, joint_map, 1.0)
    motion, import_err = _solve(P, known, mapped, target, joint_map, fit=True)
    if proportions == "source":
        return motion, 1.0, import_err, import_err
    if proportions != "ours":
        raise ValueError(f"proportions must be 'source' or 'ours', got {proportions!r}")
    scale = leg_scale(P_src, names, target, joint_map)
    P, known, mapped = _place_source(P_src, names, target, joint_map, scale)
    motion, err = _solve(P, known, mapped, target, joint_map, foot_ik=foot_ik)
    return motion, scale, import_err, err


def retarget(motion: Motion, target_skeleton: Skeleton, joint_map: dict[str, str] | None = None,
             metadata: dict | None = None, foot_ik: bool = True) -> Motion:
    """A Motion moved onto another skeleton by joint names: :func:`solve_onto` of its FK positions onto our
    proportions, at the source's fps.

    Args:
        motion: source Motion.
        target_skeleton: e.g. ``gait_skeleton()``.
        joint_map: {target joint name: source joint name}; default :func:`generation.mocap.rigs.auto_joint_map`.
            The root must be mapped.
        metadata: merged over a copy of the source metadata.
        foot_ik: put the feet where the scaled source's are (default), else match directions only.

    Returns:
        Motion on ``target_skeleton`` at the source fps; metadata gains ``retarget`` (source skeleton, scale, map,
        largest error of the mapped joints and the import check's, in metres).
    """
    src, tgt = motion.skeleton, target_skeleton
    joint_map = dict(auto_joint_map(src.joints, tgt) if joint_map is None else joint_map)
    for t_name, s_name in joint_map.items():
        tgt.index(t_name)
        src.index(s_name)
    if tgt.joints[0] not in joint_map:
        raise ValueError(f"retarget: the target root {tgt.joints[0]!r} must be mapped (joint_map has "
                         f"{sorted(joint_map)})")
    solved, scale, import_err, err = solve_onto(motion.positions(), src.joints, tgt, joint_map, foot_ik=foot_ik)
    meta = {**motion.metadata, **(metadata or {})}
    meta["retarget"] = {"source_skeleton": src.name, "scale": scale, "joint_map": joint_map, "max_error_m": err,
                        "import_error_m": import_err}
    return Motion(tgt, solved.rotations, solved.root_positions, motion.fps, meta)


def align_root_to_hips(rotations: np.ndarray, P: np.ndarray, known: np.ndarray, tgt: Skeleton) -> np.ndarray:
    """Root positions (T, 3) that put our hip joints where the source's are.

    Rigs place the hip joints at different depths below the pelvis root (ours 5 cm, the Bandai Namco rig 2.3 cm):
    keeping the source's root position would leave our legs that much short of (or past) the feet, so knees
    never straighten. The root is moved, per frame, by the mean offset between the source hips and ours.
    ``P`` (T, J, 3) holds the source positions on our joints; unmapped hips leave the root where it is.
    """
    hips = [tgt.index(n) for n in ("left_hip", "right_hip") if n in tgt.joints and known[tgt.index(n)]]
    if not hips:
        return P[:, 0].copy()
    Q = np_forward_kinematics(rotations, P[:, 0], tgt)
    return P[:, 0] + (P[:, hips] - Q[:, hips]).mean(axis=1)


def place_feet_on_source(rotations: np.ndarray, P: np.ndarray, known: np.ndarray, tgt: Skeleton,
                joint_map: dict[str, str]) -> np.ndarray:
    """Two-bone IK of each mapped leg onto the desired heel/ankle positions; returns new rotations."""
    Q = np_forward_kinematics(rotations, P[:, 0], tgt)
    lengths = tgt.bone_lengths()
    children = tgt.children()
    changed = False
    for side in ("left", "right"):
        for end in (f"{side}_heel", f"{side}_ankle"):
            chain = (f"{side}_hip", f"{side}_knee", end)
            if not all(n in tgt.joints and n in joint_map for n in chain):
                continue
            e = tgt.index(end)
            if tgt.parents[e] != tgt.index(chain[1]) or tgt.parents[tgt.index(chain[1])] != tgt.index(chain[0]):
                continue
            Q = bend_limb_to_target(Q, tgt, end, P[:, e])
            for c in children[e]:
                if known[c] and lengths[c] > 1e-9:
                    d = P[:, c] - P[:, e]
                    Q[:, c] = Q[:, e] + lengths[c] * d / np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-12)
            changed = True
    return solve_rotations(Q, tgt) if changed else rotations


def fill_unmapped_joints(P: np.ndarray, known: np.ndarray, sk: Skeleton) -> None:
    """Place unmapped interior joints between mapped ancestor and descendant (in place; marks them known)."""
    children = sk.children()
    lengths = sk.bone_lengths()
    for j in range(sk.num_joints):
        if known[j]:
            continue
        # nearest mapped ancestor
        a, dist_a = sk.parents[j], lengths[j]
        while a >= 0 and not known[a]:
            dist_a += lengths[a]
            a = sk.parents[a]
        # nearest mapped descendant along first children
        d, dist_d = j, 0.0
        while not known[d] and children[d]:
            d = children[d][0]
            dist_d += lengths[d]
        if a < 0 or not known[d] or d == j:
            continue
        frac = dist_a / max(dist_a + dist_d, 1e-12)
        P[:, j] = P[:, a] + frac * (P[:, d] - P[:, a])
        known[j] = True


def fit_proportions(P: np.ndarray, known: np.ndarray, target: Skeleton, iterations: int = 2) -> Skeleton:
    """``target``'s joints with the source's rest geometry, so that its FK can reproduce the source positions.

    Bone lengths become the median over frames of the joint-to-parent distances in ``P``; then, ``iterations``
    times, the rotations are solved and every bone's offset becomes the median over frames of the source bone
    vector in its parent's solved frame (fits the angles between sibling bones, e.g. hips against the spine).

    Args:
        P: (T, J, 3) source positions placed on the target's joints, metres; known: (J,) which are meaningful.
        target: our skeleton (topology and starting rest directions).
    Returns:
        a Skeleton of the same joints and build; bones with an unknown end keep their rest offset scaled by the
        median length ratio of the fitted bones, and the height is scaled the same way.
    """
    lengths = target.bone_lengths()
    fitted = lengths.copy()
    bones = [j for j, p in enumerate(target.parents) if p >= 0 and known[j] and known[p] and lengths[j] > 1e-9]
    for j in bones:
        fitted[j] = float(np.median(np.linalg.norm(P[:, j] - P[:, target.parents[j]], axis=-1)))
    ratio = float(np.median(fitted[bones] / lengths[bones])) if bones else 1.0
    offsets = np.array(target.offsets) * ratio
    for j in bones:
        offsets[j] = target.offsets[j] / lengths[j] * fitted[j]
    offsets[0] = target.offsets[0]
    skeleton = Skeleton(target.name, target.joints, target.parents, offsets.copy(), target.height * ratio,
                        target.build)
    for _ in range(iterations):
        world = _world_matrices(solve_rotations(P, skeleton, known), skeleton.parents)
        for j in bones:
            p = target.parents[j]
            local = np.einsum("tba,tb->ta", world[:, p], P[:, j] - P[:, p])    # R_p^T (P_j - P_p)
            offsets[j] = np.median(local, axis=0)
        skeleton = Skeleton(target.name, target.joints, target.parents, offsets.copy(), target.height * ratio,
                            target.build)
    return skeleton


def _world_matrices(rotations: np.ndarray, parents) -> np.ndarray:
    """(T, J, 4) local rotations (w, x, y, z) -> (T, J, 3, 3) world rotation matrices."""
    local = np_qto_matrix(rotations)
    world = np.empty_like(local)
    for j, p in enumerate(parents):
        world[:, j] = local[:, j] if p < 0 else world[:, p] @ local[:, j]
    return world
