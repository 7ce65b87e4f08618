"""BVH motion files: reading any hierarchy and channel layout, and writing our skeletons.

Reading (:func:`parse_bvh`, :func:`read_bvh`):
- any hierarchy and any per-joint channel order; rotations are intrinsic Euler angles in degrees applied in
  the listed order (``Zrotation Xrotation Yrotation`` means R = Rz Rx Ry acting on column vectors);
- position channels on ANY joint are that joint's local translation in that frame (rigs such as the Bandai
  Namco dataset's carry six channels on every joint and the root motion on ``Hips`` below a static
  ``joint_Root``); :func:`parse_bvh` keeps them per frame and :meth:`BvhData.global_positions` is exact;
- a joint name is the rest of its ``ROOT``/``JOINT`` line, so names with spaces (3ds Max Biped's
  ``Bip01 L Thigh``) are kept whole;
- ``End Site`` blocks with a non-zero offset become leaf joints named ``<parent>_end`` with identity rotation;
  zero-offset end sites are dropped;
- units: ``scale`` multiplies file units into metres. ``scale=None`` guesses from the posed body's extent
  (median over frames; a rest pose with bones along local x says nothing about height) by the one unit rule,
  :func:`generation.formats.units.guess_unit` (metres, centimetres, millimetres, else normalised to a 1.7 m
  body); the guess is recorded in ``metadata["bvh_scale"]`` and ``metadata["bvh_scale_guess"]``.
Malformed files raise :class:`~generation.core.motion.MotionFormatError` naming the file and line.

Writing (:func:`write_bvh`): root with 3 position + 3 rotation channels, other joints 3 rotation channels,
skeleton leaves written as ``End Site`` (BVH leaves carry no name or rotation, so leaf names come back as
``<parent>_end``; positions are kept exactly). Readable by Blender's and Unity's importers.

Retargeting onto our skeletons lives in :mod:`generation.mocap.retarget`.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generation.core.motion import Motion, MotionFormatError
from generation.core.quaternion import np_qfix, np_qmul, np_qto_matrix, qeuler, qfrom_euler
from generation.core.skeleton import Skeleton
from generation.formats.units import guess_unit

_CHANNELS = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")


MAX_BVH_BYTES = 32 * 1024 * 1024
"""Largest BVH file read (bytes), checked before the file is opened: parsing holds the text, its lines and the
(T, channels) values, a few times the file's size (docs/benchmarks/study.md, "BVH size limit")."""
FRAME_TIME_RANGE = (1e-3, 1.0)
"""Accepted ``Frame Time`` (seconds per frame): 1000 down to 1 frame per second."""
_FRAME_TIME_LINE = re.compile(r"^[ \t]*Frame[ \t]+Time:[^\n]*\n?", re.M)


class _Tokens:
    """Whitespace tokens with their 1-based line numbers; ``tokenized_lines`` (default all) limits the tokens to
    the first lines (the header: the frame lines are read row by row, not as tokens)."""

    def __init__(self, text: str, path: Path, tokenized_lines: int | None = None):
        self.path = path
        self.items: list[tuple[str, int]] = []
        self.lines = text.splitlines()
        for ln, line in enumerate(self.lines[:tokenized_lines], 1):
            for tok in line.split():
                self.items.append((tok, ln))
        self.pos = 0

    def error(self, msg: str, line: int | None = None) -> MotionFormatError:
        if line is None:
            line = self.items[self.pos][1] if self.pos < len(self.items) else len(self.lines)
        return MotionFormatError(f"{self.path}: line {line}: {msg}")

    def next(self, what: str) -> tuple[str, int]:
        if self.pos >= len(self.items):
            raise self.error(f"unexpected end of file, expected {what}")
        tok = self.items[self.pos]
        self.pos += 1
        return tok

    def expect(self, word: str) -> int:
        tok, ln = self.next(repr(word))
        if tok != word:
            raise self.error(f"expected {word!r}, got {tok!r}", ln)
        return ln

    def number(self, what: str) -> float:
        tok, ln = self.next(what)
        try:
            value = float(tok)
        except ValueError:
            raise self.error(f"expected a number for {what}, got {tok!r}", ln) from None
        if not np.isfinite(value):
            raise self.error(f"{what} is not finite ({tok!r})", ln)
        return value

    def integer(self, what: str) -> int:
        tok, ln = self.next(what)
        if not re.fullmatch(r"\d+", tok):
            raise self.error(f"expected a non-negative integer for {what}, got {tok!r}", ln)
        return int(tok)

    def peek(self) -> str | None:
        return self.items[self.pos][0] if self.pos < len(self.items) else None


