"""Skeletons: joint names, parents and bone offsets (metres, y-up, facing +z, left = +x).

A skeleton is a small immutable description of a hierarchy, as in QuaterNet's ``Skeleton``.
In the rest pose (all local rotations identity) the body stands upright with arms hanging at the
sides. Offsets are the vector from a joint's parent to the joint, in the parent's rest frame.

Two skeletons are used by the project:
- the 21-joint gait skeleton of seed 000 (Fig. 2; the authors' released code);
- the 23-joint gesture skeleton of seed 003 (Fig. 1; MPI Emotional Body Expressions database).
Both scale to a body height and a build (``"male"`` or ``"female"``; seed 003 lets the agent's
gender pick its body structure).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

REFERENCE_HEIGHT_M = 1.75

GAIT_JOINTS = (
    "root", "left_hip", "left_knee", "left_heel", "left_toe",
    "right_hip", "right_knee", "right_heel", "right_toe",
    "lower_back", "spine", "neck", "head",
    "left_shoulder", "left_elbow", "left_hand", "left_hand_index",
    "right_shoulder", "right_elbow", "right_hand", "right_hand_index",
)
GAIT_PARENTS = (-1, 0, 1, 2, 3, 0, 5, 6, 7, 0, 9, 10, 11, 10, 13, 14, 15, 10, 17, 18, 19)

GESTURE_JOINTS = (
    "root", "chest", "chest2", "chest3", "chest4", "neck", "head",
    "left_collar", "left_shoulder", "left_elbow", "left_wrist",
    "right_collar", "right_shoulder", "right_elbow", "right_wrist",
    "left_hip", "left_knee", "left_ankle", "left_toe",
    "right_hip", "right_knee", "right_ankle", "right_toe",
)
GESTURE_PARENTS = (-1, 0, 1, 2, 3, 4, 5, 4, 7, 8, 9, 4, 11, 12, 13, 0, 15, 16, 17, 0, 19, 20, 21)

# Width factors per build: shoulders (lateral offsets above the pelvis) and hips.
BUILDS = {
    "male": {"shoulder_width": 1.0, "hip_width": 1.0},
    "female": {"shoulder_width": 0.88, "hip_width": 1.12},
}

# Rest offsets for a 1.75 m male body. Pelvis (root) about 0.95 m above the ground.
_GAIT_OFFSETS = {
    "root": (0.0, 0.0, 0.0),
    "left_hip": (0.09, -0.05, 0.0),
    "left_knee": (0.0, -0.43, 0.0),
    "left_heel": (0.0, -0.41, -0.02),
    "left_toe": (0.0, -0.05, 0.15),
    "lower_back": (0.0, 0.10, 0.0),
    "spine": (0.0, 0.25, 0.0),
    "neck": (0.0, 0.20, 0.0),
    "head": (0.0, 0.17, 0.02),
    "left_shoulder": (0.17, 0.15, 0.0),
    "left_elbow": (0.0, -0.29, 0.0),
    "left_hand": (0.0, -0.25, 0.0),
    "left_hand_index": (0.0, -0.08, 0.0),
}
_GESTURE_OFFSETS = {
    "root": (0.0, 0.0, 0.0),
    "chest": (0.0, 0.09, 0.0),
    "chest2": (0.0, 0.09, 0.0),
    "chest3": (0.0, 0.09, 0.0),
    "chest4": (0.0, 0.09, 0.0),
    "neck": (0.0, 0.13, 0.0),
    "head": (0.0, 0.15, 0.02),
    "left_collar": (0.04, 0.10, 0.0),
    "left_shoulder": (0.13, 0.0, 0.0),
    "left_elbow": (0.0, -0.29, 0.0),
    "left_wrist": (0.0, -0.25, 0.0),
    "left_hip": (0.09, -0.05, 0.0),
    "left_knee": (0.0, -0.43, 0.0),
    "left_ankle": (0.0, -0.41, -0.02),
    "left_toe": (0.0, -0.05, 0.15),
}


@dataclass(frozen=True)
class Skeleton:
    """A joint hierarchy.

    Attributes:
        name: "gait" or "gesture" (or the source's name for imported hierarchies).
        joints: joint names, length J.
        parents: parent index per joint, -1 for the root, parents before children.
        offsets: (J, 3) float64 rest offsets in metres from the parent, in the parent's frame.
        height: standing height in metres the offsets were scaled to.
        build: "male" or "female".
    """

    name: str
    joints: tuple[str, ...]
    parents: tuple[int, ...]
    offsets: np.ndarray = field(repr=False)
    height: float = REFERENCE_HEIGHT_M
    build: str = "male"

    def __post_init__(self):
        offsets = np.asarray(self.offsets, dtype=np.float64)
        if offsets.shape != (len(self.joints), 3):
            raise ValueError(f"offsets must be ({len(self.joints)}, 3), got {offsets.shape}")
        if len(self.parents) != len(self.joints):
            raise ValueError("parents and joints differ in length")
        for j, p in enumerate(self.parents):
            if (j == 0) != (p == -1) or p >= j:
                raise ValueError(f"joint {j} ({self.joints[j]}) has parent {p}; parents must precede children")
        offsets.setflags(write=False)
        object.__setattr__(self, "offsets", offsets)

    @property
    def num_joints(self) -> int:
        return len(self.joints)

    def index(self, name: str) -> int:
        """Index of a joint by name; KeyError naming the skeleton when missing."""
        try:
            return self.joints.index(name)
        except ValueError:
            raise KeyError(f"skeleton {self.name!r} has no joint {name!r}") from None

    def children(self) -> list[list[int]]:
        """Children indices per joint."""
        kids: list[list[int]] = [[] for _ in self.joints]
        for j, p in enumerate(self.parents):
            if p >= 0:
                kids[p].append(j)
        return kids

    def bone_lengths(self) -> np.ndarray:
        """(J,) length of each joint's offset (0 for the root)."""
        return np.linalg.norm(self.offsets, axis=1)

    def mirror_map(self) -> np.ndarray:
        """(J,) index of each joint's left/right counterpart (itself on the midline)."""
        mapping = np.arange(self.num_joints)
        for j, name in enumerate(self.joints):
            for a, b in (("left_", "right_"), ("right_", "left_")):
                if name.startswith(a):
                    mapping[j] = self.index(b + name[len(a):])
        return mapping

    @property
    def left_joints(self) -> list[int]:
        return [j for j, n in enumerate(self.joints) if n.startswith("left_")]

    @property
    def right_joints(self) -> list[int]:
        return [j for j, n in enumerate(self.joints) if n.startswith("right_")]

    def rest_positions(self) -> np.ndarray:
        """(J, 3) joint positions in the rest pose with the root at the origin."""
        pos = np.zeros((self.num_joints, 3))
        for j, p in enumerate(self.parents):
            if p >= 0:
                pos[j] = pos[p] + self.offsets[j]
        return pos

    def root_height(self) -> float:
        """Height of the root above the lowest joint in the rest pose, metres."""
        return float(-self.rest_positions()[:, 1].min())

    def with_offsets(self, offsets: np.ndarray) -> Skeleton:
        return Skeleton(self.name, self.joints, self.parents, offsets, self.height, self.build)


def _mirror_offsets(table: dict[str, tuple[float, float, float]], joints: tuple[str, ...]) -> np.ndarray:
    out = np.zeros((len(joints), 3))
    for j, name in enumerate(joints):
        if name in table:
            out[j] = table[name]
        elif name.startswith("right_"):
            x, y, z = table["left_" + name[len("right_"):]]
            out[j] = (-x, y, z)
        else:
            raise KeyError(name)
    return out


def _apply_build(offsets: np.ndarray, joints: tuple[str, ...], height: float, build: str) -> np.ndarray:
    if build not in BUILDS:
        raise ValueError(f"build must be one of {sorted(BUILDS)}, got {build!r}")
    if not 1.0 <= height <= 2.3:
        raise ValueError(f"height must be between 1.0 and 2.3 metres, got {height}")
    factors = BUILDS[build]
    out = offsets * (height / REFERENCE_HEIGHT_M)
    for j, name in enumerate(joints):
        if name.endswith("_hip"):
            out[j, 0] *= factors["hip_width"]
        elif name.endswith(("_shoulder", "_collar")):
            out[j, 0] *= factors["shoulder_width"]
    if build == "female":
        # Slightly shorter limbs relative to the trunk at the same height.
        out *= 0.98
    return out


def gait_skeleton(height: float = REFERENCE_HEIGHT_M, build: str = "male") -> Skeleton:
    """The 21-joint gait skeleton of seed 000 scaled to ``height`` metres."""
    base = _mirror_offsets(_GAIT_OFFSETS, GAIT_JOINTS)
    return Skeleton("gait", GAIT_JOINTS, GAIT_PARENTS, _apply_build(base, GAIT_JOINTS, height, build), height, build)


def gesture_skeleton(height: float = REFERENCE_HEIGHT_M, build: str = "male") -> Skeleton:
    """The 23-joint gesture skeleton of seed 003 scaled to ``height`` metres."""
    base = _mirror_offsets(_GESTURE_OFFSETS, GESTURE_JOINTS)
    return Skeleton("gesture", GESTURE_JOINTS, GESTURE_PARENTS,
                    _apply_build(base, GESTURE_JOINTS, height, build), height, build)
