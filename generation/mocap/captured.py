"""Real captured walks: the DeepMimic walk clips retargeted onto the project's 21-joint gait skeleton.

Source: DeepMimic (Peng et al., SIGGRAPH 2018) humanoid reference motions as shipped in ``pybullet_data``
(MIT licence), originally from the CMU and SFU motion capture databases; see ``data/deepmimic/NOTICE.md``.
These are captured human motion (not synthetic) with no emotion labels: one neutral walk cycle and five walker
clips (straight, two left turns, two right turns), each about 1.3 s at 30 fps.

Retargeting: :func:`generation.mocap.retarget.retarget`, the importer's path. DeepMimic joints are mapped by name
onto the gait skeleton (:func:`generation.mocap.rigs.auto_joint_map`: ankle -> heel, chest -> spine, wrist ->
hand); the gait skeleton's ``lower_back`` lies on the root-chest line, the hand index tips follow the forearms.
Positions are scaled by our leg length / DeepMimic's (thigh + shin: 1.011 for a 1.75 m gait body), solved with IK,
the legs bent with two-bone IK so the heels land where the source's ankles do (keeps the captured foot contacts),
then shifted vertically so the lowest joint over the clip touches y = 0.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from generation.core.quaternion import np_qfrom_axis_angle, np_qmul, np_qrot
from generation.core.skeleton import REFERENCE_HEIGHT_M, Skeleton, gait_skeleton
from generation.formats.deepmimic import DATA_DIR, read_deepmimic

from .retarget import retarget

#: (file, description). All are walks; the turn clips walk along a curve.
WALK_FILES = (
    ("humanoid3d_walk.txt", "neutral walk cycle (DeepMimic humanoid3d_walk)"),
    ("0walk_forward.txt", "straight walk (DeepMimic walker 0walk_forward)"),
    ("turn_left0.txt", "walk turning left (DeepMimic walker turn_left0)"),
    ("turn_left1.txt", "walk turning left (DeepMimic walker turn_left1)"),
    ("turn_right0.txt", "walk turning right (DeepMimic walker turn_right0)"),
    ("turn_right1.txt", "walk turning right (DeepMimic walker turn_right1)"),
)

CREDIT = ("DeepMimic humanoid reference motions (Peng, Abbeel, Levine, van de Panne, SIGGRAPH 2018), from the "
          "CMU Graphics Lab and SFU motion capture databases, distributed with pybullet_data")

def ground(motion: Motion) -> tuple[Motion, float]:
    """Shift the root vertically so the lowest joint over the whole clip is at y = 0; returns (motion, shift m)."""
    shift = -float(motion.positions()[..., 1].min())
    root = motion.root_positions.copy()
    root[:, 1] += shift
    return Motion(motion.skeleton, motion.rotations.copy(), root, motion.fps, dict(motion.metadata)), shift


def load_captured_walk(file_name: str, skeleton: Skeleton | None = None) -> Motion:
    """One DeepMimic walk file (name in :data:`WALK_FILES`) retargeted onto ``skeleton`` (default gait 1.75 m)."""
    names = dict(WALK_FILES)
    if file_name not in names:
        raise ValueError(f"unknown captured walk {file_name!r}; expected one of {sorted(names)}")
    source = read_deepmimic(DATA_DIR / file_name)
    if source.metadata.get("loop") == "wrap" and _last_is_closure(DATA_DIR / file_name):
        source = source.slice(0, source.num_frames - 1)      # the last frame repeats the first (duration 0)
    target = skeleton or gait_skeleton(REFERENCE_HEIGHT_M, "male")
    motion = retarget(source, target)
    motion, shift = ground(motion)
    motion.metadata = {
        "origin": "captured",
        "source": f"pybullet_data/data/motions/{'walker/' if file_name[0] in '0t' else ''}{file_name}",
        "description": names[file_name],
        "credit": CREDIT,
        "license": "MIT",
        "synthetic": False,
        "emotion_labels": None,
        "loop": source.metadata.get("loop"),
        "retarget": {**motion.metadata["retarget"], "ground_shift_m": shift},
    }
    return motion


def _last_is_closure(path: Path) -> bool:
    import json
    frames = json.loads(path.read_text())["Frames"]
    return frames[-1][0] == 0


def captured_walks(skeleton: Skeleton | None = None) -> list[Motion]:
    """All DeepMimic walk clips on the gait skeleton (fresh Motion objects), in :data:`WALK_FILES` order.

    Metadata: ``{"origin": "captured", "source": ..., "credit": ..., "license": "MIT", "synthetic": False,
    "emotion_labels": None, ...}``.
    """
    return [load_captured_walk(name, skeleton) for name, _ in WALK_FILES]


def chain_clip_repeats(motion: Motion, cycles: int) -> Motion:
    """Repeat a walk clip ``cycles`` times, chaining root position and heading.

    Each repeat starts where the previous one ended: the displacement and yaw between the clip's first frame and
    one frame past its last (extrapolated from the last frame step) are applied cumulatively. Best for loopable
    clips (``metadata["loop"] == "wrap"``); for others the seams show.

    Returns a Motion of T * cycles frames; metadata gains ``repeated_cycles``.
    """
    if cycles < 1:
        raise ValueError(f"cycles must be >= 1, got {cycles}")
    T = motion.num_frames
    rot, root = motion.rotations, motion.root_positions
    # heading of the root (yaw about +y from +z) at the first frame and at one frame past the end
    fwd = np_qrot(rot[:, 0], np.broadcast_to([0.0, 0.0, 1.0], (T, 3)).copy())
    yaw = np.arctan2(fwd[:, 0], fwd[:, 2])
    yaw_end = yaw[-1] + (yaw[-1] - yaw[-2] if T > 1 else 0.0)
    end_root = root[-1] + (root[-1] - root[-2] if T > 1 else 0.0)
    d_yaw = yaw_end - yaw[0]
    q = np.broadcast_to(np_qfrom_axis_angle(np.array([0.0, 1.0, 0.0]), np.array(d_yaw)), (T, 4)).copy()
    start = np.array([root[0, 0], 0.0, root[0, 2]])
    end = np.array([end_root[0], 0.0, end_root[2]])

    def step(r: np.ndarray) -> np.ndarray:  # the rigid ground-plane move taking frame 0 to one past the end
        return end + np_qrot(q, r - start)

    out_rot, out_root = [rot], [root]
    for _ in range(cycles - 1):
        out_root.append(step(out_root[-1]))
        nxt = out_rot[-1].copy()
        nxt[:, 0] = np_qmul(q, nxt[:, 0])
        out_rot.append(nxt)
    meta = dict(motion.metadata)
    meta["repeated_cycles"] = cycles
    return Motion(motion.skeleton, np.concatenate(out_rot), np.concatenate(out_root), motion.fps, meta)
