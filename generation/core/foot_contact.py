"""Contact-aware foot clean-up of generated walks: planted feet, no floor penetration, rotations only.

Generated gaits (the gait network's) slide their feet while they stand on them and dip below the floor. The
clean-up (:func:`plant_feet`):

1. detects each foot's contacts in the motion itself (:func:`detect_contacts_hysteresis`): the foot's lowest
   joint near the clip's lowest height for that joint and slow on the ground plane, with hysteresis (a contact
   starts below the ``on`` thresholds and ends above the ``off`` ones) and short gaps filled;
2. locks the planted foot: during a contact the foot keeps its generated orientation (heel and toe roll
   survive) but pivots about its lowest joint, which is held at one ground position (the mean over the
   frames it is the pivot, on the floor); when the pivot passes from heel to toe the toe stays where it is;
3. outside contacts the ankle's displacement fades to zero over ``blend_frames`` on each side (smoothstep),
   so nothing pops, and any foot joint below the floor is lifted onto it;
4. solves each leg with analytic two-bone IK (:func:`generation.core.rigging.two_bone_ik`) so the ankle
   reaches its target, the knee bending in the plane of the generated knee; the thigh and shin are turned by
   the shortest arc from their generated directions (their twist is kept) and the ankle's local rotation is
   recomputed so the foot keeps its world orientation. Only local rotations of hips, knees and ankles change:
   bone lengths stay exact. The root is raised by the median lift of the planted ankles (feet that sank into
   the floor mean a body that is too low; the knees keep their generated bend), and a target out of reach
   may lower the pelvis by the missing length (smoothed; off by default, the ankle then stops short).

Works for any skeleton whose legs are named ``left_/right_`` + hip, knee, heel or ankle, toe (gait and
gesture skeletons). Positions in metres, y-up; the floor is y = ``floor_y`` (0 for the project's motions).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .motion import Motion
from .quaternion import np_qbetween, np_qconj, np_qmul, np_qrot
from .rigging import smoothstep, two_bone_ik
from .skeleton import Skeleton

#: Hysteresis thresholds for a 1.75 m body (scaled with skeleton.height / 1.75): a contact starts when the
#: foot's lowest joint is within CONTACT_ON_HEIGHT_M of that joint's lowest height in the clip and slower than
#: CONTACT_ON_SPEED_M_S on the ground plane, and ends when it rises above CONTACT_OFF_HEIGHT_M or moves faster
#: than CONTACT_OFF_SPEED_M_S.
CONTACT_ON_HEIGHT_M = 0.05
CONTACT_OFF_HEIGHT_M = 0.07
CONTACT_ON_SPEED_M_S = 0.45
CONTACT_OFF_SPEED_M_S = 0.65
#: Frames over which the lock fades in before and out after a contact (at 30 fps).
BLEND_FRAMES = 5


@dataclass(frozen=True)
class Leg:
    """Joint indices of one leg: hip -> knee -> ankle (heel) -> toe."""

    hip: int
    knee: int
    ankle: int
    toe: int


def legs(skeleton: Skeleton) -> tuple[Leg, Leg]:
    """(left, right) legs found by name: ``<side>_heel`` or ``<side>_ankle``, its parent knee and grandparent hip,
    and ``<side>_toe``."""
    out = []
    for side in ("left", "right"):
        names = skeleton.joints
        ankle = next((names.index(f"{side}_{n}") for n in ("heel", "ankle") if f"{side}_{n}" in names), None)
        toe = names.index(f"{side}_toe") if f"{side}_toe" in names else None
        if ankle is None or toe is None:
            raise ValueError(f"skeleton {skeleton.name!r} has no {side}_heel/{side}_ankle and {side}_toe joints")
        knee = skeleton.parents[ankle]
        hip = skeleton.parents[knee]
        if knee < 0 or hip < 0 or skeleton.parents[toe] != ankle:
            raise ValueError(f"skeleton {skeleton.name!r}: the {side} leg is not hip -> knee -> ankle -> toe")
        out.append(Leg(hip, knee, ankle, toe))
    return out[0], out[1]


def global_rotations(rotations: np.ndarray, parents) -> np.ndarray:
    """World rotations (T, J, 4) from local ones (T, J, 4) (parents before children)."""
    G = np.empty_like(rotations)
    for j, p in enumerate(parents):
        G[:, j] = rotations[:, j] if p < 0 else np_qmul(G[:, p], rotations[:, j])
    return G


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) index pairs (stop exclusive) of the True runs of a 1-D bool array."""
    d = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def detect_contacts_hysteresis(positions: np.ndarray, fps: float, skeleton: Skeleton, min_frames: int = 3,
                               max_gap: int = 2) -> np.ndarray:
    """(T, 2) bool contacts (left, right) of each foot from positions (T, J, 3), with hysteresis.

    A foot's height is its lowest joint's (ankle or toe) height above that joint's lowest height in the clip;
    its speed the ground-plane speed of that joint (smaller of backward and forward differences). A contact
    starts when height < on-height and speed < on-speed and lasts until height > off-height or speed >
    off-speed. Gaps of at most ``max_gap`` frames are filled, then runs shorter than ``min_frames`` dropped.
    """
    P = np.asarray(positions, dtype=np.float64)
    scale = skeleton.height / 1.75
    on_h, off_h = CONTACT_ON_HEIGHT_M * scale, CONTACT_OFF_HEIGHT_M * scale
    on_v, off_v = CONTACT_ON_SPEED_M_S * scale, CONTACT_OFF_SPEED_M_S * scale
    T = len(P)
    out = np.zeros((T, 2), dtype=bool)
    for s, leg in enumerate(legs(skeleton)):
        F = P[:, [leg.ankle, leg.toe]]                                    # (T, 2, 3)
        rel = F[..., 1] - F[..., 1].min(axis=0)                           # (T, 2)
        step = np.linalg.norm(np.diff(F[..., [0, 2]], axis=0), axis=-1) * fps
        speed = np.minimum(np.concatenate([step[:1], step]), np.concatenate([step, step[-1:]]))
        low = np.argmin(rel, axis=1)                                      # the joint nearest its own ground
        h, v = rel[np.arange(T), low], speed[np.arange(T), low]
        state = False
        for t in range(T):
            state = (h[t] < off_h and v[t] < off_v) if state else (h[t] < on_h and v[t] < on_v)
            out[t, s] = state
        m = out[:, s]
        for a, b in _runs(~m):
            if 0 < a and b < T and b - a <= max_gap:
                m[a:b] = True
        for a, b in _runs(m):
            if b - a < min_frames:
                m[a:b] = False
    return out