def _parse_hierarchy(tk: _Tokens):
    names: list[str] = []
    parents: list[int] = []
    offsets: list[list[float]] = []
    channels: list[list[str]] = []
    end_site: list[bool] = []

    def joint(parent: int, keyword_line: int):
        name, ln = tk.next("a joint name")
        if name in ("{", "}"):
            raise tk.error(f"expected a joint name, got {name!r}", ln)
        # a name may hold spaces (3ds Max Biped: "Bip01 L Thigh"): the rest of the keyword's line up to "{"
        while tk.pos < len(tk.items) and tk.items[tk.pos][1] == keyword_line and tk.items[tk.pos][0] != "{":
            name += " " + tk.items[tk.pos][0]
            tk.pos += 1
        if name in names:
            raise tk.error(f"duplicate joint name {name!r}", ln)
        idx = len(names)
        names.append(name)
        parents.append(parent)
        end_site.append(False)
        tk.expect("{")
        tk.expect("OFFSET")
        offsets.append([tk.number(f"OFFSET of {name}") for _ in range(3)])
        tk.expect("CHANNELS")
        n = tk.integer(f"channel count of {name}")
        chans = []
        for _ in range(n):
            ch, cln = tk.next(f"a channel name of {name}")
            if ch not in _CHANNELS:
                raise tk.error(f"unknown channel {ch!r} of joint {name!r} (expected one of {', '.join(_CHANNELS)})",
                               cln)
            if ch in chans:
                raise tk.error(f"channel {ch!r} repeated for joint {name!r}", cln)
            chans.append(ch)
        channels.append(chans)
        while True:
            tok, ln = tk.next(f"JOINT, End Site or '}}' closing {name}")
            if tok == "JOINT":
                joint(idx, ln)
            elif tok == "End":
                tk.expect("Site")
                tk.expect("{")
                tk.expect("OFFSET")
                off = [tk.number(f"End Site OFFSET of {name}") for _ in range(3)]
                tk.expect("}")
                if any(abs(v) > 0 for v in off):
                    end_name = f"{name}_end"
                    while end_name in names:
                        end_name += "_"
                    names.append(end_name)
                    parents.append(idx)
                    offsets.append(off)
                    channels.append([])
                    end_site.append(True)
            elif tok == "}":
                return
            else:
                raise tk.error(f"expected 'JOINT', 'End Site' or '}}' inside joint {name!r}, got {tok!r}", ln)

    tk.expect("HIERARCHY")
    ln = tk.expect("ROOT")
    joint(-1, ln)
    if tk.peek() == "ROOT":
        raise tk.error("more than one ROOT; only one hierarchy per file is supported")
    return names, parents, np.array(offsets, dtype=np.float64), channels, end_site


def _euler_channels_to_quat(values: np.ndarray, order: str) -> np.ndarray:
    """(T, 3) degrees in channel order ``order`` (e.g. "zxy") to (T, 4) quaternions R = R0 R1 R2."""
    import torch
    angles = np.zeros_like(values)
    for k, axis in enumerate(order):
        angles[:, "xyz".index(axis)] = values[:, k]
    with torch.no_grad():
        return qfrom_euler(torch.as_tensor(np.radians(angles)), order).numpy()


@dataclass
class BvhData:
    """A BVH file as written: the hierarchy and, per frame, every joint's local rotation and translation.

    Attributes:
        path: the file.
        names, parents: joints in file order (``<parent>_end`` leaves for non-zero End Sites), parent -1 = root.
        offsets: (J, 3) OFFSET of each joint, file units.
        channels: per joint the channel names in file order ([] for end sites).
        end_site: per joint, whether it is an End Site leaf.
        rotations: (T, J, 4) local rotations (w, x, y, z) from the rotation channels (identity where none).
        translations: (T, J, 3) local translations, file units: the position channels where a joint has them
            (missing axes from its OFFSET), else its OFFSET in every frame.
        fps: 1 / Frame Time.
    """

    path: Path
    names: tuple[str, ...]
    parents: tuple[int, ...]
    offsets: np.ndarray
    channels: list[list[str]]
    end_site: list[bool]
    rotations: np.ndarray
    translations: np.ndarray
    fps: float

    def global_positions(self, scale: float = 1.0) -> np.ndarray:
        """(T, J, 3) world positions by forward kinematics with the per-frame translations, times ``scale``."""
        return _fk_with_translations(self.rotations, self.translations, self.parents)[0] * scale


