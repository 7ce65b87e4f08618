"""Seat a real captured (standing) gesture on the gesture skeleton as seed 003's agents sit: legs and pelvis held in
the seated rest pose, trunk, head and arms from the capture, hands kept clear of the body and the chair.

The capture is standing; the study's agents sit on a chair (seed 003 section 5.6). What is kept and what is not:

- pelvis and legs: the seated rest pose (:func:`generation.procedural.gesture.seated_rest_pose`), root fixed at
  the seated root position; the capture's steps, sway and pelvis translation are dropped;
- trunk: the capture's world orientation of the lower spine (``chest``) with the capture's mean heading turned to
  face +z, so a lean or a bow stays a lean or a bow of the same angle; spine, neck and head above it keep their
  captured local rotations;
- arms: the captured local rotations, except where the captured hand hangs at the side of a standing body
  (wrist below :data:`RAISED_FROM_M` above the pelvis along the trunk): a seated body has its thighs and the
  chair there, so the arm is eased (slerp per joint) into the seated rest arm (hands on the thighs) as the hand
  goes down, and fully so below :data:`REST_BELOW_M`. Both limits are heights above the pelvis along the trunk,
  scaled with the body height (1.75 m reference).
- clearance: frames where a wrist would still come closer than :data:`TRUNK_RADIUS_M` to the trunk axis,
  :data:`THIGH_RADIUS_M` to a thigh axis, or below the seat top above the chair (the chair of
  :func:`generation.render.scene.chair_boxes`) ease that arm further toward the rest arm until clear (smoothed
  over :data:`CLEARANCE_SMOOTH_S`). The smallest clearance reached is in the metadata.

Shapes: motions (T, 23, 4) local unit quaternions (w, x, y, z), metres, y-up. The result keeps the frame rate and
the capture's metadata (captured, dataset, take, licence, citation) and adds ``seated`` and ``seating``.
"""
from __future__ import annotations

import numpy as np

from generation.core.motion import Motion
from generation.core.quaternion import np_qconj, np_qfix, np_qmul, np_qrot, np_qslerp
from generation.core.rigging import smoothstep, yaw_quat
from generation.core.skeleton import GESTURE_JOINTS, GESTURE_PARENTS, Skeleton, gesture_skeleton
from generation.procedural.gesture import seated_rest_pose

J = {name: i for i, name in enumerate(GESTURE_JOINTS)}
#: Joints whose captured local rotations are kept as they are (spine above the lower chest, neck, head).
UPPER_TRUNK = ("chest2", "chest3", "chest4", "neck", "head")
ARM_JOINTS = {side: tuple(f"{side}_{j}" for j in ("collar", "shoulder", "elbow", "wrist"))
              for side in ("left", "right")}
#: Wrist height above the pelvis along the trunk (metres, 1.75 m body) below which the arm is the seated rest arm,
#: and above which it is the captured arm (smoothstep between). A standing body's hanging wrist is about 0.07 m
#: below the pelvis; a hand raised to gesture is well above it.
REST_BELOW_M = 0.02
RAISED_FROM_M = 0.20
TRUNK_RADIUS_M = 0.11
THIGH_RADIUS_M = 0.06
SEAT_MARGIN_M = 0.03
CLEARANCE_SMOOTH_S = 0.2
CLEARANCE_PASSES = 6
SEATING_METHOD = "generation.mocap.seated_gesture 1"


class SeatingError(ValueError):
    """The motion cannot be seated (not on the gesture skeleton, or fewer than 2 frames)."""


