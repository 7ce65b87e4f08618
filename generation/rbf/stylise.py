"""Applying a seed 004 theme to a neutral walk cycle: Y = P + w * S, then back onto the skeleton.

Pipeline (shapes: m cycle frames, J joints):

1. ``P`` (m, J, 3): the neutral cycle's joint positions in the walker's frame, i.e. with the mean forward
   progression (stride * t / m) removed; the root keeps its sway, bob and surge.
2. ``S`` (m, J, 3): the theme's secondary features (:func:`theme_rbfs`): for each of the first n features of
   Table III and each joint of its body part, up to three Gaussian RBFs (eq. 4) on one Cartesian axis,
   amplitudes = intensity x walker height. Posture features are shape 1; movement features are placed on the
   extrema of the joint's own neutral trajectory (relative to the root) by :func:`generation.rbf.basis.swing_params`.
   An axis of a joint with no edit of its own follows its parent's edit (:func:`theme_displacement`), so a
   lifted knee lifts the foot and the toes and hand tips, which the paper's 54-DOF model lacks, follow.
3. ``Y = P + w * S``: the paper's linear model (eq. 1 with r = 1). A negative w inverts only the amplitudes.
4. The paper edits Cartesian positions and so does not keep bone lengths (its stated limitation). We put
   ``Y`` back onto the skeleton (:func:`fit_to_skeleton`): foot joints are first kept above their neutral
   floor height (:func:`keep_feet_above_ground`); legs and arms are solved by analytic two-bone IK that
   reaches the edited heel/hand position when it is reachable, bending in the neutral bend plane turned by
   the knee/elbow edit; toes and hand tips keep their edited height; other bones keep the edited direction;
   joints with several children (pelvis, chest) take the best rotation onto their children (Horn's
   quaternion method). Twist comes from the neutral motion. Bone lengths are then exact. With the ``extended`` and
   ``pooled`` sets the arms keep at least the base's elbow bend (:func:`keep_bend`): a hand target beyond the base's
   reach swings the bent arm from the shoulder.
5. Uniform time warping for speed (cycle duration / speed) and the cycle repeated n_cycles times along +z.

With the ``extended`` (or ``pooled``) set and all ten features, two levers of ours (:func:`stride_cadence_scales`):
the stride scaled by s (before step 4, :func:`scale_stride` and :func:`keep_leg_extension`; the progression per cycle by
the same s) and the cadence by c (step 5).
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import torch

from generation.core.features import foot_joints
from generation.core.foot_contact import plant_feet
from generation.core.kinematics import forward_kinematics, np_forward_kinematics
from generation.core.motion import Motion
from generation.core.quaternion import np_qbetween, np_qconj, np_qfix, np_qmul, np_qrot, np_qslerp
from generation.core.skeleton import Skeleton

from .basis import CYCLE_FRAMES, rbf_sum, shape_params, swing_params
from .data_features import data_rbfs, load_data_features
from .themes import (
    AXES,
    BODY_PARTS,
    DEFAULT_INTENSITIES,
    EXTENDED_SETS,
    INTENSITY_SETS,
    POOLED_PATH,
    THEME_NAMES,
    calibration_provenance,
    extended_provenance,
    extended_sources,
    extended_stride_cadence,
    theme_features,
)

_MODELLED = frozenset(name for joints in BODY_PARTS.values() for name in joints)
PAPER_WEIGHTS = (0.4, 0.7, 1.0, 1.3)  # Fig. 7
PAPER_FEATURE_COUNTS = (1, 4, 7, 10)  # Fig. 7
INVERSION_WEIGHT = -0.7  # Fig. 8
FEATURE_SOURCES = ("expert", "data")  # Table III's expert features, or RBFs fitted to real themed walks

#: (hip, knee, heel, toe) of each leg of the gait skeleton: what a stride change moves.
STRIDE_LEGS = (("left_hip", "left_knee", "left_heel", "left_toe"),
               ("right_hip", "right_knee", "right_heel", "right_toe"))
#: The straightest a leg may be after a stride change: hip-to-heel distance / (thigh + shin) at most this
#: (:func:`keep_leg_extension`).
MAX_LEG_EXTENSION = 0.995
MIN_GAIT_SCALE = 0.5  # stride and cadence factors are at least this (a negative weight past -1 / ratio would stop)

# Two-bone chains (root, middle, end) of the 21-joint gait skeleton solved analytically.
GAIT_LIMB_CHAINS = (
    ("left_hip", "left_knee", "left_heel"), ("right_hip", "right_knee", "right_heel"),
    ("left_shoulder", "left_elbow", "left_hand"), ("right_shoulder", "right_elbow", "right_hand"),
)
#: Root joints of the arm chains: with the ``extended`` and ``pooled`` sets the arms keep at least the base's elbow
#: bend (:func:`keep_bend`).
ARM_ROOTS = ("left_shoulder", "right_shoulder")


# --------------------------------------------------------------------------------------------------
# The neutral cycle in the walker's frame
# --------------------------------------------------------------------------------------------------
def cycle_stride(neutral: Motion) -> np.ndarray:
    """(3,) root displacement over one cycle, metres (metadata ``stride_m`` if present, else estimated).

    The cycle is assumed periodic: frame m would be frame 0 moved by the stride.
    """
    stride = neutral.metadata.get("stride_m")
    if stride is not None:
        vec = np.asarray(stride, dtype=np.float64).reshape(-1)
        if vec.shape == (1,):
            vec = np.array([0.0, 0.0, float(vec[0])])
        if vec.shape != (3,):
            raise ValueError(f"neutral cycle metadata 'stride_m' must be a number or 3-vector, got {stride!r}")
    else:
        m = neutral.num_frames
        vec = (neutral.root_positions[-1] - neutral.root_positions[0]) * m / (m - 1)
        vec[1] = 0.0
    return vec


def walker_frame_positions(neutral: Motion) -> tuple[np.ndarray, np.ndarray]:
    """Neutral positions with the mean forward progression removed.

    Returns:
        P: (m, J, 3) metres, the walker's frame (y up, facing +z).
        progression: (m, 3) the removed offset stride * t / m.

    Raises:
        ValueError: if the cycle is too short or does not walk along +z (heading more than 15 degrees off).
    """
    m = neutral.num_frames
    if m < 20:
        raise ValueError(f"a neutral cycle needs at least 20 frames, got {m}")
    stride = cycle_stride(neutral)
    horizontal = np.hypot(stride[0], stride[2])
    if horizontal < 1e-6 or stride[2] < np.cos(np.radians(15.0)) * horizontal:
        raise ValueError(f"the neutral cycle must walk along +z (stride {np.round(stride, 3).tolist()} m); "
                         "rotate it first (generation.rbf.neutral_base does)")
    progression = np.arange(m)[:, None] / m * stride[None, :]
    return neutral.positions() - progression[:, None, :], progression


# --------------------------------------------------------------------------------------------------
# Secondary features S
# --------------------------------------------------------------------------------------------------
def theme_rbfs(P: np.ndarray, skeleton: Skeleton, theme: str, n_features: int,
               height: float | None = None, exclude: tuple[int, ...] = (),
               intensities: str | Mapping[int, float] = DEFAULT_INTENSITIES) -> dict[tuple[str, str], np.ndarray]:
    """RBF parameters per degree of freedom for the first ``n_features`` of a theme.

    Args:
        P: (m, J, 3) neutral cycle in the walker's frame (:func:`walker_frame_positions`), metres.
        skeleton: gait skeleton (joint names as in :data:`generation.rbf.themes.BODY_PARTS`).
        theme: one of :data:`generation.rbf.themes.THEME_NAMES`.
        n_features: how many of Table III's features, in frequency order (0..10).
        height: walker height in metres for de-normalising intensities (default ``skeleton.height``).
        exclude: Table III ranks (1..10) to leave out of the first ``n_features`` (for ablations).
        intensities: ``extended`` (default), ``calibrated``, ``visual`` or {rank: intensity}
            (:func:`generation.rbf.themes.theme_features`).

    Returns:
        {(joint name, axis "X"|"Y"|"Z"): (M, 3) rows (alpha metres, mu frames, sigma2 frames^2)}, M <= 3.
        This is the theme's parameter matrix Q of eq. 5, one entry per DOF.
    """
    height = float(skeleton.height if height is None else height)
    m = P.shape[0]
    root = skeleton.index("root")
    dofs: dict[tuple[str, str], np.ndarray] = {}
    for feat in theme_features(theme, n_features, intensities):
        if feat.rank in exclude:
            continue
        for joint, sign in feat.joint_signs():
            j = skeleton.index(joint)
            a = AXES[feat.axis]
            alpha = sign * feat.intensity * height
            if feat.kind == "tilt":
                params = shape_params(1, alpha, m=m)
            else:
                traj = P[:, j, a] if j == root else P[:, j, a] - P[:, root, a]
                params = swing_params(traj, feat.shape, alpha)
            key = (joint, feat.axis)
            dofs[key] = params if key not in dofs else np.concatenate([dofs[key], params])
            if len(dofs[key]) > 3:
                raise ValueError(f"theme {theme!r}: DOF {key} would need {len(dofs[key])} RBFs (> 3)")
    return dofs


def theme_displacement(P: np.ndarray, skeleton: Skeleton, theme: str, n_features: int,
                       height: float | None = None, propagate: bool = True,
                       exclude: tuple[int, ...] = (),
                       intensities: str | Mapping[int, float] = DEFAULT_INTENSITIES) -> np.ndarray:
    """Secondary features S of the first ``n_features``: (m, J, 3) metres, for weight 1 (linear in the RBFs).

    The paper moved each marker independently (its bones stretched). With exact bone lengths an isolated knee
    or elbow edit would be almost cancelled by the limb IK, so with ``propagate`` (default) a joint axis that
    has no edit of its own follows its parent's displacement on that axis (a tilted neck carries the head, a
    lifted knee the foot, a dropped shoulder the arm); an axis with its own edit keeps exactly the paper's
    per-marker displacement. The root's (pelvis) edits are not passed on, as that would only translate the
    body. Without ``propagate`` only joints outside the paper's model (toes, hand tips) follow their parent.
    """
    return rbf_displacement(P, skeleton, theme_rbfs(P, skeleton, theme, n_features, height, exclude, intensities),
                            propagate)


def rbf_displacement(P: np.ndarray, skeleton: Skeleton, dofs: dict[tuple[str, str], np.ndarray],
                     propagate: bool = True) -> np.ndarray:
    """Displacement (m, J, 3) metres of per-DOF RBFs {(joint, axis): (M, 3)} on a cycle shaped like P (m, J, 3).

    Propagation as in :func:`theme_displacement`; with ``propagate`` False only joints outside the paper's
    model (toes, hand tips) follow their parent (right for features fitted to every DOF of real data).
    """
    m, J = P.shape[:2]
    S = np.zeros((m, J, 3))
    edited = np.zeros((J, 3), dtype=bool)
    t = np.arange(m, dtype=np.float64)
    for (joint, axis), params in dofs.items():
        j, a = skeleton.index(joint), AXES[axis]
        S[:, j, a] += rbf_sum(t, params, period=m)
        edited[j, a] = True
    for j, p in enumerate(skeleton.parents):
        if p < 0:
            continue
        if propagate and p > 0:
            follow = ~edited[j]  # axes without an edit of their own follow the parent
        elif skeleton.joints[j] not in _MODELLED:
            follow = np.ones(3, dtype=bool)  # toes and hand tips always move with their parent
        else:
            continue
        S[:, j, follow] = S[:, p, follow]
    return S


# --------------------------------------------------------------------------------------------------
# Stride and cadence (levers of ours, extended set)
# --------------------------------------------------------------------------------------------------
def stride_cadence_scales(theme: str, weight: float, n_features: int, features: str = "expert",
                          intensities: str | Mapping[int, float] = DEFAULT_INTENSITIES) -> tuple[float, float]:
    """(stride factor s, cadence factor c) of a styled walk, both 1 unless the ``extended`` (or ``pooled``) set's
    expert features are all on (all ten of Table III): s = max(0.5, 1 + w * stride), c = max(0.5, 1 + w * cadence)
    with the theme's real stride and cadence ratios minus 1 (:func:`generation.rbf.themes.extended_stride_cadence`), so
    w = 1 gives the real style's stride and cadence relative to normal walking and a negative w inverts them."""
    if not (uses_bent_arms(features, intensities) and n_features == len(theme_features(theme, None, "visual"))):
        return 1.0, 1.0
    stride, cadence = extended_stride_cadence(theme, EXTENDED_SETS[intensities])
    w = float(weight)
    return max(MIN_GAIT_SCALE, 1.0 + w * stride), max(MIN_GAIT_SCALE, 1.0 + w * cadence)