def _ankle_targets(P: np.ndarray, leg: Leg, contact: np.ndarray, floor_y: float, blend: int, rest_h: np.ndarray,
                   pivot_margin: float = 0.01) -> np.ndarray:
    """(T, 3) ankle targets of one leg: locked pivots in contacts, fading displacements around them.

    ``rest_h`` (2,): heights of the ankle and toe joints above the sole when standing (rest pose). A joint's
    height above its ground is its height minus its lowest height in the clip; in a contact the pivot keeps
    that clearance above ``floor_y + rest_h`` (so a foot the network sank into the floor is lifted onto it).
    """
    T = len(P)
    ankle, toe = P[:, leg.ankle].copy(), P[:, leg.toe]
    toe_rel = toe - ankle
    clear = np.stack([ankle[:, 1] - ankle[:, 1].min(), toe[:, 1] - toe[:, 1].min()], -1)    # (T, 2)
    floor_at = floor_y + rest_h
    disp = np.zeros((T, 3))
    runs = _runs(contact)
    for a, b in runs:
        pivot = np.zeros(b - a, dtype=int)
        # pivot: the lower of heel and toe (heights as placed on the floor), switching only when the other is
        # lower by pivot_margin (for a heel joint above the sole, mostly the toe, as foot_skate measures it)
        y = floor_at + clear
        cur = int(y[a, 1] < y[a, 0])
        for k, t in enumerate(range(a, b)):
            if cur == 0 and y[t, 1] < y[t, 0] - pivot_margin:
                cur = 1
            elif cur == 1 and y[t, 0] < y[t, 1] - pivot_margin:
                cur = 0
            pivot[k] = cur
        target = np.empty((b - a, 3))
        anchor = None
        for k, t in enumerate(range(a, b)):
            j = pivot[k]
            if k == 0 or j != pivot[k - 1]:
                if anchor is None:                 # the first pivot: its mean ground position over its run
                    stop = k + 1
                    while stop < len(pivot) and pivot[stop] == j:
                        stop += 1
                    src = (ankle if j == 0 else toe)[a + k:a + stop]
                    anchor = np.array([src[:, 0].mean(), 0.0, src[:, 2].mean()])
                else:                              # the new pivot stays where the locked foot put it
                    anchor = target[k - 1] + (toe_rel[t - 1] if j == 1 else 0.0)
                    anchor = anchor.copy()
            pos = anchor.copy()
            pos[1] = floor_at[j] + clear[t, j]
            target[k] = pos if j == 0 else pos - toe_rel[t]
        disp[a:b] = target - ankle[a:b]
    # fade the displacement in before and out after each contact, within the free frames around it
    free = _runs(~contact)
    out = disp.copy()
    for a, b in free:
        n = b - a
        t = np.arange(a, b)
        if a > 0:                                  # after a contact ending at a - 1
            w = 1.0 - smoothstep((t - (a - 1)) / (min(blend, n) + 1.0))
            out[a:b] += w[:, None] * disp[a - 1]
        if b < T:                                  # before a contact starting at b
            w = 1.0 - smoothstep((b - t) / (min(blend, n) + 1.0))
            out[a:b] += w[:, None] * disp[b]
    target = ankle + out
    # no foot joint below the floor
    low = np.minimum(target[:, 1] - rest_h[0], target[:, 1] + toe_rel[:, 1] - rest_h[1])
    target[:, 1] += np.maximum(floor_y - low, 0.0)
    return target


