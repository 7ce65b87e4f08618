"""Drive an exported body from a Motion: bone orientations from the joints' world rotations, feet on the floor.

Every body bone is driven by one joint of the Motion's skeleton (found by the project's joint names, so the gait
and gesture skeletons and imports with the same conventions work): the joint whose rotation turns the segment the
bone lies on. A bone's world orientation is that joint's world rotation times a fixed rest alignment
``A = S @ C @ R`` (``R`` the bone's rest orientation):

- trunk, pelvis, shoulder girdle, neck and head: ``S = I`` (the body keeps its own spine curve and turns it as the
  Motion turns its trunk joints; spine bones go to the trunk joint at the same fraction of the root->neck height);
- limbs (thigh, shin, foot, upper arm, forearm, hand when the skeleton has one): ``S`` is the shortest rotation
  taking the body's rest segment onto the skeleton's rest segment, chained down the limb (the forearm's rotation
  straightens the elbow about its own hinge after the upper arm's), so limb directions are the Motion's exactly;
- toes follow the foot, fingers and metacarpals the hand (or the forearm), the head and eyes the neck segment (the
  skeletons' ``head`` joint ends the chain: its own rotation turns nothing the Motion shows);
- ``C`` is a relaxed curl of the fingers (about each finger's own bend axis), identity elsewhere.

The body keeps its own proportions, so its feet would not land where the Motion's do: the legs are solved by
two-bone IK (:func:`generation.core.foot_contact.reach_ankles`) on a copy of the skeleton with the body's leg
lengths and hip offsets, so each ankle reaches the Motion's ankle position, moved up or down by the difference of
the two feet's ankle heights; the pelvis starts at the body's own hip height and is lowered where a target is out
of reach. Numpy only.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from generation.core.foot_contact import Leg, global_rotations, legs, reach_ankles, reach_targets
from generation.core.motion import Motion
from generation.core.quaternion import np_qto_matrix
from generation.core.skeleton import Skeleton

from .skinning import Skinner, bone_transforms, vertex_normals
from .store import Body

#: Lowest joint of the Motion's skeleton above its sole, as a fraction of a 1.75 m body: the renderer's floor lies
#: this far below the lowest joint of a clip (see ``generation.render.clip.plan_cameras``).
SOLE_BELOW_LOWEST_JOINT = 0.03
#: Relaxed finger curl in degrees per phalanx (proximal, middle, distal): thumb, then the four fingers.
THUMB_CURL_DEG = (6.0, 12.0, 10.0)
FINGER_CURL_DEG = (16.0, 26.0, 12.0)


class RetargetError(ValueError):
    """The skeleton lacks the joints a body needs (legs, arms, neck); the message names them."""


def _unit(v: np.ndarray) -> np.ndarray:
    return v / max(float(np.linalg.norm(v)), 1e-12)


def _swing(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(3, 3) shortest rotation taking direction ``u`` onto ``v``."""
    u, v = _unit(u), _unit(v)
    axis = np.cross(u, v)
    s, c = np.linalg.norm(axis), float(np.dot(u, v))
    if s < 1e-9:
        if c > 0:
            return np.eye(3)
        perp = _unit(np.cross(u, [1.0, 0, 0] if abs(u[0]) < 0.9 else [0, 1.0, 0]))
        return 2 * np.outer(perp, perp) - np.eye(3)
    return _axis_angle(axis / s, np.arctan2(s, c))


def _axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    x, y, z = _unit(axis)
    K = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


@dataclass(frozen=True)
class Rig:
    """How one body follows one skeleton.

    Attributes:
        driver: (B,) skeleton joint driving each body bone.
        align: (B, 3, 3) rest alignment: a bone's world orientation is ``Q[driver] @ align``.
        leg_skeleton: the skeleton with the body's leg lengths and hip offsets (for the feet).
        root_lift: metres the body's root sits above the skeleton's root when both stand.
        ankle_lift: metres the body's ankle sits above the skeleton's ankle (heel) when both stand on their floors.
    """

    body: Body
    skeleton: Skeleton
    driver: np.ndarray
    align: np.ndarray
    leg_skeleton: Skeleton
    root_lift: float
    ankle_lift: float


def _joint(skeleton: Skeleton, *names: str) -> int | None:
    for n in names:
        if n in skeleton.joints:
            return skeleton.joints.index(n)
    return None


def _need(skeleton: Skeleton, *names: str) -> int:
    j = _joint(skeleton, *names)
    if j is None:
        raise RetargetError(f"skeleton {skeleton.name!r} has none of the joints {list(names)} a human body needs")
    return j


def _first_child(skeleton: Skeleton, j: int) -> int | None:
    kids = skeleton.children()[j]
    return kids[0] if kids else None