def heading_of(rotations_root: np.ndarray) -> float:
    """Mean heading (radians about +y, 0 = facing +z) of root rotations (T, 4): the circular mean of the
    horizontal direction +z is turned to."""
    fwd = np_qrot(rotations_root, np.broadcast_to([0.0, 0.0, 1.0], rotations_root.shape[:-1] + (3,)))
    return float(np.arctan2(fwd[:, 0].mean(), fwd[:, 2].mean()))


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance (T,) from points p (T, 3) to segments a-b (T, 3)."""
    ab = b - a
    t = np.clip(((p - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-12), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=-1)


def clearance(positions: np.ndarray, skeleton: Skeleton) -> dict[str, np.ndarray]:
    """Per frame and wrist, how far the wrist is inside (negative) or clear of (positive) the body and chair.

    positions (T, 23, 3) metres of a seated motion. Returns {"left": (T,), "right": (T,)} metres: the least of
    (distance to the trunk axis root-neck - TRUNK_RADIUS_M), (distance to either thigh axis hip-knee -
    THIGH_RADIUS_M) and, where the wrist is over the chair seat, (height above the seat top - SEAT_MARGIN_M).
    Radii scale with the body height.
    """
    s = skeleton.height / 1.75
    P = positions
    hips_y = P[:, [J["left_hip"], J["right_hip"]], 1].min()
    seat_top = hips_y - 0.07 * s  # as generation.render.scene.chair_boxes places the seat
    root0 = P[0, 0]
    out = {}
    for side in ("left", "right"):
        w = P[:, J[f"{side}_wrist"]]
        c = _segment_distance(w, P[:, J["root"]], P[:, J["neck"]]) - TRUNK_RADIUS_M * s
        for leg in ("left", "right"):
            c = np.minimum(c, _segment_distance(w, P[:, J[f"{leg}_hip"]], P[:, J[f"{leg}_knee"]]) - THIGH_RADIUS_M * s)
        rel = w - root0
        over_seat = (np.abs(rel[:, 0]) < 0.23 * s + SEAT_MARGIN_M) & (rel[:, 2] > -0.15 * s) & (rel[:, 2] < 0.30 * s)
        c = np.where(over_seat, np.minimum(c, w[:, 1] - seat_top - SEAT_MARGIN_M * s), c)
        out[side] = c
    return out


def _smooth_max(x: np.ndarray, n: int) -> np.ndarray:
    """Running maximum over +-n frames followed by a moving average of the same width (a soft dilation)."""
    if n <= 0:
        return x
    pad = np.pad(x, n, mode="edge")
    dil = np.stack([pad[k:k + len(x)] for k in range(2 * n + 1)]).max(0)
    pad = np.pad(dil, n, mode="edge")
    return np.convolve(pad, np.ones(2 * n + 1) / (2 * n + 1), mode="valid")


def _world_rotation(rotations: np.ndarray, joint: str) -> np.ndarray:
    """World rotation (..., 4) of a joint of the gesture skeleton from local rotations (..., 23, 4)."""
    chain = []
    j = J[joint]
    while j >= 0:
        chain.append(j)
        j = GESTURE_PARENTS[j]
    world = rotations[..., chain[-1], :]
    for j in reversed(chain[:-1]):
        world = np_qmul(world, rotations[..., j, :])
    return world


def _rest_arm(rest: np.ndarray, seated: np.ndarray, joints: tuple[str, ...]) -> np.ndarray:
    """The seated rest arm (T, 4 joints, 4) under the seated trunk ``seated`` (T, 23, 4): the collar keeps its
    rest pose's world orientation (so a leaning trunk carries the hands forward along the thighs instead of
    rotating them down into them), the joints below it their rest local rotations."""
    T = len(seated)
    collar = joints[0]
    parent = GESTURE_JOINTS[GESTURE_PARENTS[J[collar]]]
    world_collar = np.broadcast_to(_world_rotation(rest, collar), (T, 4))
    arm = np.repeat(rest[None, [J[n] for n in joints]], T, axis=0)
    arm[:, 0] = np_qmul(np_qconj(_world_rotation(seated, parent)), world_collar)
    return arm


def seat_gesture(motion: Motion, build: str | None = None) -> Motion:
    """The seated version of a captured gesture ``motion`` (gesture skeleton, T >= 2 frames).

    Args:
        motion: a standing captured gesture on the 23-joint gesture skeleton (e.g. a real-corpus clip).
        build: "male" or "female" body to seat it on (default: the motion's own build), at the motion's height.

    Returns:
        a new Motion (T, 23, 4) at the same fps on that body, root fixed at the seated root position, metadata
        copied plus ``seated: True`` and ``seating`` (method, arm_capture_share per arm: mean weight of the
        captured arm, min_clearance_m: the smallest wrist clearance reached, heading_deg removed).
    """

    if tuple(motion.skeleton.joints) != GESTURE_JOINTS or motion.num_frames < 2:
        raise SeatingError(f"seat_gesture needs a motion on the 23-joint gesture skeleton with >= 2 frames, got "
                           f"{motion.skeleton.name!r} ({motion.skeleton.num_joints} joints, {motion.num_frames} "
                           f"frames)")
    skeleton = gesture_skeleton(motion.skeleton.height, build or motion.skeleton.build)
    s = skeleton.height / 1.75
    Q = np_qfix(np.asarray(motion.rotations, dtype=np.float64))
    T = len(Q)
    rest, root = seated_rest_pose(skeleton)
    heading = heading_of(Q[:, 0])
    unturn = np.broadcast_to(yaw_quat(-heading), (T, 4))
    chest_world = np_qmul(unturn, np_qmul(Q[:, 0], Q[:, J["chest"]]))
    out = np.repeat(rest[None], T, axis=0)
    out[:, J["chest"]] = np_qmul(np.broadcast_to(np_qconj(rest[0]), (T, 4)), chest_world)
    for name in UPPER_TRUNK:
        out[:, J[name]] = Q[:, J[name]]
    captured = {side: Q[:, [J[n] for n in joints]] for side, joints in ARM_JOINTS.items()}
    rest_arm = {side: _rest_arm(rest, out, joints) for side, joints in ARM_JOINTS.items()}

    # how far each captured hand is raised above a standing body's hanging rest, along the captured trunk
    Pc = motion.positions()
    up = np_qrot(np_qmul(Q[:, 0], Q[:, J["chest"]]), np.broadcast_to([0.0, 1.0, 0.0], (T, 3)))
    weight = {}
    for side in ARM_JOINTS:
        h = ((Pc[:, J[f"{side}_wrist"]] - Pc[:, J["root"]]) * up).sum(-1) / (motion.skeleton.height / 1.75)
        weight[side] = smoothstep((h - REST_BELOW_M) / (RAISED_FROM_M - REST_BELOW_M))

    def pose(weights: dict[str, np.ndarray]) -> np.ndarray:
        rot = out.copy()
        for side, joints in ARM_JOINTS.items():
            w = np.broadcast_to(weights[side][:, None], (T, len(joints)))
            rot[:, [J[n] for n in joints]] = np_qslerp(rest_arm[side], captured[side], w)
        return rot

    roots = np.repeat(np.asarray(root, dtype=np.float64)[None], T, axis=0)
    n_smooth = max(1, int(round(CLEARANCE_SMOOTH_S * motion.fps)))
    for _ in range(CLEARANCE_PASSES):
        rot = pose(weight)
        clear = clearance(Motion(skeleton, rot, roots, motion.fps, {}).positions(), skeleton)
        if min(float(c.min()) for c in clear.values()) >= -1e-4:
            break
        for side, c in clear.items():
            # scale the captured arm down where it is inside, by how deep (10 cm deep -> rest arm), smoothly
            depth = _smooth_max(np.clip(-c / (0.10 * s), 0.0, 1.0), n_smooth)
            weight[side] = weight[side] * (1.0 - np.clip(depth + (c < 0) * 0.25, 0.0, 1.0))
    rot = pose(weight)
    clear = clearance(Motion(skeleton, rot, roots, motion.fps, {}).positions(), skeleton)
    meta = dict(motion.metadata)
    meta.update({"seated": True, "seating": {
        "method": SEATING_METHOD, "heading_deg": round(float(np.degrees(heading)), 2),
        "arm_capture_share": {side: round(float(w.mean()), 4) for side, w in weight.items()},
        "min_clearance_m": round(min(float(c.min()) for c in clear.values()), 4)}})
    return Motion(skeleton, np_qfix(rot), roots, motion.fps, meta)
