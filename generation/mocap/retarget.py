"""Retargeting by joint names: a source motion's positions onto the gait or gesture skeleton with IK.

Source FK positions, scaled by the ratio of hip heights, are mapped by joint name onto the target and solved with
:func:`generation.core.ik.solve_rotations`; two-bone IK of the legs then puts the feet where the source's are.
The importer (:mod:`generation.mocap.importer`) uses the same steps on any file's global joint positions.
"""
from __future__ import annotations

import numpy as np

from generation.core.ik import bend_limb_to_target, solve_rotations
from generation.core.kinematics import np_forward_kinematics
from generation.core.motion import Motion
from generation.core.quaternion import np_qto_matrix
from generation.core.skeleton import Skeleton

#: Candidate source names per gait-skeleton joint (first present wins): Mixamo/Unity-style, CMU-style
#: (cgspeed conversion), our own skeletons and the DeepMimic humanoid.
GAIT_NAME_CANDIDATES: dict[str, tuple[str, ...]] = {
    "root": ("Hips", "hips", "Hip", "pelvis", "root"),
    "left_hip": ("LeftUpLeg", "LeftHip", "LeftThigh", "LHip", "left_hip"),
    "left_knee": ("LeftLeg", "LeftKnee", "LeftShin", "LKnee", "left_knee"),
    "left_heel": ("LeftFoot", "LeftAnkle", "LAnkle", "left_heel", "left_ankle"),
    "left_toe": ("LeftToeBase", "LeftToe", "LeftToe_End", "LeftFoot_end", "left_toe", "left_heel_end"),
    "right_hip": ("RightUpLeg", "RightHip", "RightThigh", "RHip", "right_hip"),
    "right_knee": ("RightLeg", "RightKnee", "RightShin", "RKnee", "right_knee"),
    "right_heel": ("RightFoot", "RightAnkle", "RAnkle", "right_heel", "right_ankle"),
    "right_toe": ("RightToeBase", "RightToe", "RightToe_End", "RightFoot_end", "right_toe", "right_heel_end"),
    "lower_back": ("LowerBack", "Spine", "spine", "lower_back", "chest"),
    "spine": ("Spine2", "Spine1", "Chest", "chest3", "chest4", "spine"),
    "neck": ("Neck", "neck"),
    "head": ("Head", "head", "Neck1", "Neck_end", "neck_end"),
    "left_shoulder": ("LeftArm", "LeftShoulder", "LeftUpperArm", "left_shoulder"),
    "left_elbow": ("LeftForeArm", "LeftElbow", "LeftLowerArm", "left_elbow"),
    "left_hand": ("LeftHand", "LeftWrist", "left_hand", "left_wrist"),
    "left_hand_index": ("LeftHandIndex1", "LeftHandMiddle1", "LeftFingerBase", "LeftHand_end", "left_hand_index",
                        "left_wrist_end"),
    "right_shoulder": ("RightArm", "RightShoulder", "RightUpperArm", "right_shoulder"),
    "right_elbow": ("RightForeArm", "RightElbow", "RightLowerArm", "right_elbow"),
    "right_hand": ("RightHand", "RightWrist", "right_hand", "right_wrist"),
    "right_hand_index": ("RightHandIndex1", "RightHandMiddle1", "RightFingerBase", "RightHand_end",
                         "right_hand_index", "right_wrist_end"),
}
#: Candidate source names per gesture-skeleton joint.
GESTURE_NAME_CANDIDATES: dict[str, tuple[str, ...]] = {
    "root": ("Hips", "hips", "Hip", "pelvis", "root"),
    "chest": ("Spine", "LowerBack", "chest"),
    "chest2": ("Spine1", "chest2"),
    "chest3": ("Spine2", "Chest", "chest3"),
    "chest4": ("Spine3", "UpperChest", "Chest2", "chest4"),
    "neck": ("Neck", "neck"),
    "head": ("Head", "head", "Neck1"),
    "left_collar": ("LeftShoulder", "LeftCollar", "LeftClavicle", "left_collar"),
    "left_shoulder": ("LeftArm", "LeftUpperArm", "left_shoulder"),
    "left_elbow": ("LeftForeArm", "LeftElbow", "LeftLowerArm", "left_elbow"),
    "left_wrist": ("LeftHand", "LeftWrist", "left_wrist", "left_hand"),
    "right_collar": ("RightShoulder", "RightCollar", "RightClavicle", "right_collar"),
    "right_shoulder": ("RightArm", "RightUpperArm", "right_shoulder"),
    "right_elbow": ("RightForeArm", "RightElbow", "RightLowerArm", "right_elbow"),
    "right_wrist": ("RightHand", "RightWrist", "right_wrist", "right_hand"),
    "left_hip": ("LeftUpLeg", "LeftHip", "LeftThigh", "left_hip"),
    "left_knee": ("LeftLeg", "LeftKnee", "LeftShin", "left_knee"),
    "left_ankle": ("LeftFoot", "LeftAnkle", "left_ankle", "left_heel"),
    "left_toe": ("LeftToeBase", "LeftToe", "LeftToe_End", "LeftFoot_end", "left_toe"),
    "right_hip": ("RightUpLeg", "RightHip", "RightThigh", "right_hip"),
    "right_knee": ("RightLeg", "RightKnee", "RightShin", "right_knee"),
    "right_ankle": ("RightFoot", "RightAnkle", "right_ankle", "right_heel"),
    "right_toe": ("RightToeBase", "RightToe", "RightToe_End", "RightFoot_end", "right_toe"),
}