def fit_rig(body: Body, skeleton: Skeleton) -> Rig:
    """The :class:`Rig` of ``body`` on ``skeleton`` (see the module docstring)."""
    B = body.num_bones
    rest = skeleton.rest_positions()
    heads = body.bone_heads
    H = {label: heads[i] for i, label in enumerate(body.bone_labels)}
    driver = np.full(B, -1)
    S = np.tile(np.eye(3), (B, 1, 1))
    root = 0
    neck = _need(skeleton, "neck")
    _need(skeleton, "head")
    # trunk chain root .. neck with each joint's height fraction
    chain, j = [], neck
    while j > 0:
        chain.append(j)
        j = skeleton.parents[j]
    chain = [0] + chain[::-1]
    span = max(rest[neck, 1] - rest[0, 1], 1e-6)
    frac = [(rest[c, 1] - rest[0, 1]) / span for c in chain]
    body_span = max(H["neck01"][1] - H["root"][1], 1e-6)

    def set_bone(label: str, joint: int, s: np.ndarray) -> None:
        i = body.bone(label)
        driver[i], S[i] = joint, s

    for label in body.bone_labels:
        base = label.split(".")[0]
        if base in ("root", "spine05") or base == "pelvis":
            set_bone(label, root, np.eye(3))
        elif base.startswith("spine"):
            f = (H[label][1] - H["root"][1]) / body_span
            k = max(i for i, fc in enumerate(frac) if fc <= f + 0.02)
            set_bone(label, chain[k], np.eye(3))
        elif base.startswith("neck") or base in ("head", "eye"):
            # the head turns with the neck segment (neck -> head): the skeletons' head joint ends the chain, and
            # generators leave its own rotation unconstrained
            set_bone(label, neck, np.eye(3))
    for side, sfx in (("left", ".L"), ("right", ".R")):
        hip = _need(skeleton, f"{side}_hip")
        knee = _need(skeleton, f"{side}_knee")
        ankle = _need(skeleton, f"{side}_heel", f"{side}_ankle")
        toe = _need(skeleton, f"{side}_toe")
        shoulder = _need(skeleton, f"{side}_shoulder")
        elbow = _need(skeleton, f"{side}_elbow")
        wrist = _need(skeleton, f"{side}_hand", f"{side}_wrist")
        hand_end = _first_child(skeleton, wrist)
        ball = np.mean([H[f"toe{k}-1{sfx}"] for k in (2, 3, 4)], axis=0)
        # legs: thigh, shin, foot, chained
        s_thigh = _swing(H[f"lowerleg01{sfx}"] - H[f"upperleg01{sfx}"], rest[knee] - rest[hip])
        s_shin = _swing(s_thigh @ (H[f"foot{sfx}"] - H[f"lowerleg01{sfx}"]), rest[ankle] - rest[knee]) @ s_thigh
        s_foot = _swing(s_shin @ (ball - H[f"foot{sfx}"]), rest[toe] - rest[ankle]) @ s_shin
        for label in (f"upperleg01{sfx}", f"upperleg02{sfx}"):
            set_bone(label, hip, s_thigh)
        for label in (f"lowerleg01{sfx}", f"lowerleg02{sfx}"):
            set_bone(label, knee, s_shin)
        set_bone(f"foot{sfx}", ankle, s_foot)
        # arms: girdle with the trunk, then upper arm, forearm and hand, chained
        girdle = skeleton.parents[shoulder]
        for label in (f"clavicle{sfx}", f"shoulder01{sfx}"):
            set_bone(label, girdle, np.eye(3))
        s_upper = _swing(H[f"lowerarm01{sfx}"] - H[f"upperarm01{sfx}"], rest[elbow] - rest[shoulder])
        s_fore = _swing(s_upper @ (H[f"wrist{sfx}"] - H[f"lowerarm01{sfx}"]), rest[wrist] - rest[elbow]) @ s_upper
        for label in (f"upperarm01{sfx}", f"upperarm02{sfx}"):
            set_bone(label, shoulder, s_upper)
        for label in (f"lowerarm01{sfx}", f"lowerarm02{sfx}"):
            set_bone(label, elbow, s_fore)
        if hand_end is not None:
            s_hand = _swing(s_fore @ (H[f"finger3-1{sfx}"] - H[f"wrist{sfx}"]), rest[hand_end] - rest[wrist]) @ s_fore
            hand_joint = wrist
        else:
            s_hand, hand_joint = s_fore, elbow
        set_bone(f"wrist{sfx}", hand_joint, s_hand)
        for label in body.bone_labels:
            if label.endswith(sfx) and label.startswith("metacarpal"):
                set_bone(label, hand_joint, s_hand)
            elif label.endswith(sfx) and label.startswith("toe"):
                set_bone(label, ankle, s_foot)
        for finger in range(1, 6):
            names = [f"finger{finger}-{k}{sfx}" for k in (1, 2, 3)]
            p = [H[n] for n in names]
            d1, d2 = p[1] - p[0], p[2] - p[1]
            axis = np.cross(d1, d2)
            if np.linalg.norm(axis) < 1e-3 * np.linalg.norm(d1) * np.linalg.norm(d2):
                # a straight finger: bend it about the knuckle line, toward the palm side of the thumb's base
                axis = np.cross(d1, H[f"finger1-1{sfx}"] - p[0])
            curl = THUMB_CURL_DEG if finger == 1 else FINGER_CURL_DEG
            total = 0.0
            for name, deg in zip(names, curl):
                total += np.radians(deg)
                set_bone(name, hand_joint, s_hand @ _axis_angle(axis, total))
    missing = [body.bone_labels[i] for i in np.flatnonzero(driver < 0)]
    if missing:
        raise RetargetError(f"body {body.name!r}: no skeleton joint drives the bones {missing}")
    align = S @ body.bone_rest
    return Rig(body, skeleton, driver, align, *_leg_fit(body, skeleton))


