"""BVH motion files: reading any hierarchy, writing our skeletons, and retargeting by joint names.

Reading (:func:`read_bvh`):
- any hierarchy and any per-joint channel order; rotations are intrinsic Euler angles in degrees applied in
  the listed order (``Zrotation Xrotation Yrotation`` means R = Rz Rx Ry acting on column vectors);
- a joint name is the rest of its ``ROOT``/``JOINT`` line, so names with spaces (3ds Max Biped's
  ``Bip01 L Thigh``) are kept whole;
- the root's position channels give its absolute position (as Blender reads them); position channels on other
  joints are taken from the first frame as that joint's offset (their later changes are not representable on a
  fixed skeleton and are recorded in ``metadata["ignored_channels"]``);
- ``End Site`` blocks with a non-zero offset become leaf joints named ``<parent>_end`` with identity rotation;
  zero-offset end sites are dropped;
- units: ``scale`` multiplies file units into metres. ``scale=None`` guesses from the rest-pose height (vertical
  extent of the hierarchy): 0.5..3 -> metres (1), 50..300 -> centimetres (0.01), anything else is normalised to a
  1.7 m body; the guess is recorded in ``metadata["bvh_scale"]`` and ``metadata["bvh_scale_guess"]``.
Malformed files raise :class:`~generation.core.motion.MotionFormatError` naming the file and line.

Writing (:func:`write_bvh`): root with 3 position + 3 rotation channels, other joints 3 rotation channels,
skeleton leaves written as ``End Site`` (BVH leaves carry no name or rotation, so leaf names come back as
``<parent>_end``; positions are kept exactly). Readable by Blender's and Unity's importers.

Retargeting (:func:`retarget`): source FK positions, scaled by the ratio of hip heights, are mapped by joint name
onto the target and solved with :func:`generation.core.ik.solve_rotations`.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from generation.core.ik import bend_limb_to_target, ik_report, solve_rotations
from generation.core.kinematics import np_forward_kinematics
from generation.core.motion import Motion, MotionFormatError
from generation.core.quaternion import np_qfix, qeuler, qfrom_euler
from generation.core.skeleton import Skeleton

_CHANNELS = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")


class _Tokens:
    """Whitespace tokens with their 1-based line numbers."""

    def __init__(self, text: str, path: Path):
        self.path = path
        self.items: list[tuple[str, int]] = []
        self.lines = text.splitlines()
        for ln, line in enumerate(self.lines, 1):
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


def _guess_scale(rest_height: float) -> tuple[float, str]:
    if 0.5 <= rest_height <= 3.0:
        return 1.0, "metres"
    if 50.0 <= rest_height <= 300.0:
        return 0.01, "centimetres"
    if rest_height <= 0:
        return 1.0, "flat hierarchy, kept as metres"
    return 1.7 / rest_height, "unknown unit, normalised to a 1.7 m body"


def read_bvh(path: str | Path, scale: float | None = None) -> Motion:
    """Read a BVH file into a Motion on a skeleton named after the file (stem).

    Args:
        path: the .bvh file.
        scale: metres per file unit; None guesses (see the module docstring).

    Returns:
        Motion with one joint per BVH joint (plus ``<parent>_end`` leaves for non-zero End Sites), rotations
        (T, J, 4), root positions (T, 3) in metres, fps = 1 / Frame Time, metadata with ``source`` (file name),
        ``bvh_scale``, ``bvh_scale_guess``, ``bvh_channels`` (per joint).

    Raises:
        MotionFormatError: naming the file and the line of the first problem.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise MotionFormatError(f"{path}: cannot read ({exc.strerror or exc})") from None
    tk = _Tokens(text, path)
    names, parents, offsets, channels, end_site = _parse_hierarchy(tk)
    values, frame_time = _read_frames(tk, sum(len(c) for c in channels))

    rest = Skeleton(path.stem, tuple(names), tuple(parents), offsets).rest_positions()
    rest_height = float(rest[:, 1].max() - rest[:, 1].min())
    guess = "given"
    if scale is None:
        scale, guess = _guess_scale(rest_height)
    if not scale > 0:
        raise MotionFormatError(f"{path}: scale must be positive, got {scale}")

    rotations, root_pos, offsets, ignored = _apply_channels(values, names, offsets, channels, rest_height)
    skeleton = Skeleton(path.stem, tuple(names), tuple(parents), offsets * scale,
                        height=rest_height * scale if rest_height > 0 else 1.0)
    metadata = {"source": path.name, "format": "bvh", "bvh_scale": scale, "bvh_scale_guess": guess,
                "bvh_channels": {names[j]: chans for j, chans in enumerate(channels) if not end_site[j]}}
    if ignored:
        metadata["ignored_channels"] = [f"{n}: varying position channels (first frame used as offset)"
                                        for n in ignored]
    return Motion(skeleton, np_qfix(rotations), root_pos * scale, 1.0 / frame_time, metadata)


