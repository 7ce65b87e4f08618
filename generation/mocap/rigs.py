"""Joint-name normalisation and automatic rig maps onto the gait and gesture skeletons.

A source joint name is reduced to a key ``<side>_<part>`` (or ``<part>`` on the midline):
- namespace prefixes are dropped: anything up to the last ``:`` (``mixamorig:``, ``mixamorig1:``), ``Bip01 ``,
  ``Bip001_``, ``Character1_``;
- the name is split into words at separators (space, ``_``, ``-``, ``.``) and camel-case boundaries and
  lower-cased; a word ``left``/``l`` or ``right``/``r`` anywhere gives the side (``LeftUpLeg``, ``Shoulder_L``,
  ``ShoulderLeft``, ``L Thigh``, ``lShldr``); the remaining words are joined.
So ``mixamorig:LeftUpLeg`` -> ``left_upleg``, ``Bip01 L Calf`` -> ``left_calf``, ``UpperArm_L`` ->
``left_upperarm``, ``ElbowLeft`` -> ``left_elbow``, ``mixamorig:LeftHand_end`` (a BVH end site) ->
``left_handend``.

Each of our joints has an ordered list of candidate keys covering Mixamo, CMU BVH, Biovision/MotionBuilder, 3ds
Max Biped, Bandai-Namco, Kinect v2 and Unreal mannequin (``thigh_l``, ``spine_03``) names. Joints are resolved in
:data:`RESOLVE_ORDER` and a source joint is used once, which settles the names that mean different things in
different rigs: ``LeftShoulder`` is the upper-arm joint in Biovision and Kinect (no ``LeftArm`` there) but the
clavicle in Mixamo and CMU (where ``LeftArm`` is the upper arm and is taken first); the gait ``spine`` (where the
arms branch) takes ``Spine2`` (Mixamo), ``Spine1`` (CMU, Biped), ``Chest4``..``Chest`` (MotionBuilder, Biovision,
Bandai) or ``SpineShoulder`` (Kinect) before ``lower_back`` takes what is left below it.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

from generation.core.skeleton import Skeleton

_PREFIX = re.compile(r"^(?:.*:|bip0*\d+[ _]+|character\d*_)", re.IGNORECASE)
_WORDS = re.compile(r"[A-Z]+(?=[A-Z][a-z])|[A-Z]?[a-z]+|[A-Z]+|\d+")
_SIDES = {"left": "left", "l": "left", "right": "right", "r": "right"}


def normalise(name: str) -> str:
    """Comparable key of a joint name: ``<side>_<part>`` or ``<part>`` (see the module docstring)."""
    stripped = _PREFIX.sub("", name.strip()) or name.strip()
    side = ""
    words = []
    for chunk in re.split(r"[\s_\-.]+", stripped):
        for w in _WORDS.findall(chunk):
            lw = w.lower()
            if lw in _SIDES and not side:
                side = _SIDES[lw]
            else:
                words.append(lw)
    part = "".join(words)
    return f"{side}_{part}" if side else part


def _sided(table: dict[str, tuple[str, ...]]) -> dict[str, tuple[str, ...]]:
    """Expand ``side_*`` entries of a table into left_ and right_ entries."""
    out = {}
    for joint, keys in table.items():
        if joint.startswith("side_"):
            for s in ("left", "right"):
                out[f"{s}_{joint[5:]}"] = tuple(k.replace("side_", f"{s}_") for k in keys)
        else:
            out[joint] = keys
    return out


_ROOT = ("hips", "pelvis", "hip", "root", "spinebase", "bip01")
_CHEST_TOP = ("spine2", "spine1", "chest4", "chest3", "chest2", "chest", "spineshoulder", "upperchest", "spine3",
              "spine03")
_CHEST_LOW = ("lowerback", "spine", "abdomen", "spinemid", "chest", "spine1", "spine01")
_NECK = ("neck", "neck01", "neck1")
_HEAD = ("head", "neck1", "headtopend", "headend", "neckend")
_LEGS = {
    "side_hip": ("side_upleg", "side_thigh", "side_upperleg", "side_hip"),
    "side_knee": ("side_leg", "side_lowerleg", "side_knee", "side_calf", "side_shin"),
    "side_ankle": ("side_ankle", "side_foot"),
    "side_toe": ("side_toebase", "side_toes", "side_toe", "side_toe0", "side_ball", "side_foot", "side_toebaseend",
                 "side_toeend", "side_toesend", "side_toe0end", "side_footend", "side_ankleend", "side_heelend"),
}
_ARMS = {
    "side_shoulder": ("side_arm", "side_upperarm", "side_shldr", "side_shoulder"),
    "side_collar": ("side_collar", "side_clavicle", "side_shoulder"),
    "side_elbow": ("side_forearm", "side_lowerarm", "side_elbow"),
    "side_wrist": ("side_wrist", "side_hand"),
    "side_index": ("side_handindex1", "side_handmiddle1", "side_finger0", "side_finger1", "side_fingerbase",
                   "side_hand", "side_handtip", "side_handindex1end", "side_finger0end", "side_handend",
                   "side_wristend"),
}

#: our gait joint -> candidate source keys (first present and unused wins)
GAIT_CANDIDATES: dict[str, tuple[str, ...]] = _sided({
    # our own names last (the BVH files the renderer keeps: motions/<clip_id>.bvh): "spine" is the chest only when
    # the rig has no higher spine joint, "heel" is our ankle
    "root": _ROOT, "spine": (*_CHEST_TOP, "spine"), "lower_back": _CHEST_LOW, "neck": _NECK, "head": _HEAD,
    "side_hip": _LEGS["side_hip"], "side_knee": _LEGS["side_knee"], "side_heel": (*_LEGS["side_ankle"], "side_heel"),
    "side_toe": _LEGS["side_toe"],
    "side_shoulder": _ARMS["side_shoulder"], "side_elbow": _ARMS["side_elbow"], "side_hand": _ARMS["side_wrist"],
    "side_hand_index": _ARMS["side_index"],
})
#: our gesture joint -> candidate source keys
GESTURE_CANDIDATES: dict[str, tuple[str, ...]] = _sided({
    "root": _ROOT, "chest4": _CHEST_TOP, "chest": _CHEST_LOW, "chest2": ("spine1", "spine", "chest2"),
    "chest3": ("spine2", "chest3"), "neck": _NECK, "head": _HEAD,
    "side_hip": _LEGS["side_hip"], "side_knee": _LEGS["side_knee"], "side_ankle": _LEGS["side_ankle"],
    "side_toe": _LEGS["side_toe"],
    "side_shoulder": _ARMS["side_shoulder"], "side_collar": _ARMS["side_collar"],
    "side_elbow": _ARMS["side_elbow"], "side_wrist": _ARMS["side_wrist"],
})

#: resolution order: joints whose names are ambiguous across rigs come after the ones that disambiguate them
RESOLVE_ORDER = ("root", "spine", "chest4", "lower_back", "chest", "chest2", "chest3", "neck", "head",
                 "left_hip", "left_knee", "left_heel", "left_ankle", "left_toe",
                 "right_hip", "right_knee", "right_heel", "right_ankle", "right_toe",
                 "left_shoulder", "left_collar", "left_elbow", "left_hand", "left_wrist", "left_hand_index",
                 "right_shoulder", "right_collar", "right_elbow", "right_hand", "right_wrist", "right_hand_index")

#: joints that must be mapped (the rest are interpolated between mapped neighbours or follow their parent)
REQUIRED = {
    "gait": ("root", "left_hip", "left_knee", "left_heel", "right_hip", "right_knee", "right_heel", "spine",
             "left_shoulder", "left_elbow", "left_hand", "right_shoulder", "right_elbow", "right_hand"),
    "gesture": ("root", "left_hip", "left_knee", "left_ankle", "right_hip", "right_knee", "right_ankle", "chest4",
                "left_shoulder", "left_elbow", "left_wrist", "right_shoulder", "right_elbow", "right_wrist"),
}

JOINT_MAP_HELP = ('--joint-map takes a JSON file holding one object {our_joint: their_joint}, e.g. '
                  '{"root": "pelvis_jnt", "left_hip": "thigh_l"}; names given there override the automatic map')


class RigMapError(ValueError):
    """A source rig cannot be mapped onto our skeleton; the message lists what was found and what is missing."""


def candidates_for(target: Skeleton) -> dict[str, tuple[str, ...]]:
    return GAIT_CANDIDATES if "left_hand_index" in target.joints else GESTURE_CANDIDATES


def required_for(target: Skeleton) -> tuple[str, ...]:
    return REQUIRED["gait" if "left_hand_index" in target.joints else "gesture"]


def auto_joint_map(source_joints, target: Skeleton, overrides: dict[str, str] | None = None) -> dict[str, str]:
    """{our joint: source joint} from normalised names; ``overrides`` (exact or normalised source names) first.

    Raises:
        RigMapError: an override names a joint we do not have or a source joint that is not there.
    """
    source_joints = list(source_joints)
    by_key: dict[str, str] = {}
    for name in source_joints:
        by_key.setdefault(normalise(name), name)
    out: dict[str, str] = {}
    used: set[str] = set()
    for ours, theirs in (overrides or {}).items():
        if ours not in target.joints:
            raise RigMapError(f"--joint-map names {ours!r}, which is not a joint of the {target.name} skeleton "
                              f"(ours: {', '.join(target.joints)})")
        found = theirs if theirs in source_joints else by_key.get(normalise(str(theirs)))
        if found is None:
            raise RigMapError(f"--joint-map maps {ours!r} to {theirs!r}, which the file does not have "
                              f"(joints found: {', '.join(source_joints)})")
        out[ours] = found
        used.add(found)
    table = candidates_for(target)
    for ours in RESOLVE_ORDER:
        if ours not in target.joints or ours in out:
            continue
        for key in table[ours]:
            name = by_key.get(key)
            if name is not None and name not in used:
                out[ours] = name
                used.add(name)
                break
    return {j: out[j] for j in target.joints if j in out}


def check_joint_map(joint_map: dict[str, str], source_joints, target: Skeleton, source: str = "") -> None:
    """RigMapError naming the joints found, the required ones missing and the ``--joint-map`` format."""
    missing = [j for j in required_for(target) if j not in joint_map]
    if missing:
        where = f"{source}: " if source else ""
        raise RigMapError(
            f"{where}cannot map this rig onto the {target.name} skeleton: missing {', '.join(missing)}. "
            f"Joints found in the file: {', '.join(source_joints)}. Mapped so far: "
            f"{', '.join(f'{k}={v}' for k, v in joint_map.items()) or 'nothing'}. {JOINT_MAP_HELP}")


def load_joint_map(path: str | Path) -> dict[str, str]:
    """Read a ``--joint-map`` JSON file: one object of strings {our_joint: their_joint}."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise RigMapError(f"{path}: cannot read the joint map ({exc.strerror or exc})") from None
    except json.JSONDecodeError as exc:
        raise RigMapError(f"{path}: line {exc.lineno}: not valid JSON ({exc.msg}). {JOINT_MAP_HELP}") from None
    if not isinstance(data, dict) or not all(isinstance(k, str) and isinstance(v, str) for k, v in data.items()):
        raise RigMapError(f"{path}: the joint map must be one JSON object of strings. {JOINT_MAP_HELP}")
    return data
