"""Our motions re-exported as other rigs would write them: the fixtures of the importer's tests and benchmark.

:func:`export_as` renames our joints under a naming convention (:data:`CONVENTIONS`), inserts the joints those
rigs have and we do not (Mixamo's and CMU's clavicles, CMU's ``LHipJoint`` and ``Neck1``, Mixamo's ``Spine1``,
...), can change the rest pose (arms out in a T-pose: different offsets, the same bone lengths) and writes a BVH
in centimetres with a chosen rotation order. The global joint positions are exactly those of the input motion,
so importing the file back must recover them (up to the BVH text precision).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generation.core.ik import solve_rotations
from generation.core.motion import Motion
from generation.core.skeleton import Skeleton
from generation.formats.bvh import write_bvh


@dataclass(frozen=True)
class Convention:
    """A rig's names for our joints.

    Attributes:
        names: {our joint: their name}, per side with ``{s}`` for the side word and ``{S}`` for its letter
            (``Left``/``L``); a leaf named None is written as a BVH End Site (its name becomes
            ``<parent>_end``).
        inserts: (their name, our joint, fraction): a joint of theirs on the bone into our joint, at that
            fraction of it from the parent.
        side_words: how the convention writes (left, right) in ``{s}``; ``{S}`` takes the first letter.
    """

    names: dict[str, str | None]
    inserts: tuple[tuple[str, str, float], ...] = ()
    side_words: tuple[str, str] = ("Left", "Right")
    rotation_order: str = "ZXY"
    extra: dict = field(default_factory=dict)

    def resolve(self, joint: str, template: str | None) -> str | None:
        if template is None:
            return None
        for side, word in zip(("left", "right"), self.side_words):
            if joint.startswith(side + "_"):
                return template.format(s=word, S=word[0])
        return template


def _sided(table: dict[str, str | None]) -> dict[str, str | None]:
    out = {}
    for k, v in table.items():
        if k.startswith("side_"):
            out["left_" + k[5:]] = v
            out["right_" + k[5:]] = v
        else:
            out[k] = v
    return out


_GAIT = {
    "mixamo": Convention(_sided({
        "root": "mixamorig:Hips", "lower_back": "mixamorig:Spine", "spine": "mixamorig:Spine2",
        "neck": "mixamorig:Neck", "head": "mixamorig:Head",
        "side_hip": "mixamorig:{s}UpLeg", "side_knee": "mixamorig:{s}Leg", "side_heel": "mixamorig:{s}Foot",
        "side_toe": "mixamorig:{s}ToeBase", "side_shoulder": "mixamorig:{s}Arm",
        "side_elbow": "mixamorig:{s}ForeArm", "side_hand": "mixamorig:{s}Hand",
        "side_hand_index": "mixamorig:{s}HandIndex1"}),
        inserts=(("mixamorig:Spine1", "spine", 0.5), ("mixamorig:{s}Shoulder", "side_shoulder", 0.4))),
    "cmu": Convention(_sided({
        "root": "Hips", "lower_back": "LowerBack", "spine": "Spine1", "neck": "Neck", "head": "Head",
        "side_hip": "{s}UpLeg", "side_knee": "{s}Leg", "side_heel": "{s}Foot", "side_toe": "{s}ToeBase",
        "side_shoulder": "{s}Arm", "side_elbow": "{s}ForeArm", "side_hand": "{s}Hand",
        "side_hand_index": "{s}HandIndex1"}),
        inserts=(("Spine", "spine", 0.5), ("Neck1", "head", 0.5), ("{S}HipJoint", "side_hip", 0.3),
                 ("{s}Shoulder", "side_shoulder", 0.4)), rotation_order="ZYX"),
    "biovision": Convention(_sided({
        "root": "Hips", "lower_back": "Chest", "spine": "Chest2", "neck": "Neck", "head": "Head",
        "side_hip": "{s}Hip", "side_knee": "{s}Knee", "side_heel": "{s}Ankle", "side_toe": None,
        "side_shoulder": "{s}Shoulder", "side_elbow": "{s}Elbow", "side_hand": "{s}Wrist",
        "side_hand_index": None}),
        inserts=(("{s}Collar", "side_shoulder", 0.4),), rotation_order="ZXY"),
    "biped": Convention(_sided({
        "root": "Bip01 Pelvis", "lower_back": "Bip01 Spine", "spine": "Bip01 Spine1", "neck": "Bip01 Neck",
        "head": "Bip01 Head", "side_hip": "Bip01 {S} Thigh", "side_knee": "Bip01 {S} Calf",
        "side_heel": "Bip01 {S} Foot", "side_toe": "Bip01 {S} Toe0", "side_shoulder": "Bip01 {S} UpperArm",
        "side_elbow": "Bip01 {S} Forearm", "side_hand": "Bip01 {S} Hand", "side_hand_index": "Bip01 {S} Finger0"}),
        inserts=(("Bip01 {S} Clavicle", "side_shoulder", 0.4),), rotation_order="YXZ"),
    "bandai": Convention(_sided({
        "root": "Hips", "lower_back": "Spine", "spine": "Chest", "neck": "Neck", "head": "Head",
        "side_hip": "UpperLeg_{S}", "side_knee": "LowerLeg_{S}", "side_heel": "Foot_{S}", "side_toe": "Toes_{S}",
        "side_shoulder": "UpperArm_{S}", "side_elbow": "LowerArm_{S}", "side_hand": "Hand_{S}",
        "side_hand_index": None}),
        inserts=(("Shoulder_{S}", "side_shoulder", 0.4),), rotation_order="XYZ"),
    "kinect": Convention(_sided({
        "root": "SpineBase", "lower_back": "SpineMid", "spine": "SpineShoulder", "neck": "Neck", "head": "Head",
        "side_hip": "Hip{s}", "side_knee": "Knee{s}", "side_heel": "Ankle{s}", "side_toe": "Foot{s}",
        "side_shoulder": "Shoulder{s}", "side_elbow": "Elbow{s}", "side_hand": "Wrist{s}",
        "side_hand_index": "Hand{s}"}), rotation_order="ZXY"),
}

_GESTURE = {
    "mixamo": Convention(_sided({
        "root": "mixamorig:Hips", "chest": "mixamorig:Spine", "chest2": "mixamorig:Spine1",
        "chest3": "mixamorig:Spine1Bend", "chest4": "mixamorig:Spine2", "neck": "mixamorig:Neck",
        "head": "mixamorig:Head", "side_collar": "mixamorig:{s}Shoulder", "side_shoulder": "mixamorig:{s}Arm",
        "side_elbow": "mixamorig:{s}ForeArm", "side_wrist": "mixamorig:{s}Hand", "side_hip": "mixamorig:{s}UpLeg",
        "side_knee": "mixamorig:{s}Leg", "side_ankle": "mixamorig:{s}Foot", "side_toe": "mixamorig:{s}ToeBase"})),
    "motionbuilder": Convention(_sided({
        "root": "Hips", "chest": "Chest", "chest2": "Chest2", "chest3": "Chest3", "chest4": "Chest4",
        "neck": "Neck", "head": "Head", "side_collar": "{s}Collar", "side_shoulder": "{s}Shoulder",
        "side_elbow": "{s}Elbow", "side_wrist": "{s}Wrist", "side_hip": "{s}Hip", "side_knee": "{s}Knee",
        "side_ankle": "{s}Ankle", "side_toe": "{s}Toe"})),
}

#: skeleton name -> convention name -> Convention
CONVENTIONS: dict[str, dict[str, Convention]] = {"gait": _GAIT, "gesture": _GESTURE}

_ARM_BONES = ("shoulder", "elbow", "hand", "wrist", "hand_index")


def _tpose(sk: Skeleton, offsets: np.ndarray, names_ours: list[str | None]) -> np.ndarray:
    """Arm bones below the shoulders turned horizontal (outward along +-x), lengths kept."""
    out = offsets.copy()
    for k, ours in enumerate(names_ours):
        if ours is None:
            continue
        side, _, part = ours.partition("_")
        if side in ("left", "right") and part in _ARM_BONES[1:]:
            out[k] = np.array([1.0 if side == "left" else -1.0, 0.0, 0.0]) * np.linalg.norm(offsets[k])
    return out


def convention_motion(motion: Motion, convention: str, tpose: bool = True) -> Motion:
    """``motion`` on a renamed skeleton with the convention's extra joints; FK positions of our joints equal."""
    conv = CONVENTIONS[motion.skeleton.name][convention]
    sk = motion.skeleton
    P = motion.positions()
    inserts = {}
    for name, ours, frac in conv.inserts:
        for joint in ([f"left_{ours[5:]}", f"right_{ours[5:]}"] if ours.startswith("side_") else [ours]):
            inserts[joint] = (conv.resolve(joint, name), frac)
    names, parents, offsets, cols, ours_of = [], [], [], [], []
    where: dict[int, int] = {}
    leaves = [j for j, kids in enumerate(sk.children()) if not kids]
    for j, joint in enumerate(sk.joints):
        p = sk.parents[j]
        parent_new = where[p] if p >= 0 else -1
        off = sk.offsets[j]
        pos = P[:, j]
        if joint in inserts:
            ins_name, frac = inserts[joint]
            names.append(ins_name)
            parents.append(parent_new)
            offsets.append(off * frac)
            cols.append(P[:, p] + frac * (P[:, j] - P[:, p]))
            ours_of.append(None)
            parent_new = len(names) - 1
            off = off * (1.0 - frac)
        their = conv.resolve(joint, conv.names[joint])
        names.append(their if their is not None else f"__{joint}")
        parents.append(parent_new)
        offsets.append(off)
        cols.append(pos)
        ours_of.append(joint)
        where[j] = len(names) - 1
    known = [True] * len(names)
    for j in leaves:   # a named leaf gets an end site so that it is written as a JOINT
        if conv.names[sk.joints[j]] is not None:
            names.append(f"{names[where[j]]}End")
            parents.append(where[j])
            offsets.append(np.array([0.0, 0.05, 0.0]))
            cols.append(P[:, sk.joints.index(sk.joints[j])])
            ours_of.append(None)
            known.append(False)
    offsets = np.array(offsets)
    if tpose:
        offsets = _tpose(sk, offsets, ours_of)
    src = Skeleton(f"{sk.name}-{convention}", tuple(names), tuple(parents), offsets, sk.height, sk.build)
    Psrc = np.stack(cols, 1)
    rotations = solve_rotations(Psrc, src, np.array(known))
    return Motion(src, rotations, Psrc[:, 0].copy(), motion.fps, {"convention": convention})


def export_as(motion: Motion, convention: str, path: str | Path, centimetres: bool = True, tpose: bool = True) -> Path:
    """Write ``motion`` (gait or gesture skeleton) as a BVH under a naming convention; returns the path."""
    conv = CONVENTIONS[motion.skeleton.name][convention]
    write_bvh(convention_motion(motion, convention, tpose), path, rotation_order=conv.rotation_order,
              scale=100.0 if centimetres else 1.0)
    return Path(path)