def _read_frames(tk: _Tokens, n_ch: int) -> tuple[np.ndarray, float]:
    """The MOTION section: (T, n_ch) channel values, one line per frame, and the frame time in seconds."""
    tk.expect("MOTION")
    tk.expect("Frames:")
    n_frames = tk.integer("the frame count after 'Frames:'")
    tk.expect("Frame")
    tk.expect("Time:")
    frame_time = tk.number("Frame Time")
    if frame_time <= 0:
        raise tk.error(f"Frame Time must be positive, got {frame_time}", tk.items[tk.pos - 1][1])
    if n_frames == 0:
        raise tk.error("the file has no frames (Frames: 0)", tk.items[tk.pos - 1][1])
    data_line = tk.items[tk.pos][1] if tk.pos < len(tk.items) else len(tk.lines) + 1
    rows = []
    for ln in range(data_line, len(tk.lines) + 1):
        line = tk.lines[ln - 1].split()
        if not line:
            continue
        if len(line) != n_ch:
            raise tk.error(f"frame {len(rows)} has {len(line)} values, expected {n_ch} (one per channel)", ln)
        try:
            row = [float(v) for v in line]
        except ValueError:
            bad = next(v for v in line if not _is_float(v))
            raise tk.error(f"frame {len(rows)}: expected a number, got {bad!r}", ln) from None
        if not np.all(np.isfinite(row)):
            raise tk.error(f"frame {len(rows)}: value is not finite", ln)
        rows.append(row)
    if len(rows) != n_frames:
        raise tk.error(f"'Frames: {n_frames}' but the file holds {len(rows)} frame lines")
    return np.array(rows, dtype=np.float64).reshape(n_frames, n_ch), frame_time


def _apply_channels(values: np.ndarray, names: list[str], offsets: np.ndarray, channels: list[list[str]],
                    rest_height: float):
    """Per-joint channel blocks -> local rotations (T, J, 4), root positions (T, 3) and offsets (J, 3), in file
    units, and the names of non-root joints whose position channels vary (only their first frame is kept)."""
    n_frames, J = len(values), len(names)
    rotations = np.zeros((n_frames, J, 4))
    rotations[..., 0] = 1.0
    root_pos = np.tile(offsets[0], (n_frames, 1))
    ignored = []
    col = 0
    offsets = offsets.copy()
    for j, chans in enumerate(channels):
        block = values[:, col:col + len(chans)]
        col += len(chans)
        pos_idx = [k for k, c in enumerate(chans) if c.endswith("position")]
        rot_idx = [k for k, c in enumerate(chans) if c.endswith("rotation")]
        if pos_idx:
            xyz = np.zeros((n_frames, 3))
            xyz[:] = offsets[j] if j else 0.0
            for k in pos_idx:
                xyz[:, "XYZ".index(chans[k][0])] = block[:, k]
            if j == 0:
                root_pos = xyz
            else:
                offsets[j] = xyz[0]
                if np.abs(xyz - xyz[0]).max() > 1e-6 * max(rest_height, 1e-9):
                    ignored.append(names[j])
        if rot_idx:
            order = "".join(chans[k][0].lower() for k in rot_idx)
            vals = block[:, rot_idx]
            if len(rot_idx) < 3:  # pad missing axes with zero angles
                missing = [a for a in "xyz" if a not in order]
                order += "".join(missing)
                vals = np.concatenate([vals, np.zeros((n_frames, 3 - len(rot_idx)))], 1)
            rotations[:, j] = _euler_channels_to_quat(vals, order)
    return rotations, root_pos, offsets, ignored


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