def scale_stride(Y: np.ndarray, skeleton: Skeleton, scale: float) -> np.ndarray:
    """Walker-frame targets (m, J, 3) metres with the stride scaled by ``scale``: a copy.

    The fore-aft (z) offsets of the hips and heels from the pelvis are scaled by ``scale`` and the pelvis' own
    fore-aft surge about its cycle mean too (a uniform stretch of the legs along z about the pelvis' mean), so with
    the progression per cycle scaled by the same factor a planted heel stays planted; the other joints (trunk,
    arms, head) move with the pelvis. Knees follow their hip and toes their heel unscaled (the knee is solved by
    the leg IK, so its bend direction is kept; the foot keeps its shape). Heights are unchanged
    (:func:`keep_leg_extension` then moves the pelvis up or down to keep the legs' flexion).
    """
    out = Y.copy()
    if scale == 1.0:
        return out
    root = skeleton.index("root")
    z = Y[:, :, 2]
    z0 = float(z[:, root].mean())
    surge = (scale - 1.0) * (z[:, root] - z0)                           # (m,) the pelvis' own change
    out[:, :, 2] = z + surge[:, None]
    for hip, knee, heel, toe in STRIDE_LEGS:
        for joint, follows in ((hip, knee), (heel, toe)):
            j, f = skeleton.index(joint), skeleton.index(follows)
            out[:, j, 2] = z0 + scale * (z[:, j] - z0)
            out[:, f, 2] = z[:, f] + (out[:, j, 2] - z[:, j])
    return out