def _leg_fit(body: Body, skeleton: Skeleton) -> tuple[Skeleton, float, float]:
    """The skeleton with the body's leg bone lengths and hip offsets, the root lift and the ankle lift."""
    rest = skeleton.rest_positions()
    H = {label: body.bone_heads[i] for i, label in enumerate(body.bone_labels)}
    off = skeleton.offsets.copy()
    sole = rest[:, 1].min() - SOLE_BELOW_LOWEST_JOINT * skeleton.height / 1.75
    lifts_root, lifts_ankle = [], []
    for leg, sfx in zip(legs(skeleton), (".L", ".R")):
        ball = np.mean([H[f"toe{k}-1{sfx}"] for k in (2, 3, 4)], axis=0)
        off[leg.hip] = H[f"upperleg01{sfx}"] - H["root"]
        for j, a, b in ((leg.knee, f"upperleg01{sfx}", f"lowerleg01{sfx}"), (leg.ankle, f"lowerleg01{sfx}",
                                                                              f"foot{sfx}")):
            off[j] = _unit(skeleton.offsets[j]) * np.linalg.norm(H[b] - H[a])
        off[leg.toe] = _unit(skeleton.offsets[leg.toe]) * np.linalg.norm(ball - H[f"foot{sfx}"])
        lifts_root.append(H["root"][1] - (rest[0, 1] - sole))
        lifts_ankle.append(H[f"foot{sfx}"][1] - (rest[leg.ankle, 1] - sole))
    return skeleton.with_offsets(off), float(np.mean(lifts_root)), float(np.mean(lifts_ankle))


def body_motion(rig: Rig, motion: Motion, extra_lift: np.ndarray | None = None) -> Motion:
    """The Motion on the rig's leg skeleton: root raised to the body's hip height, legs solved so each ankle reaches
    the Motion's own ankle (moved by the ankle-height difference, plus ``extra_lift`` (T, 2) metres per foot)."""
    P = motion.positions()
    lifted = replace(motion, skeleton=rig.leg_skeleton,
                     root_positions=motion.root_positions + np.array([0.0, rig.root_lift, 0.0]))
    extra = np.zeros((len(P), 2)) if extra_lift is None else extra_lift
    targets = tuple(P[:, leg.ankle] + np.array([0.0, rig.ankle_lift, 0.0]) + np.outer(extra[:, s], [0.0, 1.0, 0.0])
                    for s, leg in enumerate(legs(motion.skeleton)))
    return reach_ankles(lifted, targets, lower_pelvis=True)


def _transforms(rig: Rig, m: Motion, root_lift: float = 0.0) -> np.ndarray:
    Q = np_qto_matrix(global_rotations(m.rotations, m.skeleton.parents))          # (T, J, 3, 3)
    D = Q[:, rig.driver] @ rig.align[None]
    return bone_transforms(rig.body, D, m.root_positions + np.array([0.0, root_lift, 0.0]))


def sole_heights(rig: Rig, transforms: np.ndarray) -> np.ndarray:
    """(T, 2) lowest point of the left and right shoe (metres, world y) under ``transforms`` (T, B, 3, 4)."""
    body = rig.body
    shoes = np.flatnonzero(body.vertex_region == body.region_names.index("shoes"))
    pts = Skinner(body).points_many(transforms, shoes)
    left = body.vertices[shoes, 0] > 0
    return np.stack([pts[:, left, 1].min(1), pts[:, ~left, 1].min(1)], 1)