def _pelvis_drop(P: np.ndarray, the_legs, targets, lengths: np.ndarray, fps: float) -> np.ndarray:
    """(T,) metres to lower the root so that every ankle target is within its leg's reach, smoothed (a max filter
    then a box filter of 0.15 s half-width: never below the needed drop, and the body does not bob)."""
    drop = np.zeros(len(P))
    for leg, target in zip(the_legs, targets):
        reach = 0.998 * (lengths[leg.knee] + lengths[leg.ankle])
        d = target - P[:, leg.hip]
        horiz2 = d[:, 0] ** 2 + d[:, 2] ** 2
        need_y = np.sqrt(np.maximum(reach ** 2 - horiz2, 0.0))   # the largest vertical hip-ankle distance
        drop = np.maximum(drop, np.maximum(-d[:, 1] - need_y, 0.0))
    if not drop.any():
        return drop
    k = max(1, int(round(0.15 * fps)))
    kernel = np.ones(2 * k + 1) / (2 * k + 1)
    drop = np.lib.stride_tricks.sliding_window_view(np.pad(drop, k, mode="edge"), 2 * k + 1).max(axis=1)
    return np.convolve(np.pad(drop, k, mode="edge"), kernel, mode="valid")


def _solve_leg(rot: np.ndarray, G: np.ndarray, P: np.ndarray, sk, leg, target: np.ndarray,
               lengths: np.ndarray) -> None:
    """Set the hip, knee and ankle local rotations of ``leg`` in ``rot`` (T, J, 4), in place, so the ankle reaches
    ``target`` (T, 3) by two-bone IK; G: (T, J, 4) global rotations before the change; P: (T, J, 3) positions.
    The foot keeps its world rotation."""
    hip, knee = P[:, leg.hip], P[:, leg.knee]
    l1, l2 = lengths[leg.knee], lengths[leg.ankle]
    mid, _, _ = two_bone_ik(hip, target, l1, l2, knee - hip)
    dist = np.linalg.norm(target - hip, axis=-1, keepdims=True)
    end = hip + np.clip(dist, abs(l1 - l2) + 1e-6, (l1 + l2) * (1 - 1e-9)) * (target - hip) / np.maximum(dist, 1e-12)
    g_hip_new = np_qmul(np_qbetween(knee - hip, mid - hip), G[:, leg.hip])
    g_knee_tmp = np_qmul(g_hip_new, rot[:, leg.knee])
    shin_now = np_qrot(g_knee_tmp, np.broadcast_to(sk.offsets[leg.ankle], mid.shape).copy())
    g_knee_new = np_qmul(np_qbetween(shin_now, end - mid), g_knee_tmp)
    rot[:, leg.hip] = np_qmul(np_qconj(G[:, sk.parents[leg.hip]]), g_hip_new)
    rot[:, leg.knee] = np_qmul(np_qconj(g_hip_new), g_knee_new)
    rot[:, leg.ankle] = np_qmul(np_qconj(g_knee_new), G[:, leg.ankle])