def _hip_height_shift(Y: np.ndarray, hip: int, heel: int, distance: np.ndarray) -> np.ndarray:
    """(m,) metres the hip of targets ``Y`` (m, J, 3) must move up (negative: down) to stand ``distance`` (m,)
    from its heel, the horizontal offset kept (0 height over the heel where the offset alone is longer)."""
    d = Y[:, hip] - Y[:, heel]
    rise = np.sqrt(np.maximum(distance * distance - d[:, 0] ** 2 - d[:, 2] ** 2, 0.0))
    return rise - d[:, 1]


def keep_leg_extension(Y: np.ndarray, P: np.ndarray, skeleton: Skeleton) -> tuple[np.ndarray, np.ndarray]:
    """Raise or lower every joint but the feet so the legs reach their heels and keep about the base's flexion.

    A stride change moves the heels fore-aft but not the pelvis' height. A longer stride would stretch a leg past
    its length (the IK would lift the heel off its planted spot): where a leg's hip-to-heel distance in the targets
    ``Y`` (m, J, 3) would exceed its straightest in the neutral cycle ``P`` (m, J, 3) (at most
    :data:`MAX_LEG_EXTENSION` x (thigh + shin)), the pelvis is lowered until it does not, as real walkers' is with
    long steps. A shorter stride would bend the stance knee more than the base's: the pelvis is raised, at most
    until one leg is as straight as in the neutral cycle at that frame. The shift (per frame, the most both legs
    allow) moves the pelvis, trunk, arms, hips and knees; heels and toes keep their targets. Returns the shifted
    copy and the shift per frame (m,) metres (negative: lowered).
    """
    lower, raise_ = [], []
    for hip, knee, heel, _ in STRIDE_LEGS:
        h, k, e = skeleton.index(hip), skeleton.index(knee), skeleton.index(heel)
        length = float(np.linalg.norm(skeleton.offsets[k]) + np.linalg.norm(skeleton.offsets[e]))
        base = np.linalg.norm(P[:, e] - P[:, h], axis=-1)                                      # (m,)
        reach = min(float(base.max()), MAX_LEG_EXTENSION * length)
        lower.append(_hip_height_shift(Y, h, e, np.full(len(Y), reach)))
        raise_.append(_hip_height_shift(Y, h, e, np.minimum(base, reach)))
    shift = np.minimum(np.minimum(*lower), np.maximum(np.minimum(*raise_), 0.0))
    out = Y.copy()
    feet = [skeleton.index(n) for leg in STRIDE_LEGS for n in leg[2:]]
    body = [j for j in range(skeleton.num_joints) if j not in feet]
    out[:, body, 1] += shift[:, None]
    return out, shift