# ---- retargeting -----------------------------------------------------------------------------------
#: Candidate source names per gait-skeleton joint (first present wins): Mixamo/Unity-style, CMU-style
#: (cgspeed conversion), our own skeletons and the DeepMimic humanoid.
GAIT_NAME_CANDIDATES: dict[str, tuple[str, ...]] = {
    "root": ("Hips", "hips", "Hip", "pelvis", "root"),
    "left_hip": ("LeftUpLeg", "LeftHip", "LeftThigh", "LHip", "left_hip"),
    "left_knee": ("LeftLeg", "LeftKnee", "LeftShin", "LKnee", "left_knee"),
    "left_heel": ("LeftFoot", "LeftAnkle", "LAnkle", "left_heel", "left_ankle"),
    "left_toe": ("LeftToeBase", "LeftToe", "LeftToe_End", "LeftFoot_end", "left_toe", "left_heel_end"),
    "right_hip": ("RightUpLeg", "RightHip", "RightThigh", "RHip", "right_hip"),
    "right_knee": ("RightLeg", "RightKnee", "RightShin", "RKnee", "right_knee"),
    "right_heel": ("RightFoot", "RightAnkle", "RAnkle", "right_heel", "right_ankle"),
    "right_toe": ("RightToeBase", "RightToe", "RightToe_End", "RightFoot_end", "right_toe", "right_heel_end"),
    "lower_back": ("LowerBack", "Spine", "spine", "lower_back", "chest"),
    "spine": ("Spine2", "Spine1", "Chest", "chest3", "chest4", "spine"),
    "neck": ("Neck", "neck"),
    "head": ("Head", "head", "Neck1", "Neck_end", "neck_end"),
    "left_shoulder": ("LeftArm", "LeftShoulder", "LeftUpperArm", "left_shoulder"),
    "left_elbow": ("LeftForeArm", "LeftElbow", "LeftLowerArm", "left_elbow"),
    "left_hand": ("LeftHand", "LeftWrist", "left_hand", "left_wrist"),
    "left_hand_index": ("LeftHandIndex1", "LeftHandMiddle1", "LeftFingerBase", "LeftHand_end", "left_hand_index",
                        "left_wrist_end"),
    "right_shoulder": ("RightArm", "RightShoulder", "RightUpperArm", "right_shoulder"),
    "right_elbow": ("RightForeArm", "RightElbow", "RightLowerArm", "right_elbow"),
    "right_hand": ("RightHand", "RightWrist", "right_hand", "right_wrist"),
    "right_hand_index": ("RightHandIndex1", "RightHandMiddle1", "RightFingerBase", "RightHand_end",
                         "right_hand_index", "right_wrist_end"),
}
#: Candidate source names per gesture-skeleton joint.
GESTURE_NAME_CANDIDATES: dict[str, tuple[str, ...]] = {
    "root": ("Hips", "hips", "Hip", "pelvis", "root"),
    "chest": ("Spine", "LowerBack", "chest"),
    "chest2": ("Spine1", "chest2"),
    "chest3": ("Spine2", "Chest", "chest3"),
    "chest4": ("Spine3", "UpperChest", "Chest2", "chest4"),
    "neck": ("Neck", "neck"),
    "head": ("Head", "head", "Neck1"),
    "left_collar": ("LeftShoulder", "LeftCollar", "LeftClavicle", "left_collar"),
    "left_shoulder": ("LeftArm", "LeftUpperArm", "left_shoulder"),
    "left_elbow": ("LeftForeArm", "LeftElbow", "LeftLowerArm", "left_elbow"),
    "left_wrist": ("LeftHand", "LeftWrist", "left_wrist", "left_hand"),
    "right_collar": ("RightShoulder", "RightCollar", "RightClavicle", "right_collar"),
    "right_shoulder": ("RightArm", "RightUpperArm", "right_shoulder"),
    "right_elbow": ("RightForeArm", "RightElbow", "RightLowerArm", "right_elbow"),
    "right_wrist": ("RightHand", "RightWrist", "right_wrist", "right_hand"),
    "left_hip": ("LeftUpLeg", "LeftHip", "LeftThigh", "left_hip"),
    "left_knee": ("LeftLeg", "LeftKnee", "LeftShin", "left_knee"),
    "left_ankle": ("LeftFoot", "LeftAnkle", "left_ankle", "left_heel"),
    "left_toe": ("LeftToeBase", "LeftToe", "LeftToe_End", "LeftFoot_end", "left_toe"),
    "right_hip": ("RightUpLeg", "RightHip", "RightThigh", "right_hip"),
    "right_knee": ("RightLeg", "RightKnee", "RightShin", "right_knee"),
    "right_ankle": ("RightFoot", "RightAnkle", "right_ankle", "right_heel"),
    "right_toe": ("RightToeBase", "RightToe", "RightToe_End", "RightFoot_end", "right_toe"),
}