def plant_feet(motion: Motion, contacts: np.ndarray | None = None, floor_y: float = 0.0,
               blend_frames: int | None = None, raise_pelvis: bool = True,
               lower_pelvis: bool = False) -> Motion:
    """The motion with planted feet and no floor penetration (see the module docstring).

    Args:
        motion: a Motion whose skeleton has named legs (see :func:`legs`).
        contacts: optional (T, 2) bool (left, right); default :func:`detect_contacts_hysteresis`.
        floor_y: floor height, metres.
        blend_frames: fade length in frames; default :data:`BLEND_FRAMES` scaled to the motion's fps.
        raise_pelvis: raise the root by the median height the planted ankles were lifted (a body whose feet sank
            into the floor is too low; without this its knees would bend further).
        lower_pelvis: lower the root where an ankle target is out of the leg's reach (else the ankle stops short
            of it on the straight leg). Off by default: on the seed000 gaits it bent the knees beyond the corpus
            (crouching is the problem this clean-up addresses) for no gain in skate (0.29 vs 0.36 cm/s).

    Returns:
        A new Motion (same skeleton, fps and metadata plus ``"foot_cleanup"``) whose hip, knee and ankle local
        rotations and root height may differ.
    """
    sk = motion.skeleton
    if blend_frames is None:
        blend_frames = max(1, int(round(BLEND_FRAMES * motion.fps / 30.0)))
    rot = motion.rotations.copy()
    root = motion.root_positions.copy()
    P = motion.positions()
    if contacts is None:
        contacts = detect_contacts_hysteresis(P, motion.fps, sk)
    contacts = np.asarray(contacts, dtype=bool)
    the_legs = legs(sk)
    lengths = sk.bone_lengths()
    rest = sk.rest_positions()
    targets = []
    for s, leg in enumerate(the_legs):
        rest_h = rest[[leg.ankle, leg.toe], 1] - rest[[leg.ankle, leg.toe], 1].min()
        targets.append(_ankle_targets(P, leg, contacts[:, s], floor_y, blend_frames, rest_h))

    # feet the network sank into the floor and had lifted onto it would bend the knees: raise the whole body by
    # the median lift of the planted ankles (one height for the clip, so the body does not bob)
    lift = np.concatenate([(target - P[:, leg.ankle])[contacts[:, s], 1] for s, (leg, target)
                           in enumerate(zip(the_legs, targets))])
    raise_m = max(float(np.median(lift)), 0.0) if lift.size and raise_pelvis else 0.0
    root[:, 1] += raise_m
    P = P + np.array([0.0, raise_m, 0.0])
    drop = _pelvis_drop(P, the_legs, targets, lengths, motion.fps)
    if drop.any() and lower_pelvis:
        root[:, 1] -= drop
        P = P - np.stack([np.zeros_like(drop), drop, np.zeros_like(drop)], -1)[:, None]

    G = global_rotations(rot, sk.parents)
    for leg, target in zip(the_legs, targets):
        _solve_leg(rot, G, P, sk, leg, target, lengths)
    meta = dict(motion.metadata)
    meta["foot_cleanup"] = {"method": "contact lock + two-bone IK", "blend_frames": blend_frames,
                            "contact_share": round(float(contacts.mean()), 4),
                            "pelvis_raise_m": round(raise_m, 4),
                            "pelvis_drop_max_m": round(float(drop.max()) if lower_pelvis else 0.0, 4)}
    return Motion(sk, rot, root, motion.fps, meta)


