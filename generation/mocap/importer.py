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
from generation.formats.bvh import parse_bvh

from .labels import Label
from .positions import LAYOUT_MAPS, read_positions
from .retarget import align_root_to_hips, fill_unmapped_joints, fit_proportions, place_feet_on_source
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
    centres are anatomical: the standing hip height is thigh + shin (:func:`_leg_length`) + the ankle's lowest
    height (5th percentile) above the floor (the lowest point of the clip), divided by
    :data:`HIP_HEIGHT_FRACTION`. 0 when the legs are not mapped.
    """
    idx = {n: k for k, n in enumerate(names)}
    end = "heel" if "left_heel" in joint_map or "right_heel" in joint_map else "ankle"
    index = {ours: idx[theirs] for ours, theirs in joint_map.items()}
    leg = _leg_length(P, index, end)
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


def _place_source(P_src: np.ndarray, names, target: Skeleton, joint_map: dict[str, str], scale: float):
    """Source positions (T, K, 3) times ``scale`` on the target's joints: (T, J, 3), known (J,), mapped indices."""
    idx = {n: k for k, n in enumerate(names)}
    T, J = len(P_src), target.num_joints
    P = np.zeros((T, J, 3))
    known = np.zeros(J, bool)
    for ours, theirs in joint_map.items():
        P[:, target.index(ours)] = P_src[:, idx[theirs]] * scale
        known[target.index(ours)] = True
    return P, known, np.flatnonzero(known)


def _solve(P: np.ndarray, known: np.ndarray, mapped: np.ndarray, target: Skeleton, joint_map: dict[str, str],
           fit: bool = False) -> tuple[Motion, float]:
    """IK of placed positions onto ``target`` (feet put on the source's): (Motion at fps 1, max mapped error m).
    With ``fit`` the target first takes the source's rest geometry (:func:`fit_proportions`)."""
    P = P.copy()
    known = known.copy()
    fill_unmapped_joints(P, known, target)
    if fit:
        target = fit_proportions(P, known, target)
    rotations = solve_rotations(P, target, known)
    P[:, 0] = align_root_to_hips(rotations, P, known, target)
    rotations = place_feet_on_source(rotations, P, known, target, joint_map)
    motion = Motion(target, rotations, P[:, 0].copy(), 1.0, {})
    err = np.linalg.norm(motion.positions()[:, mapped] - P[:, mapped], axis=-1)
    return motion, float(err.max())


def solve_onto(P_src: np.ndarray, names, target: Skeleton, joint_map: dict[str, str],
               proportions: str = "ours") -> tuple[Motion, float, float, float]:
    """Mapped source positions (T, K, 3), metres, y-up -> a Motion on our joints.

    The import check always solves onto our joints with the source's bone lengths
    (:func:`~generation.mocap.retarget.fit_proportions`): its largest error over mapped joints says whether the
    file was read and solved right (millimetres for a right reading; bone-length changes within a take and rest
    directions that differ from ours add a few). ``proportions="source"`` returns that motion (the actor's body);
    ``"ours"`` moves it onto ``target``'s own lengths: positions scaled by our leg length / the source's, feet put
    where the scaled source's are.

    Returns:
        (Motion at fps 1, scale applied to the source positions, import error m, retarget error m): the import
        error of the source-proportioned solve, and the largest mapped-joint distance of the returned motion.
    """
    idx = {n: k for k, n in enumerate(names)}
    P, known, mapped = _place_source(P_src, names, target, joint_map, 1.0)
    motion, import_err = _solve(P, known, mapped, target, joint_map, fit=True)
    if proportions == "source":
        return motion, 1.0, import_err, import_err
    if proportions != "ours":
        raise ValueError(f"proportions must be 'source' or 'ours', got {proportions!r}")
    end = "heel" if "left_heel" in target.joints else "ankle"
    src_leg = _leg_length(P_src, {ours: idx[theirs] for ours, theirs in joint_map.items()}, end)
    tgt_leg = _leg_length(target.rest_positions(), {n: j for j, n in enumerate(target.joints)}, end)
    scale = tgt_leg / src_leg if src_leg > 1e-6 else 1.0
    P, known, mapped = _place_source(P_src, names, target, joint_map, scale)
    motion, err = _solve(P, known, mapped, target, joint_map)
    return motion, scale, import_err, err


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
    unit, guess = (options.scale, "given") if options.scale is not None else _guess_unit(extent)
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
                    "import_error_cm": f"{100 * import_err:.2f}",
                    "message": ""}