def _fk_with_translations(rotations: np.ndarray, translations: np.ndarray, parents) -> tuple[np.ndarray, np.ndarray]:
    """Forward kinematics with a local translation per joint and frame.

    Args:
        rotations: (T, J, 4) local rotations; translations: (T, J, 3) local translations (the root's is its
            world position); parents: parent index per joint, parents before children.
    Returns:
        world positions (T, J, 3) and world rotation matrices (T, J, 3, 3).
    """
    local = np_qto_matrix(rotations)
    world_R = np.empty_like(local)
    world_P = np.empty_like(translations)
    for j, p in enumerate(parents):
        if p < 0:
            world_R[:, j] = local[:, j]
            world_P[:, j] = translations[:, j]
        else:
            world_R[:, j] = world_R[:, p] @ local[:, j]
            world_P[:, j] = world_P[:, p] + np.einsum("tab,tb->ta", world_R[:, p], translations[:, j])
    return world_P, world_R


def parse_bvh(path: str | Path, max_bytes: int | None = MAX_BVH_BYTES) -> BvhData:
    """Read a BVH file exactly as written (file units; see :class:`BvhData`).

    Args:
        path: the file.
        max_bytes: the largest file read (checked before it is opened; None: no limit).
    Raises:
        MotionFormatError: naming the file and the line of the first problem, or the file's size.
    """
    path = Path(path)
    try:
        size = path.stat().st_size
        if max_bytes is not None and size > max_bytes:
            raise MotionFormatError(f"{path}: {size / 2**20:.1f} MiB, larger than the BVH limit of "
                                    f"{max_bytes / 2**20:.0f} MiB")
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise MotionFormatError(f"{path}: cannot read ({exc.strerror or exc})") from None
    header = _FRAME_TIME_LINE.search(text)
    tk = _Tokens(text, path, len(text[:header.end()].splitlines()) if header else None)
    names, parents, offsets, channels, end_site = _parse_hierarchy(tk)
    values, frame_time = _read_frames(tk, sum(len(c) for c in channels))
    rotations, translations = _apply_channels(values, offsets, channels)
    return BvhData(path, tuple(names), tuple(parents), offsets, channels, end_site, np_qfix(rotations),
                   translations, 1.0 / frame_time)


def _fold_static_root(rotations: np.ndarray, translations: np.ndarray, names: list[str], parents: list[int],
                      tolerance: float):
    """Drop a root that does not move and has one child (a placement joint such as ``joint_Root``): its constant
    transform is folded into the child, which becomes the root and keeps its per-frame translation."""
    children = [j for j, p in enumerate(parents) if p == 0]
    static = (np.abs(translations[:, 0] - translations[0, 0]).max() <= tolerance
              and np.abs(rotations[:, 0] - rotations[0, 0]).max() <= 1e-9)
    if len(parents) < 3 or len(children) != 1 or not static:
        return None
    c = children[0]
    R0 = np_qto_matrix(rotations[0, 0])
    translations = translations.copy()
    rotations = rotations.copy()
    translations[:, c] = translations[:, 0] + translations[:, c] @ R0.T
    rotations[:, c] = np_qmul(rotations[:, 0], rotations[:, c])
    keep = [j for j in range(len(names)) if j != 0]
    new_index = {old: new for new, old in enumerate(keep)}
    new_parents = [new_index.get(parents[j], -1) for j in keep]
    return rotations[:, keep], translations[:, keep], [names[j] for j in keep], new_parents