def reach_targets(motion: Motion, chains, targets) -> Motion:
    """The motion with each two-bone chain (a :class:`Leg`: ``hip`` -> ``knee`` -> ``ankle``, e.g. shoulder -> elbow
    -> wrist) solved by two-bone IK so its end reaches its target (T, 3), bending in the plane of the chain's own
    middle joint and keeping the end joint's world rotation (as :func:`plant_feet` solves legs)."""
    sk = motion.skeleton
    rot = motion.rotations.copy()
    P = motion.positions()
    G = global_rotations(rot, sk.parents)
    lengths = sk.bone_lengths()
    for chain, target in zip(chains, targets):
        _solve_leg(rot, G, P, sk, chain, np.asarray(target, dtype=float), lengths)
    return Motion(sk, rot, motion.root_positions.copy(), motion.fps, dict(motion.metadata))


def reach_ankles(motion: Motion, targets: tuple[np.ndarray, np.ndarray], lower_pelvis: bool = True) -> Motion:
    """The motion with each leg solved by two-bone IK so its ankle reaches ``targets`` (left, right), each (T, 3)
    metres, the knee bending in the plane of the motion's own knee and each foot keeping its world orientation
    (as :func:`plant_feet` solves its legs). With ``lower_pelvis`` the root is lowered, smoothly, where a target is
    out of a leg's reach. Used to put a body of other proportions on the feet of a motion (the renderer's human
    bodies); the metadata gains ``"ankle_ik"`` with the largest pelvis drop."""
    sk = motion.skeleton
    rot = motion.rotations.copy()
    root = motion.root_positions.copy()
    P = motion.positions()
    the_legs = legs(sk)
    lengths = sk.bone_lengths()
    drop = _pelvis_drop(P, the_legs, targets, lengths, motion.fps) if lower_pelvis else np.zeros(len(P))
    if drop.any():
        root[:, 1] -= drop
        P = P - np.stack([np.zeros_like(drop), drop, np.zeros_like(drop)], -1)[:, None]
    G = global_rotations(rot, sk.parents)
    for leg, target in zip(the_legs, targets):
        _solve_leg(rot, G, P, sk, leg, np.asarray(target, dtype=float), lengths)
    meta = dict(motion.metadata)
    meta["ankle_ik"] = {"pelvis_drop_max_m": round(float(drop.max()), 4)}
    return Motion(sk, rot, root, motion.fps, meta)


__all__ = ["BLEND_FRAMES", "CONTACT_OFF_HEIGHT_M", "CONTACT_OFF_SPEED_M_S", "CONTACT_ON_HEIGHT_M",
           "CONTACT_ON_SPEED_M_S", "Leg", "detect_contacts_hysteresis", "global_rotations", "legs", "plant_feet",
           "reach_ankles", "reach_targets"]