def pose_transforms(rig: Rig, motion: Motion, feet: bool = True, hands: bool = True) -> np.ndarray:
    """(T, B, 3, 4) bone transforms of the body following ``motion``.

    With ``feet`` (default) the ankles land on the Motion's ankles (:func:`body_motion`), and where the body's
    longer foot would dip its sole below the renderer's floor (a toe rolling over the ball of the foot) that ankle's
    target is raised by the depth, smoothed over 0.1 s, and the legs solved again. With ``hands`` (default) a hand
    that would go into a thigh or hip (a resting hand on a seated lap) is moved out by two-bone IK of the arm
    (:func:`hand_depths`)."""
    if not feet:
        return _transforms(rig, motion, rig.root_lift)
    m = body_motion(rig, motion)
    T = _transforms(rig, m)
    P = motion.positions()
    floor = P[..., 1].min() - SOLE_BELOW_LOWEST_JOINT * motion.skeleton.height / 1.75
    depth = np.maximum(floor - sole_heights(rig, T), 0.0)                           # (T, 2)
    if depth.max() > 1e-4:
        k = max(1, int(round(0.1 * motion.fps)))
        depth = np.stack([np.lib.stride_tricks.sliding_window_view(np.pad(d, k, mode="edge"), 2 * k + 1).max(1)
                          for d in depth.T], 1)
        m = body_motion(rig, motion, extra_lift=depth)
        T = _transforms(rig, m)
    return T if not hands else _hands_clear(rig, m, T)


#: Hands are kept this far (metres) outside the thighs and hips.
HAND_CLEARANCE_M = 0.006


def hand_depths(rig: Rig, transforms: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """How deep each hand is in the thighs and hips per frame: depths (T, 2) metres (left, right; 0 when clear)
    and the unit directions (T, 2, 3) out of them (the surface normal at the deepest point)."""
    from scipy.spatial import cKDTree

    body = rig.body
    top = body.weight_bones[np.arange(len(body.vertices)), np.argmax(body.weights, 1)]
    labels = body.bone_labels
    thigh = np.flatnonzero(np.isin(top, [i for i, n in enumerate(labels) if n.startswith(("upperleg", "pelvis"))]))
    sk = Skinner(body, rest_normals=vertex_normals(body.vertices, body.faces))
    tp, tn = sk.pose_many(transforms, thigh)
    depth = np.zeros((len(transforms), 2))
    direction = np.tile([0.0, 1.0, 0.0], (len(transforms), 2, 1))
    for s, sfx in enumerate((".L", ".R")):
        bones = [i for i, n in enumerate(labels) if n.endswith(sfx) and n.startswith(("wrist", "finger", "metacarpal"))]
        hp = sk.points_many(transforms, np.flatnonzero(np.isin(top, bones)))
        for t in range(len(transforms)):
            d, i = cKDTree(tp[t]).query(hp[t], distance_upper_bound=0.06)
            ok = np.isfinite(d)
            if not ok.any():
                continue
            inside = -((hp[t][ok] - tp[t][i[ok]]) * tn[t][i[ok]]).sum(1)
            k = int(np.argmax(inside))
            if inside[k] > -HAND_CLEARANCE_M:
                depth[t, s] = inside[k] + HAND_CLEARANCE_M
                direction[t, s] = tn[t][i[ok][k]]
    return depth, direction


def _hands_clear(rig: Rig, m: Motion, T: np.ndarray, passes: int = 4) -> np.ndarray:
    """Transforms with each hand moved out of the thighs and hips: the wrist is pushed out along the surface normal
    by the hand's depth (smoothed over 0.2 s, never less than needed) and the arm solved by two-bone IK."""
    sk = m.skeleton
    chains = []
    for side in ("left", "right"):
        shoulder, elbow = sk.index(f"{side}_shoulder"), sk.index(f"{side}_elbow")
        wrist = _joint(sk, f"{side}_hand", f"{side}_wrist")
        chains.append(Leg(shoulder, elbow, wrist, wrist))
    k = max(1, int(round(0.2 * m.fps)))
    # a body that stays in place (seated) rests its hands on its lap: lift them; a walker's swinging hands brush the
    # side of the thighs: push them out along the surface
    in_place = float(np.ptp(m.root_positions[:, [0, 2]], axis=0).max()) < 0.5
    for _ in range(passes):
        depth, direction = hand_depths(rig, T)
        if in_place:
            direction[:] = (0.0, 1.0, 0.0)
        if depth.max() <= 1e-4:
            break
        P = m.positions()
        push = depth[..., None] * direction                                          # (T, 2, 3)
        for s in range(2):
            mag = np.lib.stride_tricks.sliding_window_view(np.pad(depth[:, s], k, mode="edge"), 2 * k + 1).max(1)
            unit = push[:, s] / np.maximum(depth[:, s, None], 1e-9)
            unit[depth[:, s] <= 0] = direction[depth[:, s] <= 0, s]
            push[:, s] = unit * mag[:, None]
        targets = [P[:, c.ankle] + push[:, s] for s, c in enumerate(chains)]
        m = reach_targets(m, chains, targets)
        T = _transforms(rig, m)
    return T