def read_bvh(path: str | Path, scale: float | None = None) -> Motion:
    """Read a BVH file into a Motion on a skeleton named after the file (stem).

    Position channels on any joint are that joint's local translation. A Motion carries a translation only on
    its root, so: a root that does not move and has one child (``joint_Root`` above ``Hips``) is folded into
    that child; other joints whose translation varies keep their median translation as the bone offset, and the
    largest resulting position error is recorded as ``metadata["translation_residual_m"]`` (read exact world
    positions with :func:`parse_bvh` and :meth:`BvhData.global_positions`).

    Args:
        path: the .bvh file.
        scale: metres per file unit; None guesses from the posed body's extent (see the module docstring).

    Returns:
        Motion (rotations (T, J, 4), root positions (T, 3) in metres, fps = 1 / Frame Time), metadata with
        ``source`` (file name), ``bvh_scale``, ``bvh_scale_guess``, ``bvh_channels`` (per joint).

    Raises:
        MotionFormatError: naming the file and the line of the first problem.
    """
    data = parse_bvh(path)
    path = data.path
    exact = data.global_positions()                       # (T, J, 3) file units, the file's own FK
    # the posed body's largest extent (median over frames) gives the units: some rigs' rest pose lies along one axis
    extent = max(float(np.median((exact.max(1) - exact.min(1)).max(-1))), 1e-9)
    guess = "given"
    if scale is None:
        scale, guess = guess_unit(extent)
    if not scale > 0:
        raise MotionFormatError(f"{path}: scale must be positive, got {scale}")
    names, parents = list(data.names), list(data.parents)
    rotations, translations = data.rotations, data.translations
    folded = _fold_static_root(rotations, translations, names, parents, 1e-6 * extent)
    if folded is not None:
        rotations, translations, names, parents = folded
        exact = exact[:, 1:]                              # world positions do not change when the root is folded
    offsets = np.median(translations, axis=0)
    offsets[0] = 0.0
    skeleton = Skeleton(path.stem, tuple(names), tuple(parents), offsets * scale,
                        height=extent * scale)
    motion = Motion(skeleton, rotations, translations[:, 0] * scale, data.fps, {})
    residual = float(np.linalg.norm(motion.positions() - exact * scale, axis=-1).max())
    motion.metadata = metadata = {"source": path.name, "format": "bvh", "bvh_scale": scale, "bvh_scale_guess": guess,
                "bvh_channels": {data.names[j]: chans for j, chans in enumerate(data.channels)
                                 if not data.end_site[j]}}
    if folded is not None:
        metadata["folded_root"] = data.names[0]
    if residual > 1e-6:
        metadata["translation_residual_m"] = residual
    return motion


def _read_frames(tk: _Tokens, n_ch: int) -> tuple[np.ndarray, float]:
    """The MOTION section: (T, n_ch) channel values, one line per frame, and the frame time in seconds."""
    tk.expect("MOTION")
    tk.expect("Frames:")
    n_frames = tk.integer("the frame count after 'Frames:'")
    tk.expect("Frame")
    tk.expect("Time:")
    frame_time = tk.number("Frame Time")
    lo, hi = FRAME_TIME_RANGE
    if not lo <= frame_time <= hi:
        raise tk.error(f"Frame Time must be from {lo:g} to {hi:g} s (1000 to 1 frames per second), got "
                       f"{frame_time:g}", tk.items[tk.pos - 1][1])
    if n_frames == 0:
        raise tk.error("the file has no frames (Frames: 0)", tk.items[tk.pos - 1][1])
    data_line = tk.items[tk.pos][1] if tk.pos < len(tk.items) else tk.items[tk.pos - 1][1] + 1
    # one row per non-blank line, filled in place: no Python float per value
    values = np.empty((sum(1 for line in tk.lines[data_line - 1:] if line.strip()), n_ch), dtype=np.float64)
    n = 0
    for ln in range(data_line, len(tk.lines) + 1):
        line = tk.lines[ln - 1].split()
        if not line:
            continue
        if len(line) != n_ch:
            raise tk.error(f"frame {n} has {len(line)} values, expected {n_ch} (one per channel)", ln)
        try:
            values[n] = line
        except ValueError:
            bad = next(v for v in line if not _is_float(v))
            raise tk.error(f"frame {n}: expected a number, got {bad!r}", ln) from None
        if not np.all(np.isfinite(values[n])):
            raise tk.error(f"frame {n}: value is not finite", ln)
        n += 1
    if n != n_frames:
        raise tk.error(f"'Frames: {n_frames}' but the file holds {n} frame lines")
    return values, frame_time