# --------------------------------------------------------------------------------------------------
# Back onto the skeleton
# --------------------------------------------------------------------------------------------------
def _horn_rotation(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """Best rotation (least squares) taking vectors src (T, K, 3) onto dst (T, K, 3): (T, 4) quaternions.

    Horn (1987): the eigenvector of the largest eigenvalue of the 4x4 matrix built from sum_k src_k dst_k^T.
    """
    S = np.einsum("tki,tkj->tij", src, dst)
    Sxx, Sxy, Sxz = S[:, 0, 0], S[:, 0, 1], S[:, 0, 2]
    Syx, Syy, Syz = S[:, 1, 0], S[:, 1, 1], S[:, 1, 2]
    Szx, Szy, Szz = S[:, 2, 0], S[:, 2, 1], S[:, 2, 2]
    N = np.stack([
        np.stack([Sxx + Syy + Szz, Syz - Szy, Szx - Sxz, Sxy - Syx], -1),
        np.stack([Syz - Szy, Sxx - Syy - Szz, Sxy + Syx, Szx + Sxz], -1),
        np.stack([Szx - Sxz, Sxy + Syx, -Sxx + Syy - Szz, Syz + Szy], -1),
        np.stack([Sxy - Syx, Szx + Sxz, Syz + Szy, -Sxx - Syy + Szz], -1),
    ], -2)
    _, vecs = np.linalg.eigh(N)
    q = vecs[..., -1]
    return q * np.where(q[:, :1] < 0, -1.0, 1.0)


def _two_bone(root: np.ndarray, pole_hint: np.ndarray, end_target: np.ndarray, a: float,
              b: float) -> tuple[np.ndarray, np.ndarray]:
    """Analytic two-bone IK per frame: (T, 3) x 3 -> middle and end positions with lengths a, b exactly.

    The end reaches ``end_target`` when it is within reach (otherwise the limb points at it, fully
    stretched or folded); the middle joint bends towards ``pole_hint`` (a direction, (T, 3), not parallel
    to the limb).
    """
    d = end_target - root
    dist = np.linalg.norm(d, axis=-1, keepdims=True)
    u = d / np.maximum(dist, 1e-9)
    reach = np.clip(dist, abs(a - b) + 1e-6, a + b - 1e-6)
    pole = pole_hint - (pole_hint * u).sum(-1, keepdims=True) * u
    pole = pole / np.maximum(np.linalg.norm(pole, axis=-1, keepdims=True), 1e-12)
    cos_a = np.clip((a * a + reach * reach - b * b) / (2 * a * reach), -1.0, 1.0)
    mid = root + a * (cos_a * u + np.sqrt(1.0 - cos_a * cos_a) * pole)
    end = root + reach * u
    return mid, end


def _bend_hint(ref_pos: np.ndarray, target: np.ndarray, r: int, m: int, e: int, a: float) -> np.ndarray:
    """Direction (T, 3) the middle joint of chain (r, m, e) should bend towards.

    The reference (neutral) bend: the middle joint's offset from the root-end line, at least 10 % of the
    upper bone long (a nearly straight reference limb still has a side to bend to), plus the edit of the
    middle joint itself (relative to the root). Keeping the reference bend stops a knee or elbow from
    flipping backwards when only the foot or hand was moved.
    """
    u0 = ref_pos[:, e] - ref_pos[:, r]
    u0 = u0 / np.maximum(np.linalg.norm(u0, axis=-1, keepdims=True), 1e-12)
    v = ref_pos[:, m] - ref_pos[:, r]
    v = v - (v * u0).sum(-1, keepdims=True) * u0
    mean_dir = v.mean(axis=0)
    mean_dir = mean_dir / max(float(np.linalg.norm(mean_dir)), 1e-12)
    edit = (target[:, m] - target[:, r]) - (ref_pos[:, m] - ref_pos[:, r])
    # A floor on the reference bend's size, along its own direction (so the bend plane, and an unedited limb,
    # are reproduced exactly); only a limb that is exactly straight in the reference borrows the mean direction.
    size = np.linalg.norm(v, axis=-1, keepdims=True)
    direction = np.where(size > 1e-9 * a, v / np.maximum(size, 1e-300), mean_dir)
    return np.maximum(size, 0.1 * a) * direction + edit


def _keep_height(start: np.ndarray, goal: np.ndarray, length: float) -> np.ndarray:
    """(T, 3) end points at ``length`` from ``start`` with the goal's height where reachable and its heading."""
    dy = np.clip(goal[:, 1] - start[:, 1], -length, length)
    flat = goal - start
    flat[:, 1] = 0.0
    n = np.linalg.norm(flat, axis=-1, keepdims=True)
    heading = np.where(n > 1e-9, flat / np.maximum(n, 1e-12), 0.0)
    horizontal = np.sqrt(np.maximum(length * length - dy * dy, 0.0))[:, None]
    out = start + horizontal * heading
    out[:, 1] = start[:, 1] + dy
    return out


def global_rotations(motion_rotations: np.ndarray, root_positions: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """(T, J, 4) global joint rotations from local ones."""
    with torch.no_grad():
        _, g = forward_kinematics(torch.as_tensor(motion_rotations), torch.as_tensor(root_positions),
                                  torch.tensor(skeleton.offsets), skeleton.parents, return_global_rotations=True)
    return g.numpy()


def keep_bend(root: np.ndarray, end_target: np.ndarray, ref_root: np.ndarray, ref_end: np.ndarray) -> np.ndarray:
    """(T, 3) end targets pulled towards ``root`` (T, 3) to at most the reference's root-to-end distance per frame.

    The limb still points at its edited target but is no straighter than in the reference (``ref_root``,
    ``ref_end``: (T, 3) the unedited positions), metres: a hand pushed out of the base's reach swings the bent arm
    (the shoulder turns, the elbow keeps at least the base's flexion) instead of locking the elbow straight.
    """
    d = end_target - root
    dist = np.linalg.norm(d, axis=-1, keepdims=True)
    limit = np.linalg.norm(ref_end - ref_root, axis=-1, keepdims=True)
    return root + d * np.minimum(1.0, limit / np.maximum(dist, 1e-12))


def fit_to_skeleton(target: np.ndarray, skeleton: Skeleton, reference_rotations: np.ndarray,
                    chains: tuple[tuple[str, str, str], ...] | None = None,
                    bent: tuple[str, ...] = ()) -> tuple[np.ndarray, np.ndarray]:
    """Local rotations and root positions whose forward kinematics best follows edited positions.

    Bone lengths are exact by construction (the result is a skeletal motion). This is our local
    projection (see module docstring); it is analytic and per frame, so it runs in milliseconds.

    Args:
        target: (T, J, 3) edited joint positions, metres.
        skeleton: the skeleton to fit.
        reference_rotations: (T, J, 4) local rotations of the unedited motion; they fix bone twist and the
            rotation of leaf joints. With ``target`` equal to the reference's positions the result is the
            reference itself.
        chains: (root, middle, end) joint names solved by two-bone IK; default :data:`GAIT_LIMB_CHAINS` when
            the skeleton has those joints, else none.
        bent: root joints of chains whose end target is first pulled to at most the reference's root-to-end
            distance (:func:`keep_bend`), e.g. :data:`ARM_ROOTS`: the middle joint keeps at least its reference bend.

    Returns:
        rotations (T, J, 4) local unit quaternions, root_positions (T, 3).
    """
    target = np.asarray(target, dtype=np.float64)
    T, J = target.shape[:2]
    if target.shape != (T, skeleton.num_joints, 3) or reference_rotations.shape != (T, J, 4):
        raise ValueError(f"target {target.shape} and reference rotations {reference_rotations.shape} must be "
                         f"(T, {skeleton.num_joints}, 3) and (T, {skeleton.num_joints}, 4)")
    if chains is None:
        chains = GAIT_LIMB_CHAINS if all(n in skeleton.joints for c in GAIT_LIMB_CHAINS for n in c) else ()
    offsets = skeleton.offsets
    parents = skeleton.parents
    kids = skeleton.children()
    ref_global = global_rotations(reference_rotations, target[:, 0], skeleton)
    ref_pos = np_forward_kinematics(reference_rotations, target[:, 0], skeleton)
    goal = target.copy()  # where each joint should go; limb chains overwrite middle and end joints
    chain_of = {skeleton.index(c[0]): (skeleton.index(c[1]), skeleton.index(c[2])) for c in chains}
    chain_ends = {skeleton.index(c[2]) for c in chains}
    pos = np.zeros_like(target)
    glob = ref_global.copy()
    pos[:, 0] = target[:, 0]
    for p in range(J):
        if not kids[p]:
            continue  # leaf: keeps the reference rotation
        if p in chain_of:
            mid, end = chain_of[p]
            a = float(np.linalg.norm(offsets[mid]))
            hint = _bend_hint(ref_pos, target, p, mid, end, a)
            end_goal = target[:, end]
            if skeleton.joints[p] in bent:
                end_goal = keep_bend(pos[:, p], end_goal, ref_pos[:, p], ref_pos[:, end])
            goal[:, mid], goal[:, end] = _two_bone(pos[:, p], hint, end_goal, a,
                                                  float(np.linalg.norm(offsets[end])))
        if p in chain_ends and len(kids[p]) == 1 and not kids[kids[p][0]]:
            # the foot (heel -> toe) or hand tip: keep the edited height of the tip (a planted toe stays on the
            # floor) and the edited horizontal heading; the length is the bone's.
            c = kids[p][0]
            goal[:, c] = _keep_height(pos[:, p], goal[:, c], float(np.linalg.norm(offsets[c])))
        if len(kids[p]) == 1:
            c = kids[p][0]
            current = np_qrot(ref_global[:, p], np.tile(offsets[c], (T, 1)))
            wanted = goal[:, c] - pos[:, p]
            glob[:, p] = np_qmul(np_qbetween(current, wanted), ref_global[:, p])
        else:
            src = np.stack([np.tile(offsets[c], (T, 1)) for c in kids[p]], axis=1)
            dst = np.stack([goal[:, c] - pos[:, p] for c in kids[p]], axis=1)
            glob[:, p] = _horn_rotation(src, dst)
        for c in kids[p]:
            pos[:, c] = pos[:, p] + np_qrot(glob[:, p], np.tile(offsets[c], (T, 1)))
    local = glob.copy()
    for j in range(1, J):
        if kids[j]:
            local[:, j] = np_qmul(np_qconj(glob[:, parents[j]]), glob[:, j])
        else:
            local[:, j] = reference_rotations[:, j]
    return np_qfix(local), pos[:, 0].copy()


def bone_length_error(positions: np.ndarray, skeleton: Skeleton) -> float:
    """Largest |bone length - skeleton bone length| over frames and bones, metres; positions (T, J, 3)."""
    lengths = skeleton.bone_lengths()[1:]
    parents = np.asarray(skeleton.parents[1:])
    actual = np.linalg.norm(positions[:, 1:] - positions[:, parents], axis=-1)
    return float(np.abs(actual - lengths).max())


# --------------------------------------------------------------------------------------------------
# Timing and repetition
# --------------------------------------------------------------------------------------------------
def _sample_cycle(rotations: np.ndarray, root: np.ndarray, stride: np.ndarray, phase: np.ndarray):
    """Sample a periodic cycle at continuous phases (cycles, >= 0): slerp rotations, lerp root + stride."""
    m = rotations.shape[0]
    f = phase * m
    i0 = np.floor(f).astype(np.int64)
    frac = f - i0
    k0, k1 = i0 % m, (i0 + 1) % m
    n0, n1 = i0 // m, (i0 + 1) // m  # completed cycles at each end of the interval
    q0, q1 = rotations[k0], rotations[k1]
    q1 = np.where(((q0 * q1).sum(-1, keepdims=True) < 0), -q1, q1)
    rot = np_qslerp(q0, q1, np.ascontiguousarray(np.broadcast_to(frac[:, None], q0.shape[:-1])))
    r0 = root[k0] + n0[:, None] * stride
    r1 = root[k1] + n1[:, None] * stride
    return rot, r0 + frac[:, None] * (r1 - r0)


def warp_and_repeat_cycle(rotations: np.ndarray, root: np.ndarray, stride: np.ndarray, cycle_seconds: float,
                 speed: float, n_cycles: int, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Uniformly time-warp a periodic cycle by ``speed`` and repeat it ``n_cycles`` times at ``fps``.

    Returns rotations (N, J, 4) and root positions (N, 3), N = round(n_cycles * cycle_seconds / speed * fps).
    """
    n_out = int(round(n_cycles * cycle_seconds / speed * fps))
    phase = np.arange(n_out) / fps * speed / cycle_seconds
    return _sample_cycle(rotations, root, stride, phase)




# --------------------------------------------------------------------------------------------------
# Public entry point
# --------------------------------------------------------------------------------------------------
def stylised_cycle(neutral_cycle: Motion, theme: str, weight: float, n_features: int,
                   keep_ground: bool = True, features: str = "expert", exclude: tuple[int, ...] = (),
                   intensities: str | Mapping[int, float] = DEFAULT_INTENSITIES, stride_scale: float = 1.0,
                   bent_arms: bool | None = None) -> dict:
    """One stylised cycle on the skeleton, with the intermediate arrays.

    Returns a dict with ``P`` (m, J, 3) neutral walker-frame positions, ``S`` (m, J, 3) secondary
    features, ``Y`` = P + weight * S (with the stride scaled, :func:`scale_stride`), ``rotations`` (m, J, 4) and
    ``root`` (m, 3) of the fitted cycle (root with the progression, times ``stride_scale``, added back),
    ``positions`` (m, J, 3) their forward kinematics in the walker's frame, and the bone-length errors ``before``
    (of Y) and ``after`` (of the fit), the largest distance ``residual`` between fitted and edited positions, the
    largest ``ground_lift`` applied by :func:`keep_feet_above_ground` (when ``keep_ground``) and ``pelvis_shift``
    (m,) of :func:`keep_leg_extension` (zeros with ``stride_scale`` 1), all metres.

    ``features``: "expert" (Table III, :func:`theme_displacement`) or "data" (RBFs fitted to real themed walks,
    :func:`generation.rbf.data_features.data_rbfs`, applied to their own DOFs without propagation). ``exclude``:
    expert features (Table III ranks) to leave out, for ablations. ``intensities``: the expert features'
    amplitudes, ``extended`` (default), ``calibrated`` or ``visual`` (:data:`generation.rbf.themes.INTENSITY_SETS`)
    or {rank: intensity}. ``stride_scale``: the stride factor s (:func:`stride_cadence_scales`; 1 keeps the base's).
    ``bent_arms``: the arms keep at least the base's elbow bend (:func:`keep_bend`, :data:`ARM_ROOTS`); default
    (None): with the expert features of the ``extended`` and ``pooled`` sets (:func:`uses_bent_arms`).
    """
    if not (stride_scale > 0 and np.isfinite(stride_scale)):
        raise ValueError(f"stride_scale must be a positive number, got {stride_scale!r}")
    if features not in FEATURE_SOURCES:
        raise ValueError(f"features must be one of {list(FEATURE_SOURCES)}, got {features!r}")
    if not np.isfinite(weight):
        raise ValueError(f"weight must be a finite number, got {weight!r}")
    if theme not in THEME_NAMES:
        raise ValueError(f"unknown theme {theme!r}; expected one of {list(THEME_NAMES)}")
    skel = neutral_cycle.skeleton
    P, progression = walker_frame_positions(neutral_cycle)
    if features == "expert":
        S = theme_displacement(P, skel, theme, n_features, exclude=exclude, intensities=intensities)
    else:

        S = rbf_displacement(P, skel, data_rbfs(theme, n_features, skel.height, P.shape[0]), propagate=False)
    Y = scale_stride(P + float(weight) * S, skel, float(stride_scale))
    target, lifted = keep_feet_above_ground(Y, P, skel) if keep_ground else (Y, 0.0)
    shift = np.zeros(len(P))
    if stride_scale != 1.0:
        target, shift = keep_leg_extension(target, P, skel)
    bent = ARM_ROOTS if (uses_bent_arms(features, intensities) if bent_arms is None else bent_arms) else ()
    rotations, root = fit_to_skeleton(target, skel, neutral_cycle.rotations, bent=bent)
    fitted = np_forward_kinematics(rotations, root, skel)
    return {
        "P": P, "S": S, "Y": Y, "target": target, "rotations": rotations,
        "root": root + float(stride_scale) * progression, "positions": fitted,
        "before": bone_length_error(Y, skel), "after": bone_length_error(fitted, skel),
        "residual": float(np.linalg.norm(fitted - Y, axis=-1).max()), "ground_lift": lifted,
        "pelvis_shift": shift,
    }


def uses_bent_arms(features: str, intensities: str | Mapping[int, float]) -> bool:
    """Whether a styled walk keeps the base's elbow bend by default: the expert features of the ``extended`` or
    ``pooled`` set (the ``calibrated`` and ``visual`` sets and data features keep the plain fit). The same sets,
    with all ten features, carry the stride and cadence levers (:func:`stride_cadence_scales`)."""
    return features == "expert" and isinstance(intensities, str) and intensities in EXTENDED_SETS


def keep_feet_above_ground(Y: np.ndarray, P: np.ndarray, skeleton: Skeleton) -> tuple[np.ndarray, float]:
    """Raise edited foot joints that would go below their lowest neutral height (the floor contact height).

    The Gaussian tails of a foot feature (e.g. a lowered swing foot) reach into the stance phase and would
    push the planted foot through the floor. Each heel/toe joint's height is clamped to its minimum over the
    neutral cycle. Returns the clamped copy (m, J, 3) and the largest lift applied (metres).
    """

    left, right = foot_joints(skeleton)
    out = Y.copy()
    feet = left + right
    floor = P[:, feet, 1].min(axis=0)  # (K,)
    clamped = np.maximum(out[:, feet, 1], floor[None])
    lifted = float((clamped - out[:, feet, 1]).max())
    out[:, feet, 1] = clamped
    return out, lifted


def stylise(neutral_cycle: Motion, theme: str, weight: float, n_features: int, speed: float = 1.0,
            n_cycles: int = 4, fps: float = 30.0, keep_ground: bool = True, plant: bool = True,
            features: str = "expert", exclude: tuple[int, ...] = (), intensities: str = DEFAULT_INTENSITIES) -> Motion:
    """Apply a seed 004 theme to a neutral walk cycle and walk it along a straight line.

    Args:
        neutral_cycle: one periodic neutral cycle (left contact to next left contact, walking along +z), e.g.
            from :func:`generation.rbf.neutral_base.neutral_cycle`; metadata ``stride_m`` and ``synthetic`` are
            read when present.
        theme: happy, sad, energetic, tired, feminine or masculine.
        weight: w of Y = P + w * S; any real (the paper uses 0.4, 0.7, 1.0, 1.3 and -0.7 for inversion).
        n_features: the first n features of Table III (the paper uses 1, 4, 7, 10).
        speed: uniform time warp; 1.3 plays the cycle 1.3 times faster (same stride, higher cadence).
        n_cycles: number of cycles in the result.
        fps: output frame rate.
        keep_ground: clamp edited foot joints to their neutral floor height (:func:`keep_feet_above_ground`).
        plant: plant the feet of the walked result (:func:`plant_walk_feet`): the features move the feet (tired
            shortens the ankle swing while the body keeps the neutral stride), so without it they slide.
        features: "expert" (Table III) or "data" (fitted to real themed walks; see :func:`stylised_cycle`).
        exclude: expert features (Table III ranks) to leave out (ablations; recorded in the metadata when given).
        intensities: the expert features' amplitudes, :data:`generation.rbf.themes.INTENSITY_SETS`: ``extended``
            (default; sized from real style-vs-normal differences, with our rows and, with all ten features, the
            theme's stride and cadence, :func:`stride_cadence_scales`: the stride scaled by s with the feet
            planted and the cycle played c times faster on top of ``speed``),
            ``calibrated`` (w = 1 reproduces real actors' style differences, factors capped at 6x), ``visual``
            (the earlier hand-sized set) or ``pooled`` (as ``extended``, happy and sad sized on Bandai Namco and the
            BML walks of Emotion-Gait; metadata ``intensity_sources`` names both with their licences).

    Returns:
        Motion on the neutral cycle's skeleton, round(n_cycles * cycle duration / speed * fps) frames, with
        metadata origin, generator "rbf", theme, weight, n_features, speed, synthetic_base, the
        bone-length errors before/after the fit (metres), ``stride_scale`` and ``cadence_scale`` (when the
        levers change the walk; with ``pelvis_shift_m``, the range [min, max] of :func:`keep_leg_extension`'s
        height change) and, when planted, ``foot_planting`` (True) and
        ``foot_cleanup`` (see :func:`generation.core.foot_contact.plant_feet`).
    """
    if not speed > 0 or not np.isfinite(speed):
        raise ValueError(f"speed must be a positive number, got {speed!r}")
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps!r}")
    if isinstance(n_cycles, bool) or not isinstance(n_cycles, int) or n_cycles < 1:
        raise ValueError(f"n_cycles must be a positive integer, got {n_cycles!r}")
    if intensities not in INTENSITY_SETS:
        raise ValueError(f"intensities must be one of {list(INTENSITY_SETS)}, got {intensities!r}")
    stride_scale, cadence_scale = stride_cadence_scales(theme, weight, n_features, features, intensities)
    result = stylised_cycle(neutral_cycle, theme, weight, n_features, keep_ground, features, tuple(exclude),
                            intensities, stride_scale)
    stride = stride_scale * cycle_stride(neutral_cycle)
    rotations, root = warp_and_repeat_cycle(result["rotations"], result["root"], stride, neutral_cycle.duration,
                                            speed * cadence_scale, n_cycles, fps)
    base_meta = neutral_cycle.metadata
    metadata = {
        "origin": "generated",
        "generator": "rbf",
        "theme": theme,
        "weight": float(weight),
        "n_features": int(n_features),
        "features": features,
        "speed": float(speed),
        "synthetic_base": bool(base_meta.get("synthetic", base_meta.get("synthetic_base", True))),
        "n_cycles": n_cycles,
        "bone_length_error_before_m": result["before"],
        "bone_length_error_after_m": result["after"],
        "fit_residual_max_m": result["residual"],
        "ground_lift_max_m": result["ground_lift"],
    }
    if features == "expert":
        metadata["intensities"] = intensities
    if (stride_scale, cadence_scale) != (1.0, 1.0):
        metadata.update({"stride_scale": stride_scale, "cadence_scale": cadence_scale,
                         "pelvis_shift_m": [float(result["pelvis_shift"].min()),
                                            float(result["pelvis_shift"].max())]})
    if exclude:
        metadata["excluded_ranks"] = sorted(exclude)
    metadata.update(base_provenance(base_meta))
    if features == "expert" and intensities == "calibrated" and "licence" not in metadata:
        metadata.update(calibration_provenance())
    if features == "expert" and intensities in EXTENDED_SETS and "licence" not in metadata:
        metadata.update(extended_provenance(EXTENDED_SETS[intensities]))
    sources = extended_sources(theme, POOLED_PATH) if features == "expert" and intensities == "pooled" else {}
    if sources:
        metadata["intensity_sources"] = sources
    if features == "data" and "licence" not in metadata:

        data = load_data_features()
        metadata.update({"licence": data["licence"], "citation": data["citation"]})
    motion = Motion(neutral_cycle.skeleton, rotations, root, fps, metadata)
    return plant_walk_feet(motion) if plant else motion


def base_provenance(base_meta: dict) -> dict:
    """What a clip keeps of its base cycle's provenance: captured_base, licence, citation, dataset_url."""
    return {k: base_meta[k] for k in ("captured_base", "licence", "citation", "dataset_url") if k in base_meta}


def plant_walk_feet(motion: Motion) -> Motion:
    """The walk with its feet planted and none below the floor (y = 0), metadata ``foot_planting: True``.

    Contacts are detected on this motion (the styled one: the features change the legs), then
    :func:`generation.core.foot_contact.plant_feet` locks each planted foot and re-solves hips, knees and
    ankles with two-bone IK; the upper body, the root's path and the swing phase away from contacts are kept,
    so the theme's features stay (measured in docs/benchmarks/motion_quality.md, "RBF foot planting").
    """
    planted = plant_feet(motion)
    planted.metadata["foot_planting"] = True
    return planted


def neutral_walk(neutral_cycle: Motion, speed: float = 1.0, n_cycles: int = 4, fps: float = 30.0,
                 plant: bool = True) -> Motion:
    """The neutral cycle itself walked like a stylised clip (for the neutral-validation section, Table I).

    Same timing, path and foot planting (``plant``, :func:`plant_walk_feet`) as :func:`stylise`, so a styled
    walk differs from the neutral one by its features only; metadata origin "generated", generator
    "neutral_base", theme "neutral", weight 0, n_features 0, speed, synthetic_base (+ ``foot_planting``).
    """
    if not speed > 0 or not np.isfinite(speed):
        raise ValueError(f"speed must be a positive number, got {speed!r}")
    if isinstance(n_cycles, bool) or not isinstance(n_cycles, int) or n_cycles < 1:
        raise ValueError(f"n_cycles must be a positive integer, got {n_cycles!r}")
    stride = cycle_stride(neutral_cycle)
    walker_frame_positions(neutral_cycle)  # validates length and heading
    rotations, root = warp_and_repeat_cycle(neutral_cycle.rotations, neutral_cycle.root_positions, stride,
                                            neutral_cycle.duration, speed, n_cycles, fps)
    meta = neutral_cycle.metadata
    metadata = {"origin": "generated", "generator": "neutral_base", "theme": "neutral", "weight": 0.0,
                "n_features": 0, "speed": float(speed), "n_cycles": n_cycles,
                "synthetic_base": bool(meta.get("synthetic", meta.get("synthetic_base", True))),
                **base_provenance(meta)}
    motion = Motion(neutral_cycle.skeleton, rotations, root, fps, metadata)
    return plant_walk_feet(motion) if plant else motion


__all__ = ["neutral_walk", "plant_walk_feet", "stylise", "stylised_cycle", "theme_rbfs", "theme_displacement",
           "rbf_displacement", "FEATURE_SOURCES", "keep_bend", "uses_bent_arms", "ARM_ROOTS",
           "fit_to_skeleton", "walker_frame_positions", "stride_cadence_scales", "scale_stride",
           "keep_leg_extension", "warp_and_repeat_cycle", "bone_length_error", "CYCLE_FRAMES"]
