"""One motion-capture file -> a Motion on our gait or gesture skeleton, and its report row.

Every input becomes global joint positions first: a BVH through its own forward kinematics (``read_bvh``, any
hierarchy and channel order), a CSV/NPY position file as it is. Units are ``--scale`` or guessed from the body
height along the up axis (BVH: the rest pose; positions: the median over the frames): 0.5..3 -> metres,
50..300 -> centimetres, 500..3000 -> millimetres, else normalised to a 1.7 m body. Then:
1. joints are mapped onto ours by name (:mod:`generation.mocap.rigs`; ``--joint-map`` entries first); a rig
   without the joints we need is an error that lists what the file has;
2. the up axis is the world axis closest to feet -> head (``up="auto"``) and is turned onto +y by a proper
   rotation (z-up files from 3ds Max, say); facing needs no correction: the IK orients the root freely;
3. positions are scaled by our leg length / the source's (thigh + shin, median over frames), so strides and root
   heights fit our legs, placed on our joints, unmapped joints interpolated between mapped neighbours, and solved
   with the analytic IK of :mod:`generation.core.ik` plus two-bone IK of the legs so the feet land where the
   source's do (as :func:`generation.formats.bvh.retarget`);
4. the error reported is the largest distance between our FK and the scaled source positions of mapped joints:
   zero for a source with our proportions, otherwise how much the bone-length differences show.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generation.core.ik import solve_rotations
from generation.core.motion import Motion, MotionFormatError
from generation.core.skeleton import REFERENCE_HEIGHT_M, Skeleton, gait_skeleton, gesture_skeleton
from generation.formats.bvh import fill_unmapped_joints, place_feet_on_source, read_bvh

from .labels import Label
from .positions import LAYOUT_MAPS, read_positions
from .rigs import auto_joint_map, check_joint_map

BVH_SUFFIXES = (".bvh",)
POSITION_SUFFIXES = (".csv", ".npy")
SUFFIXES = BVH_SUFFIXES + POSITION_SUFFIXES

REPORT_COLUMNS = ("source", "status", "message", "frames", "fps", "duration_s", "mapped_joints", "unmapped_joints",
                  "retarget_max_error_m", "height_m")

# proper rotations taking each world axis (with sign) onto +y
_UP_TO_Y = {
    "+y": np.eye(3),
    "-y": np.diag([1.0, -1.0, -1.0]),
    "+z": np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]]),
    "-z": np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]]),
    "+x": np.array([[0, -1.0, 0], [1.0, 0, 0], [0, 0, 1.0]]),
    "-x": np.array([[0, 1.0, 0], [-1.0, 0, 0], [0, 0, 1.0]]),
}


@dataclass
class ImportOptions:
    """How to import.

    Attributes:
        skeleton: "gait" (21 joints) or "gesture" (23 joints).
        height: our skeleton's height, metres; build: "male" or "female".
        scale: metres per file unit; None guesses from the body height.
        fps: resample the result to this frame rate; None keeps the source's.
        input_fps: frame rate of position files (they store none).
        layout: joint names of position files without a header (named layout or comma-separated).
        joint_map: {our joint: their joint}, applied before the automatic map.
        up: "auto" or one of "+y", "-y", "+z", "-z", "+x", "-x" (the source's up axis).
    """

    skeleton: str = "gait"
    height: float = REFERENCE_HEIGHT_M
    build: str = "male"
    scale: float | None = None
    fps: float | None = None
    input_fps: float = 30.0
    layout: str | None = None
    joint_map: dict[str, str] = field(default_factory=dict)
    up: str = "auto"

    def target(self) -> Skeleton:
        if self.skeleton == "gait":
            return gait_skeleton(self.height, self.build)
        if self.skeleton == "gesture":
            return gesture_skeleton(self.height, self.build)
        raise ValueError(f"skeleton must be 'gait' or 'gesture', got {self.skeleton!r}")


@dataclass
class ImportResult:
    """The Motion (None when the import failed) and the report row (:data:`REPORT_COLUMNS`)."""

    motion: Motion | None
    row: dict
    seconds: float = 0.0


def _guess_unit(height: float) -> tuple[float, str]:
    if 0.5 <= height <= 3.0:
        return 1.0, "metres"
    if 50.0 <= height <= 300.0:
        return 0.01, "centimetres"
    if 500.0 <= height <= 3000.0:
        return 0.001, "millimetres"
    if height <= 0:
        raise MotionFormatError("the body has no vertical extent; cannot guess units (give --scale)")
    return 1.7 / height, "unknown unit, normalised to a 1.7 m body"


def load_source(path: Path, options: ImportOptions) -> tuple[np.ndarray, tuple[str, ...], float, dict]:
    """Global positions (T, K, 3) in file units (up axis not yet corrected), joint names, fps, info (format; for
    BVH the rest-pose positions (K, 3), whose height along the up axis gives the units)."""
    if path.suffix.lower() in BVH_SUFFIXES:
        m = read_bvh(path, scale=1.0)
        info = {"format": "bvh", "rest": m.skeleton.rest_positions()}
        if "ignored_channels" in m.metadata:
            info["ignored_channels"] = m.metadata["ignored_channels"]
        return m.positions(), m.skeleton.joints, m.fps, info
    P, names = read_positions(path, options.layout)
    return P, names, options.input_fps, {"format": path.suffix.lower().lstrip(".")}


def _up_axis(P: np.ndarray, names, jm: dict[str, str]) -> str:
    """The signed world axis closest to the mean feet -> head direction."""
    idx = {n: k for k, n in enumerate(names)}
    top = next(jm[j] for j in ("head", "neck", "spine", "chest4", "root") if j in jm)
    feet = [jm[j] for j in ("left_heel", "right_heel", "left_ankle", "right_ankle", "left_knee", "right_knee")
            if j in jm]
    d = (P[:, idx[top]] - P[:, [idx[f] for f in feet]].mean(1)).mean(0)
    k = int(np.argmax(np.abs(d)))
    return ("+" if d[k] >= 0 else "-") + "xyz"[k]


def _leg_length(P: np.ndarray, index: dict[str, int], end: str) -> float:
    """Median over frames of thigh + shin length, mean of the sides present (P (T, J, 3) or (J, 3))."""
    P = P.reshape(-1, P.shape[-2], 3)
    sides = []
    for s in ("left", "right"):
        hip, knee, foot = (index.get(f"{s}_hip"), index.get(f"{s}_knee"), index.get(f"{s}_{end}"))
        if None in (hip, knee, foot):
            continue
        sides.append(np.median(np.linalg.norm(P[:, hip] - P[:, knee], axis=-1)
                               + np.linalg.norm(P[:, knee] - P[:, foot], axis=-1)))
    return float(np.mean(sides)) if sides else 0.0


def solve_onto(P_src: np.ndarray, names, target: Skeleton, joint_map: dict[str, str]) -> tuple[Motion, float, float]:
    """Mapped source positions (T, K, 3), metres, y-up -> (Motion at fps 1, scale applied, max error m)."""
    idx = {n: k for k, n in enumerate(names)}
    end = "heel" if "left_heel" in target.joints else "ankle"
    src_leg = _leg_length(P_src, {ours: idx[theirs] for ours, theirs in joint_map.items()}, end)
    tgt_leg = _leg_length(target.rest_positions(), {n: j for j, n in enumerate(target.joints)}, end)
    scale = tgt_leg / src_leg if src_leg > 1e-6 else 1.0
    T, J = len(P_src), target.num_joints
    P = np.zeros((T, J, 3))
    known = np.zeros(J, bool)
    for ours, theirs in joint_map.items():
        P[:, target.index(ours)] = P_src[:, idx[theirs]] * scale
        known[target.index(ours)] = True
    mapped = np.flatnonzero(known)
    fill_unmapped_joints(P, known, target)
    rotations = place_feet_on_source(solve_rotations(P, target, known), P, known, target, joint_map)
    motion = Motion(target, rotations, P[:, 0].copy(), 1.0, {})
    err = np.linalg.norm(motion.positions()[:, mapped] - P[:, mapped], axis=-1)
    return motion, scale, float(err.max())


def import_file(path: str | Path, options: ImportOptions, label: Label | None = None,
                given_as: str | None = None) -> ImportResult:
    """Import one file; failures become a row with status "error" and the message (never raise for bad input)."""
    path = Path(path)
    source = given_as or str(path)
    row = {c: "" for c in REPORT_COLUMNS}
    row.update(source=source, status="error")
    t0 = time.perf_counter()
    try:
        motion, row_extra = _import(path, options, label)
    except (MotionFormatError, ValueError) as exc:  # RigMapError, LabelError are ValueErrors
        msg = str(exc)
        row["message"] = msg if str(path) in msg else f"{path}: {msg}"
        return ImportResult(None, row, time.perf_counter() - t0)
    row.update(row_extra, status="ok")
    return ImportResult(motion, row, time.perf_counter() - t0)


def _import(path: Path, options: ImportOptions, label: Label | None) -> tuple[Motion, dict]:
    target = options.target()
    P, names, fps, info = load_source(path, options)
    layout_map = LAYOUT_MAPS.get(options.layout or "", {}).get(target.name, {})
    overrides = {**layout_map, **options.joint_map}
    joint_map = auto_joint_map(names, target, overrides)
    check_joint_map(joint_map, names, target, str(path))
    up = _up_axis(P, names, joint_map) if options.up == "auto" else options.up
    if up not in _UP_TO_Y:
        raise ValueError(f"up must be 'auto' or one of {', '.join(_UP_TO_Y)}, got {up!r}")
    P = P @ _UP_TO_Y[up].T
    if "rest" in info:    # BVH: the rest pose's height along the up axis (as read_bvh guesses, axis-aware)
        rest_y = info.pop("rest") @ _UP_TO_Y[up][1]
        extent = float(rest_y.max() - rest_y.min())
    else:                 # positions: the median height over the frames
        extent = float(np.median(P[..., 1].max(1) - P[..., 1].min(1)))
    unit, guess = (options.scale, "given") if options.scale is not None else _guess_unit(extent)
    if not unit > 0:
        raise ValueError(f"--scale must be positive, got {unit}")
    P = P * unit
    info.update(unit_scale=unit, unit_guess=guess, height_m=extent * unit)
    solved, scale, err = solve_onto(P, names, target, joint_map)
    meta = {"origin": "captured", "synthetic": False, "source": path.name, "source_path": str(path),
            "format": info["format"], "unit_scale": info["unit_scale"], "unit_guess": info["unit_guess"],
            "up_axis": up, "source_height_m": info["height_m"],
            "retarget": {"scale": scale, "joint_map": joint_map, "max_error_m": err}}
    if "ignored_channels" in info:
        meta["ignored_channels"] = info["ignored_channels"]
    if label is not None:
        meta.update(label.metadata(target.name))
    if options.fps is not None:
        meta["source_fps"] = fps
    motion = Motion(target, solved.rotations, solved.root_positions, fps, meta)
    if options.fps is not None:
        if not options.fps > 0:
            raise ValueError(f"--fps must be positive, got {options.fps}")
        motion = motion.resample(options.fps)
    unmapped = [j for j in target.joints if j not in joint_map]
    return motion, {"frames": motion.num_frames, "fps": f"{motion.fps:.6g}", "duration_s": f"{motion.duration:.4f}",
                    "mapped_joints": len(joint_map), "unmapped_joints": ";".join(unmapped),
                    "retarget_max_error_m": f"{err:.6f}", "height_m": f"{info['height_m']:.4f}",
                    "message": ""}
