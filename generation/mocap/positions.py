"""Joint-position files (no rotations): CSV or NPY of T x 3J positions with a joint-name list.

CSV: one row per frame. A header row names the columns ``<joint>_x, <joint>_y, <joint>_z`` (also ``<joint>.x``,
``<joint>:X``, ``<joint> X``, ``<joint>X``; the three axes of a joint in any order); columns named ``frame``,
``time`` or ``timestamp`` are skipped. Without a header (the first row is numbers), ``layout`` gives the joints.
NPY: (T, 3J) or (T, J, 3) float array; ``layout`` gives the joints.

``layout`` is a named layout (:data:`LAYOUTS`) or a comma-separated list of joint names in column order. The
named layouts:
- ``emotion-gait-16``: the 16 joints of the Emotion-Gait data (root, spine, neck, head, left shoulder, elbow,
  hand, right shoulder, elbow, hand, left hip, knee, foot, right hip, knee, foot);
- ``kinect-v2``: the 25 Kinect v2 body joints in the SDK's JointType order.
Some layouts carry a map onto our joints where names alone would mislead (:data:`LAYOUT_MAPS`: Emotion-Gait's
``spine`` is the chest the arms branch from).

Units and axes are not stored in these files; the importer guesses them from the body (see ``importer``).
"""
from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from generation.core.motion import MotionFormatError

LAYOUTS: dict[str, tuple[str, ...]] = {
    "emotion-gait-16": (
        "root", "spine", "neck", "head",
        "left_shoulder", "left_elbow", "left_hand", "right_shoulder", "right_elbow", "right_hand",
        "left_hip", "left_knee", "left_foot", "right_hip", "right_knee", "right_foot",
    ),
    "kinect-v2": (
        "SpineBase", "SpineMid", "Neck", "Head", "ShoulderLeft", "ElbowLeft", "WristLeft", "HandLeft",
        "ShoulderRight", "ElbowRight", "WristRight", "HandRight", "HipLeft", "KneeLeft", "AnkleLeft", "FootLeft",
        "HipRight", "KneeRight", "AnkleRight", "FootRight", "SpineShoulder", "HandTipLeft", "ThumbLeft",
        "HandTipRight", "ThumbRight",
    ),
}

#: layout -> skeleton name -> {our joint: layout joint}, applied before the automatic name map
LAYOUT_MAPS: dict[str, dict[str, dict[str, str]]] = {
    "emotion-gait-16": {"gait": {"spine": "spine"}, "gesture": {"chest4": "spine"}},
}

_SKIP = {"frame", "time", "timestamp", "t"}
_AXIS = re.compile(r"^(.*?)[\s_.:\-]*([xyzXYZ])$")


def layout_names(layout: str) -> tuple[str, ...]:
    """Joint names of a named layout or a comma-separated list."""
    if layout in LAYOUTS:
        return LAYOUTS[layout]
    names = tuple(n.strip() for n in layout.split(",") if n.strip())
    if len(names) < 2:
        raise MotionFormatError(f"--layout {layout!r} is neither a named layout ({', '.join(LAYOUTS)}) nor a "
                                f"comma-separated list of joint names")
    return names


def read_positions(path: str | Path, layout: str | None = None) -> tuple[np.ndarray, tuple[str, ...]]:
    """Positions (T, J, 3) in file units and the J joint names, from a .csv or .npy file.

    Raises:
        MotionFormatError: naming the file (and line for CSV) of the first problem.
    """
    path = Path(path)
    if path.suffix.lower() == ".npy":
        return _read_npy(path, layout)
    return _read_csv(path, layout)


