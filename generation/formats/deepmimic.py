"""DeepMimic humanoid motion files (JSON "Loop"/"Frames", 44 numbers a frame) read into a Motion.

Frame layout (REFERENCE.md section 7; DeepMimic's humanoid3d): frame duration (s), root position (3, metres,
y-up), root rotation (w, x, y, z), chest q, neck q, right hip q, right knee angle, right ankle q, right shoulder
q, right elbow angle, left hip q, left knee angle, left ankle q, left shoulder q, left elbow angle. Knees and
elbows are 1-DoF revolute joints about the local z axis (radians).

The skeleton's offsets are the joint origins of ``humanoid.urdf`` (shipped next to the clips) scaled by 0.25,
the scale DeepMimic uses for its humanoid. Three end points that carry no rotation are added from the URDF's
collision shapes so that the feet and head have a direction: ``head`` (centre of the head sphere),
``left_toe``/``right_toe`` (front bottom edge of the foot box); the wrists are the URDF's fixed wrist joints.

DeepMimic's humanoid faces +x with its right side at +z. Everything is turned -90 degrees about y on reading so
the result follows the project's convention (facing +z, left = +x); rotations are conjugated accordingly, so
forward kinematics of the result equals the turned DeepMimic pose exactly.
"""
from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from functools import lru_cache
from pathlib import Path

import numpy as np

from generation.core.motion import Motion, MotionFormatError
from generation.core.quaternion import np_qfix, np_qmul, np_qnormalize
from generation.core.skeleton import Skeleton

DATA_DIR = Path(__file__).resolve().parent.parent / "data" / "deepmimic"
URDF_PATH = DATA_DIR / "humanoid.urdf"
URDF_SCALE = 0.25
FRAME_LENGTH = 44

#: Joints of the DeepMimic humanoid as read here (parents precede children).
DEEPMIMIC_JOINTS = (
    "root", "chest", "neck", "head",
    "right_hip", "right_knee", "right_ankle", "right_toe",
    "right_shoulder", "right_elbow", "right_wrist",
    "left_hip", "left_knee", "left_ankle", "left_toe",
    "left_shoulder", "left_elbow", "left_wrist",
)
DEEPMIMIC_PARENTS = (-1, 0, 1, 2, 0, 4, 5, 6, 1, 8, 9, 0, 11, 12, 13, 1, 15, 16)

#: (field name, joint, kind) in frame order after the duration; kind "pos", "quat" or "angle".
FRAME_FIELDS = (
    ("root_position", "root", "pos"), ("root_rotation", "root", "quat"), ("chest_rotation", "chest", "quat"),
    ("neck_rotation", "neck", "quat"), ("right_hip_rotation", "right_hip", "quat"),
    ("right_knee_angle", "right_knee", "angle"), ("right_ankle_rotation", "right_ankle", "quat"),
    ("right_shoulder_rotation", "right_shoulder", "quat"), ("right_elbow_angle", "right_elbow", "angle"),
    ("left_hip_rotation", "left_hip", "quat"), ("left_knee_angle", "left_knee", "angle"),
    ("left_ankle_rotation", "left_ankle", "quat"), ("left_shoulder_rotation", "left_shoulder", "quat"),
    ("left_elbow_angle", "left_elbow", "angle"),
)
_SIZES = {"pos": 3, "quat": 4, "angle": 1}

# DeepMimic (facing +x, right = +z) -> project (facing +z, left = +x): rotation by -90 degrees about +y,
# (x, y, z) -> (-z, y, x).
_TURN = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
_TURN_Q = np.array([np.cos(-np.pi / 4), 0.0, np.sin(-np.pi / 4), 0.0])
_TURN_Q_CONJ = _TURN_Q * np.array([1.0, -1.0, -1.0, -1.0])


def _vec(text: str | None, where: str) -> np.ndarray:
    try:
        v = np.array([float(x) for x in (text or "").split()])
    except ValueError:
        raise MotionFormatError(f"{URDF_PATH}: bad xyz {text!r} in {where}") from None
    if v.shape != (3,):
        raise MotionFormatError(f"{URDF_PATH}: xyz in {where} must have 3 numbers, got {text!r}")
    return v


@lru_cache(maxsize=2)
def deepmimic_skeleton(urdf_path: str | None = None) -> Skeleton:
    """The DeepMimic humanoid (18 joints, metres, project axes) built from ``humanoid.urdf`` x 0.25."""
    path = Path(urdf_path) if urdf_path else URDF_PATH
    try:
        text = path.read_bytes().replace(b"\0", b"").decode("utf-8")
        root = ET.fromstring(text)
    except (OSError, ET.ParseError, UnicodeDecodeError) as exc:
        raise MotionFormatError(f"{path}: cannot read the humanoid URDF ({exc})") from None
    joint_origin = {}
    for j in root.iter("joint"):
        origin = j.find("origin")
        xyz = origin.get("xyz") if origin is not None else "0 0 0"
        joint_origin[j.get("name")] = _vec(xyz, f"joint {j.get('name')}")
    link_shape = {}
    for link in root.iter("link"):
        col = link.find("collision")
        if col is None:
            continue
        origin = _vec(col.find("origin").get("xyz"), f"link {link.get('name')} collision")
        geom = col.find("geometry")
        box = geom.find("box") if geom is not None else None
        size = _vec(box.get("size"), f"link {link.get('name')} box") if box is not None else None
        link_shape[link.get("name")] = (origin, size)
    offsets = np.zeros((len(DEEPMIMIC_JOINTS), 3))
    for j, name in enumerate(DEEPMIMIC_JOINTS):
        if name == "root":
            continue
        if name == "head":
            offsets[j] = link_shape["neck"][0]              # centre of the head sphere
        elif name.endswith("_toe"):
            centre, size = link_shape[name.replace("_toe", "_ankle")]
            if size is None:
                raise MotionFormatError(f"{path}: the ankle link of {name} has no box collision shape")
            offsets[j] = centre + np.array([size[0] / 2, -size[1] / 2, 0.0])   # front bottom edge of the foot
        else:
            if name not in joint_origin:
                raise MotionFormatError(f"{path}: missing joint {name!r}")
            offsets[j] = joint_origin[name]
    offsets = offsets * URDF_SCALE @ _TURN.T
    sk = Skeleton("deepmimic_humanoid", DEEPMIMIC_JOINTS, DEEPMIMIC_PARENTS, offsets)
    rest = sk.rest_positions()
    return Skeleton(sk.name, sk.joints, sk.parents, offsets, height=float(rest[:, 1].max() - rest[:, 1].min()))