def default_joint_map(source: Skeleton, target: Skeleton) -> dict[str, str]:
    """Map target joint names to source joint names from the candidate tables (first present name wins).

    The target must be the gait or gesture skeleton (by joint names); joints with no candidate present are left
    out (retarget interpolates or keeps them straight).
    """
    table = GAIT_NAME_CANDIDATES if "left_hand_index" in target.joints else GESTURE_NAME_CANDIDATES
    present = set(source.joints)
    out = {}
    for name in target.joints:
        for cand in table.get(name, ()):
            if cand in present:
                out[name] = cand
                break
    return out


def _leg_height(skeleton: Skeleton) -> float:
    """Root height above the lowest rest joint, or the rest vertical extent when the root is at the bottom."""
    rest = skeleton.rest_positions()
    extent = float(rest[:, 1].max() - rest[:, 1].min())
    h = skeleton.root_height()
    return h if h > 0.2 * extent else extent


def retarget(motion: Motion, target_skeleton: Skeleton, joint_map: dict[str, str] | None = None,
             metadata: dict | None = None, foot_ik: bool = True) -> Motion:
    """Move a motion onto another skeleton by matching joints by name.

    The source's FK positions are scaled by target hip height / source hip height (so strides and root heights
    fit the target's legs), mapped target joint <- source joint, and solved with IK on the target (bone lengths
    of the target are kept; directions come from the source). Target joints without a mapping are placed on the
    line between their nearest mapped ancestor and descendant in proportion to rest bone lengths, or, for
    leaves, keep the identity local rotation.

    With ``foot_ik`` (default) each mapped leg chain (``<side>_hip`` - ``<side>_knee`` - ``<side>_heel`` or
    ``_ankle``) is then bent with two-bone IK so the heel/ankle lands exactly on the scaled source position, and
    the foot's children point where the source's do. Matching directions alone would move the feet with every
    difference in leg proportions and make planted feet slide; this keeps the source's foot contacts.

    Args:
        motion: source Motion.
        target_skeleton: e.g. ``gait_skeleton()``.
        joint_map: {target joint name: source joint name}; default :func:`default_joint_map`. The root must be
            mapped.
        metadata: merged over a copy of the source metadata.

    Returns:
        Motion on ``target_skeleton`` at the source fps; metadata gains ``retarget`` (scale, map, IK error of the
        mapped joints in metres).
    """
    src = motion.skeleton
    tgt = target_skeleton
    joint_map = dict(default_joint_map(src, tgt) if joint_map is None else joint_map)
    for t_name, s_name in joint_map.items():
        tgt.index(t_name)
        src.index(s_name)
    root_name = tgt.joints[0]
    if root_name not in joint_map:
        raise ValueError(f"retarget: the target root {root_name!r} must be mapped (joint_map has {sorted(joint_map)})")
    scale = _leg_height(tgt) / _leg_height(src)
    src_pos = motion.positions() * scale
    T, J = motion.num_frames, tgt.num_joints
    P = np.zeros((T, J, 3))
    known = np.zeros(J, bool)
    for t_name, s_name in joint_map.items():
        P[:, tgt.index(t_name)] = src_pos[:, src.index(s_name)]
        known[tgt.index(t_name)] = True
    fill_unmapped_joints(P, known, tgt)
    rotations = solve_rotations(P, tgt, known)
    if foot_ik:
        rotations = place_feet_on_source(rotations, P, known, tgt, joint_map)
    meta = dict(motion.metadata)
    meta.update(metadata or {})
    out = Motion(tgt, rotations, P[:, 0].copy(), motion.fps, meta)
    mapped = [tgt.index(n) for n in joint_map]
    err = np.linalg.norm(out.positions()[:, mapped] - P[:, mapped], axis=-1)
    meta["retarget"] = {"source_skeleton": src.name, "scale": scale, "joint_map": joint_map,
                        "max_error_m": float(err.max()), "mean_error_m": float(err.mean())}
    return out