def _read_npy(path: Path, layout: str | None):
    if layout is None:
        raise MotionFormatError(f"{path}: a .npy position file holds no joint names; give --layout "
                                f"({', '.join(LAYOUTS)} or a comma-separated list)")
    names = layout_names(layout)
    try:
        arr = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise MotionFormatError(f"{path}: not a readable .npy array ({exc})") from None
    J = len(names)
    if arr.ndim == 2 and arr.shape[1] == 3 * J:
        arr = arr.reshape(len(arr), J, 3)
    if arr.ndim != 3 or arr.shape[1:] != (J, 3) or not np.issubdtype(arr.dtype, np.number):
        raise MotionFormatError(f"{path}: expected a (T, {3 * J}) or (T, {J}, 3) numeric array for the {J} joints "
                                f"of the layout, got {arr.shape} {arr.dtype}")
    arr = arr.astype(np.float64)
    if len(arr) == 0:
        raise MotionFormatError(f"{path}: the array has no frames")
    bad = np.argwhere(~np.isfinite(arr))
    if len(bad):
        t, j, _ = bad[0]
        raise MotionFormatError(f"{path}: frame {t}, joint {names[j]!r}: value is not finite")
    return arr, names


def _parse_header(row: list[str], path: Path) -> tuple[tuple[str, ...], list[tuple[int, int, int]]]:
    """Joint names and, per joint, the column indices of x, y, z."""
    joints: dict[str, dict[str, int]] = {}
    for col, cell in enumerate(row):
        cell = cell.strip()
        if cell.lower() in _SKIP:
            continue
        m = _AXIS.match(cell)
        if not m or not m.group(1):
            raise MotionFormatError(f"{path}: line 1: column {col + 1} {cell!r} is not '<joint>_x|_y|_z' "
                                    f"(or frame/time)")
        axes = joints.setdefault(m.group(1), {})
        axis = m.group(2).lower()
        if axis in axes:
            raise MotionFormatError(f"{path}: line 1: column {cell!r} repeats axis {axis} of joint {m.group(1)!r}")
        axes[axis] = col
    incomplete = [j for j, a in joints.items() if len(a) != 3]
    if incomplete:
        raise MotionFormatError(f"{path}: line 1: joints without all of x, y, z columns: {', '.join(incomplete)}")
    return tuple(joints), [(a["x"], a["y"], a["z"]) for a in joints.values()]


def _read_csv(path: Path, layout: str | None):
    try:
        text = path.read_text(encoding="utf-8-sig", errors="replace")
    except OSError as exc:
        raise MotionFormatError(f"{path}: cannot read ({exc.strerror or exc})") from None
    rows = [(ln, r) for ln, r in enumerate(csv.reader(text.splitlines()), 1) if r and any(c.strip() for c in r)]
    if not rows:
        raise MotionFormatError(f"{path}: the file is empty")
    first_ln, first = rows[0]
    has_header = not all(_is_number(c) for c in first)
    if has_header:
        names, cols = _parse_header(first, path)
        rows = rows[1:]
    else:
        if layout is None:
            raise MotionFormatError(f"{path}: line {first_ln}: no header row naming the joints; add one "
                                    f"('<joint>_x,<joint>_y,<joint>_z,...') or give --layout")
        names = layout_names(layout)
        cols = [(3 * j, 3 * j + 1, 3 * j + 2) for j in range(len(names))]
    n_cols = (len(first) if has_header else 3 * len(names))
    if not rows:
        raise MotionFormatError(f"{path}: no frame rows after the header")
    out = np.empty((len(rows), len(names), 3))
    flat = np.array(cols).reshape(-1)
    for t, (ln, row) in enumerate(rows):
        if len(row) != n_cols:
            raise MotionFormatError(f"{path}: line {ln}: {len(row)} values, expected {n_cols}")
        try:
            vals = np.array([float(row[c]) for c in flat])
        except ValueError:
            bad = next(c for c in flat if not _is_number(row[c]))
            raise MotionFormatError(f"{path}: line {ln}: column {bad + 1}: expected a number, got {row[bad]!r}") \
                from None
        if not np.isfinite(vals).all():
            raise MotionFormatError(f"{path}: line {ln}: value is not finite")
        out[t] = vals.reshape(-1, 3)
    return out, tuple(names)


def _is_number(s: str) -> bool:
    try:
        float(s)
        return True
    except ValueError:
        return False