def default_joint_map(source: Skeleton, target: Skeleton) -> dict[str, str]:
    """Map target joint names to source joint names from the candidate tables (first present name wins).

    The target must be the gait or gesture skeleton (by joint names); joints with no candidate present are left
    out (retarget interpolates or keeps them straight).
    """
    table = GAIT_NAME_CANDIDATES if "left_hand_index" in target.joints else GESTURE_NAME_CANDIDATES
    present = set(source.joints)
    out = {}
    for name in target.joints:
        for cand in table.get(name, ()):
            if cand in present:
                out[name] = cand
                break
    return out


def _leg_height(skeleton: Skeleton) -> float:
    """Root height above the lowest rest joint, or the rest vertical extent when the root is at the bottom."""
    rest = skeleton.rest_positions()
    extent = float(rest[:, 1].max() - rest[:, 1].min())
    h = skeleton.root_height()
    return h if h > 0.2 * extent else extent


def retarget(motion: Motion, target_skeleton: Skeleton, joint_map: dict[str, str] | None = None,
             metadata: dict | None = None, foot_ik: bool = True) -> Motion:
    """Move a motion onto another skeleton by matching joints by name.

    The source's FK positions are scaled by target hip height / source hip height (so strides and root heights
    fit the target's legs), mapped target joint <- source joint, and solved with IK on the target (bone lengths
    of the target are kept; directions come from the source). Target joints without a mapping are placed on the
    line between their nearest mapped ancestor and descendant in proportion to rest bone lengths, or, for
    leaves, keep the identity local rotation.

    With ``foot_ik`` (default) each mapped leg chain (``<side>_hip`` - ``<side>_knee`` - ``<side>_heel`` or
    ``_ankle``) is then bent with two-bone IK so the heel/ankle lands exactly on the scaled source position, and
    the foot's children point where the source's do. Matching directions alone would move the feet with every
    difference in leg proportions and make planted feet slide; this keeps the source's foot contacts.

    Args:
        motion: source Motion.
        target_skeleton: e.g. ``gait_skeleton()``.
        joint_map: {target joint name: source joint name}; default :func:`default_joint_map`. The root must be
            mapped.
        metadata: merged over a copy of the source metadata.

    Returns:
        Motion on ``target_skeleton`` at the source fps; metadata gains ``retarget`` (scale, map, IK error of the
        mapped joints in metres).
    """
    src = motion.skeleton
    tgt = target_skeleton
    joint_map = dict(default_joint_map(src, tgt) if joint_map is None else joint_map)
    for t_name, s_name in joint_map.items():
        tgt.index(t_name)
        src.index(s_name)
    root_name = tgt.joints[0]
    if root_name not in joint_map:
        raise ValueError(f"retarget: the target root {root_name!r} must be mapped (joint_map has {sorted(joint_map)})")
    scale = _leg_height(tgt) / _leg_height(src)
    src_pos = motion.positions() * scale
    T, J = motion.num_frames, tgt.num_joints
    P = np.zeros((T, J, 3))
    known = np.zeros(J, bool)
    for t_name, s_name in joint_map.items():
        P[:, tgt.index(t_name)] = src_pos[:, src.index(s_name)]
        known[tgt.index(t_name)] = True
    fill_unmapped_joints(P, known, tgt)
    rotations = solve_rotations(P, tgt, known)
    P[:, 0] = align_root_to_hips(rotations, P, known, tgt)
    if foot_ik:
        rotations = place_feet_on_source(rotations, P, known, tgt, joint_map)
    meta = dict(motion.metadata)
    meta.update(metadata or {})
    out = Motion(tgt, rotations, P[:, 0].copy(), motion.fps, meta)
    mapped = [tgt.index(n) for n in joint_map]
    err = np.linalg.norm(out.positions()[:, mapped] - P[:, mapped], axis=-1)
    meta["retarget"] = {"source_skeleton": src.name, "scale": scale, "joint_map": joint_map,
                        "max_error_m": float(err.max()), "mean_error_m": float(err.mean())}
    return out


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