def _apply_channels(values: np.ndarray, offsets: np.ndarray, channels: list[list[str]]):
    """Per-joint channel blocks -> local rotations (T, J, 4) and local translations (T, J, 3), file units."""
    n_frames, J = len(values), len(channels)
    rotations = np.zeros((n_frames, J, 4))
    rotations[..., 0] = 1.0
    translations = np.repeat(offsets[None].astype(np.float64), n_frames, axis=0)
    col = 0
    for j, chans in enumerate(channels):
        block = values[:, col:col + len(chans)]
        col += len(chans)
        pos_idx = [k for k, c in enumerate(chans) if c.endswith("position")]
        rot_idx = [k for k, c in enumerate(chans) if c.endswith("rotation")]
        for k in pos_idx:
            translations[:, j, "XYZ".index(chans[k][0])] = block[:, k]
        if rot_idx:
            order = "".join(chans[k][0].lower() for k in rot_idx)
            vals = block[:, rot_idx]
            if len(rot_idx) < 3:  # pad missing axes with zero angles
                missing = [a for a in "xyz" if a not in order]
                order += "".join(missing)
                vals = np.concatenate([vals, np.zeros((n_frames, 3 - len(rot_idx)))], 1)
            rotations[:, j] = _euler_channels_to_quat(vals, order)
    return rotations, translations


def _is_float(v: str) -> bool:
    try:
        float(v)
        return True
    except ValueError:
        return False


def write_bvh(motion: Motion, path: str | Path, rotation_order: str = "ZXY", scale: float = 1.0) -> None:
    """Write a Motion as BVH.

    Args:
        motion: any skeleton; leaves are written as End Sites.
        path: output file.
        rotation_order: Euler channel order, a permutation of "XYZ" (e.g. "ZXY", the common mocap order).
        scale: file units per metre (1 writes metres, 100 centimetres).
    """
    import torch
    order = rotation_order.upper()
    if sorted(order) != ["X", "Y", "Z"]:
        raise ValueError(f"rotation_order must be a permutation of 'XYZ', got {rotation_order!r}")
    sk = motion.skeleton
    children = sk.children()
    with torch.no_grad():
        eul = qeuler(torch.as_tensor(np_qfix(motion.rotations)), order.lower()).numpy()   # (T, J, 3) x, y, z
    eul = np.degrees(np.unwrap(eul, axis=0))
    rot_cols = ["XYZ".index(a) for a in order]
    rot_channels = " ".join(f"{a}rotation" for a in order)
    lines = ["HIERARCHY"]
    data_cols: list[np.ndarray] = []

    def fmt(v) -> str:
        return " ".join(f"{x:.10g}" for x in v)

    def emit(j: int, depth: int):
        ind = "\t" * depth
        head = "ROOT" if j == 0 else "JOINT"
        lines.append(f"{ind}{head} {sk.joints[j]}")
        lines.append(f"{ind}{{")
        lines.append(f"{ind}\tOFFSET {fmt((sk.offsets[j] if j else np.zeros(3)) * scale)}")
        if j == 0:
            lines.append(f"{ind}\tCHANNELS 6 Xposition Yposition Zposition {rot_channels}")
            data_cols.append(motion.root_positions * scale)
        else:
            lines.append(f"{ind}\tCHANNELS 3 {rot_channels}")
        data_cols.append(eul[:, j][:, rot_cols])
        for c in children[j]:
            if children[c]:
                emit(c, depth + 1)
            else:
                lines.append(f"{ind}\tEnd Site")
                lines.append(f"{ind}\t{{")
                lines.append(f"{ind}\t\tOFFSET {fmt(sk.offsets[c] * scale)}")
                lines.append(f"{ind}\t}}")
        lines.append(f"{ind}}}")

    if not children[0]:
        raise ValueError("write_bvh needs a skeleton with at least one joint below the root")
    emit(0, 0)
    data = np.concatenate(data_cols, axis=1)
    lines += ["MOTION", f"Frames: {motion.num_frames}", f"Frame Time: {1.0 / motion.fps:.15g}"]
    lines += [fmt(row) for row in data]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


__all__ = ["read_bvh", "parse_bvh", "BvhData", "write_bvh"]