def place_feet_on_source(rotations: np.ndarray, P: np.ndarray, known: np.ndarray, tgt: Skeleton,
                joint_map: dict[str, str]) -> np.ndarray:
    """Two-bone IK of each mapped leg onto the desired heel/ankle positions; returns new rotations."""
    Q = np_forward_kinematics(rotations, P[:, 0], tgt)
    lengths = tgt.bone_lengths()
    children = tgt.children()
    changed = False
    for side in ("left", "right"):
        for end in (f"{side}_heel", f"{side}_ankle"):
            chain = (f"{side}_hip", f"{side}_knee", end)
            if not all(n in tgt.joints and n in joint_map for n in chain):
                continue
            e = tgt.index(end)
            if tgt.parents[e] != tgt.index(chain[1]) or tgt.parents[tgt.index(chain[1])] != tgt.index(chain[0]):
                continue
            Q = bend_limb_to_target(Q, tgt, end, P[:, e])
            for c in children[e]:
                if known[c] and lengths[c] > 1e-9:
                    d = P[:, c] - P[:, e]
                    Q[:, c] = Q[:, e] + lengths[c] * d / np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-12)
            changed = True
    return solve_rotations(Q, tgt) if changed else rotations


def fill_unmapped_joints(P: np.ndarray, known: np.ndarray, sk: Skeleton) -> None:
    """Place unmapped interior joints between mapped ancestor and descendant (in place; marks them known)."""
    children = sk.children()
    lengths = sk.bone_lengths()
    for j in range(sk.num_joints):
        if known[j]:
            continue
        # nearest mapped ancestor
        a, dist_a = sk.parents[j], lengths[j]
        while a >= 0 and not known[a]:
            dist_a += lengths[a]
            a = sk.parents[a]
        # nearest mapped descendant along first children
        d, dist_d = j, 0.0
        while not known[d] and children[d]:
            d = children[d][0]
            dist_d += lengths[d]
        if a < 0 or not known[d] or d == j:
            continue
        frac = dist_a / max(dist_a + dist_d, 1e-12)
        P[:, j] = P[:, a] + frac * (P[:, d] - P[:, a])
        known[j] = True


__all__ = ["read_bvh", "write_bvh", "retarget", "default_joint_map", "GAIT_NAME_CANDIDATES",
           "GESTURE_NAME_CANDIDATES", "ik_report"]
