"""One motion-capture file -> a Motion on our gait or gesture skeleton, and its report row.

Every input becomes global joint positions first: a BVH through its own forward kinematics
(:func:`generation.formats.bvh.parse_bvh`, any hierarchy and channel order), a CSV/NPY position file as it is.
Units are ``--scale`` or guessed from the posed body's height along the up axis (median over the frames) by the
one unit rule, :func:`generation.formats.units.guess_unit`: 0.5..3 -> metres, 50..300 -> centimetres,
500..3000 -> millimetres, else normalised to a 1.7 m body. Then:
1. joints are mapped onto ours by name (:mod:`generation.mocap.rigs`; ``--joint-map`` entries first); a rig
   without the joints we need is an error that lists what the file has;
2. the up axis is the world axis closest to feet -> head (``up="auto"``) and is turned onto +y by a proper
   rotation (z-up files from 3ds Max, say); facing needs no correction: the IK orients the root freely;
3. :func:`generation.mocap.retarget.solve_onto` (the one retargeting path): positions are scaled by our leg
   length / the source's (thigh + shin, median over frames), so strides and root heights fit our legs, placed on
   our joints, unmapped joints interpolated between mapped neighbours, and solved with the analytic IK of
   :mod:`generation.core.ik` plus two-bone IK of the legs so the feet land where the source's do;
4. the error reported is the largest distance between our FK and the scaled source positions of mapped joints:
   zero for a source with our proportions, otherwise how much the bone-length differences show.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generation.core.motion import Motion, MotionFormatError
from generation.core.skeleton import REFERENCE_HEIGHT_M, Skeleton, gait_skeleton, gesture_skeleton
from generation.formats.bvh import parse_bvh
from generation.formats.units import guess_unit

from .labels import Label
from .positions import LAYOUT_MAPS, read_positions
from .retarget import leg_length, solve_onto
from .rigs import auto_joint_map, check_joint_map

BVH_SUFFIXES = (".bvh",)
POSITION_SUFFIXES = (".csv", ".npy")
SUFFIXES = BVH_SUFFIXES + POSITION_SUFFIXES

REPORT_COLUMNS = ("source", "status", "message", "frames", "fps", "duration_s", "mapped_joints", "unmapped_joints",
                  "retarget_max_error_m", "height_m", "import_error_cm")

#: Hip-joint height / standing height (greater trochanter level, Drillis & Contini 1966 segment proportions).
HIP_HEIGHT_FRACTION = 0.530


class ImportCheckError(ValueError):
    """A file that was read but failed the import checks; ``values`` are the report cells measured."""

    def __init__(self, message: str, values: dict):
        super().__init__(message)
        self.values = values


def standing_height_m(P: np.ndarray, names, joint_map: dict[str, str]) -> float:
    """Estimated standing height (head top to sole), metres, of a body given as (T, K, 3) positions, y-up.

    Rigs place their head joint anywhere from the neck to mid-head and few mark the head top, but hip joint
    centres are anatomical: the standing hip height is thigh + shin (:func:`leg_length`) + the ankle's lowest
    height (5th percentile) above the floor (the lowest point of the clip), divided by
    :data:`HIP_HEIGHT_FRACTION`. 0 when the legs are not mapped.
    """
    idx = {n: k for k, n in enumerate(names)}
    end = "heel" if "left_heel" in joint_map or "right_heel" in joint_map else "ankle"
    index = {ours: idx[theirs] for ours, theirs in joint_map.items()}
    leg = leg_length(P, index, end)
    ankles = [index[f"{s}_{end}"] for s in ("left", "right")
              if all(f"{s}_{j}" in index for j in ("hip", "knee", end))]
    if not ankles or leg <= 0:
        return 0.0
    ankle_height = np.mean([np.percentile(P[:, a, 1], 5) for a in ankles]) - float(P[..., 1].min())
    return (leg + float(ankle_height)) / HIP_HEIGHT_FRACTION


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
        proportions: "source" keeps the actor's bone lengths on our joints (the import check's solve);
            "ours" moves the motion onto our skeleton of ``height`` and ``build``.
        max_import_error_m: a file whose source-proportioned solve misses a mapped joint by more is an error.
        height_range_m: a file whose estimated standing height lies outside is an error.
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
    proportions: str = "ours"
    max_import_error_m: float = 0.03
    height_range_m: tuple[float, float] = (1.2, 2.3)

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


def load_source(path: Path, options: ImportOptions) -> tuple[np.ndarray, tuple[str, ...], float, dict]:
    """Global positions (T, K, 3) in file units (up axis not yet corrected), joint names, fps and info
    (``{"format": "bvh" | "csv" | "npy"}``)."""
    if path.suffix.lower() in BVH_SUFFIXES:
        data = parse_bvh(path)
        return data.global_positions(), data.names, data.fps, {"format": "bvh"}
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
    except (MotionFormatError, ValueError) as exc:  # RigMapError, LabelError, ImportCheckError are ValueErrors
        msg = str(exc)
        if isinstance(exc, ImportCheckError):
            row.update(exc.values)
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
    extent = float(np.median(P[..., 1].max(1) - P[..., 1].min(1)))   # the posed body's height over the frames
    unit, guess = (options.scale, "given") if options.scale is not None else guess_unit(extent)
    if not unit > 0:
        raise ValueError(f"--scale must be positive, got {unit}")
    P = P * unit
    height = standing_height_m(P, names, joint_map)
    info.update(unit_scale=unit, unit_guess=guess, height_m=height)
    solved, scale, import_err, err = solve_onto(P, names, target, joint_map, options.proportions)
    problems = []
    if import_err > options.max_import_error_m:
        problems.append(f"import error {100 * import_err:.1f} cm exceeds {100 * options.max_import_error_m:.1f} cm "
                        "(the solved body does not reproduce the file's joint positions: wrong channels, units or "
                        "joint map?)")
    low, high = options.height_range_m
    if not low <= height <= high:
        problems.append(f"standing height {height:.2f} m is outside {low}-{high} m (wrong units? give --scale)")
    if problems:
        raise ImportCheckError("; ".join(problems), {"retarget_max_error_m": f"{err:.6f}",
                                                     "import_error_cm": f"{100 * import_err:.2f}",
                                                     "height_m": f"{height:.4f}"})
    meta = {"origin": "captured", "synthetic": False, "source": path.name, "source_path": str(path),
            "format": info["format"], "unit_scale": info["unit_scale"], "unit_guess": info["unit_guess"],
            "up_axis": up, "source_height_m": info["height_m"],
            "proportions": options.proportions,
            "retarget": {"scale": scale, "joint_map": joint_map, "max_error_m": err, "import_error_m": import_err}}
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
                    "import_error_cm": f"{100 * import_err:.2f}",
                    "message": ""}