def _turn_quat(q: np.ndarray) -> np.ndarray:
    """Conjugate rotations by the axis turn: q' = c q c^-1."""
    c = np.broadcast_to(_TURN_Q, q.shape).copy()
    return np_qmul(np_qmul(c, q), np.broadcast_to(_TURN_Q_CONJ, q.shape).copy())


def read_deepmimic(path: str | Path, skeleton: Skeleton | None = None) -> Motion:
    """Read a DeepMimic humanoid motion file.

    Args:
        path: JSON file with ``Frames`` (list of 44-number lists) and optional ``Loop`` ("wrap", "none", "clamp").
        skeleton: the humanoid skeleton; default :func:`deepmimic_skeleton`.

    Returns:
        Motion (T frames at 1 / median frame duration fps) on the DeepMimic skeleton in project axes;
        metadata ``{"source": file name, "format": "deepmimic", "loop": ...}``.

    Raises:
        MotionFormatError: naming the file, and the frame index and field for bad frames.
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise MotionFormatError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except json.JSONDecodeError as exc:
        raise MotionFormatError(f"{path}: not valid JSON (line {exc.lineno}: {exc.msg})") from None
    if not isinstance(data, dict):
        raise MotionFormatError(f"{path}: expected a JSON object with 'Frames', got {type(data).__name__}")
    unknown = set(data) - {"Loop", "Frames"}
    if unknown:
        raise MotionFormatError(f"{path}: unknown keys {sorted(unknown)}; expected 'Loop' and 'Frames'")
    if "Frames" not in data:
        raise MotionFormatError(f"{path}: missing key 'Frames'")
    loop = data.get("Loop", "none")
    if loop not in ("wrap", "none", "clamp"):
        raise MotionFormatError(f"{path}: 'Loop' must be 'wrap', 'none' or 'clamp', got {loop!r}")
    frames = data["Frames"]
    if not isinstance(frames, list) or not frames:
        raise MotionFormatError(f"{path}: 'Frames' must be a non-empty list")
    for i, fr in enumerate(frames):
        if not isinstance(fr, list) or len(fr) != FRAME_LENGTH:
            n = len(fr) if isinstance(fr, list) else type(fr).__name__
            raise MotionFormatError(f"{path}: frame {i} has {n} values, expected {FRAME_LENGTH}")
        for k, v in enumerate(fr):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
                raise MotionFormatError(f"{path}: frame {i}, {_field_at(k)}: not a finite number ({v!r})")
    arr = np.array(frames, dtype=np.float64)
    durations = arr[:, 0]
    if (durations < 0).any():
        i = int(np.argmax(durations < 0))
        raise MotionFormatError(f"{path}: frame {i}, frame_duration: negative ({durations[i]})")
    positive = durations[durations > 0]
    if positive.size == 0:
        raise MotionFormatError(f"{path}: every frame_duration is 0")
    fps = 1.0 / float(np.median(positive))

    sk = skeleton or deepmimic_skeleton()
    T = arr.shape[0]
    rotations = np.zeros((T, sk.num_joints, 4))
    rotations[..., 0] = 1.0
    col = 1
    root_pos = None
    for name, joint, kind in FRAME_FIELDS:
        block = arr[:, col:col + _SIZES[kind]]
        if kind == "pos":
            root_pos = block @ _TURN.T
        elif kind == "quat":
            norms = np.linalg.norm(block, axis=1)
            if (np.abs(norms - 1.0) > 0.05).any():
                i = int(np.argmax(np.abs(norms - 1.0) > 0.05))
                raise MotionFormatError(f"{path}: frame {i}, {name}: quaternion norm {norms[i]:.4f} is not 1")
            rotations[:, sk.index(joint)] = np_qnormalize(block)
        else:  # revolute about local z
            half = 0.5 * block[:, 0]
            rotations[:, sk.index(joint)] = np.stack([np.cos(half), 0 * half, 0 * half, np.sin(half)], -1)
        col += _SIZES[kind]
    rotations = _turn_quat(rotations)
    return Motion(sk, np_qfix(rotations), root_pos, fps,
                  {"source": path.name, "format": "deepmimic", "loop": loop})


def _field_at(k: int) -> str:
    if k == 0:
        return "frame_duration"
    col = 1
    for name, _, kind in FRAME_FIELDS:
        if col <= k < col + _SIZES[kind]:
            return f"{name}[{k - col}]" if _SIZES[kind] > 1 else name
        col += _SIZES[kind]
    return f"value {k}"
