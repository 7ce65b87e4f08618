"""Plan entries that show an imported motion-capture file: ``generator: captured_file``.

    - id: walk_happy_07
      generator: captured_file
      file: mocap/walk_happy_07.npz      # a Motion .npz of `python -m generation.mocap import` (or a .bvh)
      modality: gait                     # gait (default) | gesture; an .npz must be on that skeleton
      emotion: happy                     # optional label: gait emotion vector / name; gesture emotion_label or vad
      start_s: 2.0                       # optional: skip the first seconds (the clip lasts the render duration)
      seated: true                       # gesture only: seat a standing capture as the seated agents sit

The clip's ``origin`` is always ``source``: it is the captured motion a study compares generated clips with
(naturalness sections). A generated entry names it in ``pair`` (its ``source_clip_id`` in the catalogue), so a
participant is never shown both. Labels default to those the importer stored in the file (``--labels`` /
``--label-pattern``); the entry's own labels win. A ``.bvh`` is imported on the fly with the importer's defaults
(:func:`generation.mocap.import_file`: rig auto-mapping, units and up axis guessed). Relative paths are relative
to the working directory of the command that reads the plan, else to the repository root (so the built-in plans
can name the shipped real takes in ``generation/data/mocap/``).

Provenance: a ``SOURCE.json`` beside the file (``{"dataset": ..., "licence": ..., "citation": ..., "url": ...,
"name_pattern": regex with named groups such as content, style, take}``) is copied into the clip's metadata as
``dataset``, ``licence``, ``citation``, ``url`` and the groups the file name matches (``take``...): real data keeps
its licence and citation in everything derived from it.

``seated: true`` (gesture modality only) seats a standing captured gesture on the chair as the seed 003 agents sit:
legs and pelvis in the seated rest pose, trunk, head and arms from the capture, hands kept clear of the body and
the chair (:func:`generation.mocap.seated_gesture.seat_gesture`; its report is in the ``seating`` metadata).

The file's SHA-256 goes into the entry's inputs, so the clip hash changes (and the clip is rendered anew) when the
file does. Metadata of the motion: ``captured`` (True unless the file says it is synthetic), ``imported_file``,
``imported_sha256``, ``imported_format``, ``rig`` (our skeleton, the source format and rig, the joint map used,
the retarget error) and the importer's own metadata (source file name, units, up axis...).
"""
from __future__ import annotations

import functools
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

from generation.core.digest import cached_file_sha256
from generation.core.motion import Motion, MotionFormatError
from generation.mocap import ImportOptions, import_file
from generation.mocap.seated_gesture import seat_gesture
from protocol.vocabulary import GAIT_EMOTIONS, GESTURE_VAD, MODALITIES

from .fields import FieldError
from .registry import ClipGenerationError, GeneratorSpec, InputContext, MakeContext, PlanInputs, register

SUFFIXES = (".npz", ".bvh")
REPO_ROOT = Path(__file__).resolve().parents[3]
PROVENANCE_FILE = "SOURCE.json"


class CapturedFileError(ValueError):
    """A bad ``captured_file`` field; ``field`` names it (the plan validator adds the entry)."""

    def __init__(self, field: str, message: str):
        super().__init__(f"field {field!r}: {message}")
        self.field = field
        self.message = message


def file_digest(path: Path) -> str:
    """16 hex digits of the file's SHA-256 (:func:`generation.core.digest.cached_file_sha256`)."""
    return cached_file_sha256(path)[:16]


@functools.lru_cache(maxsize=16)
def _load(path: str, digest: str, modality: str, fps: float | None):
    """The Motion of a file (cached by content digest): an .npz as saved, a .bvh through the importer."""
    p = Path(path)
    if p.suffix.lower() == ".npz":
        try:
            return Motion.load_npz(p)
        except MotionFormatError as exc:
            raise CapturedFileError("file", str(exc)) from None
    result = import_file(p, ImportOptions(skeleton=modality, fps=fps))
    if result.motion is None:
        raise CapturedFileError("file", result.row["message"])
    return result.motion


def resolve_file(given: str) -> Path:
    """The file a plan names: as given (relative to the working directory), else relative to the repository root."""
    path = Path(given)
    if path.is_file() or path.is_absolute():
        return path
    in_repo = REPO_ROOT / path
    return in_repo if in_repo.is_file() else path


def provenance(path: Path) -> dict:
    """Dataset, licence, citation and name fields of a captured file from the ``SOURCE.json`` beside it ({} when
    there is none). A SOURCE.json that is not a JSON object of strings raises CapturedFileError."""
    sidecar = path.parent / PROVENANCE_FILE
    if not sidecar.is_file():
        return {}
    try:
        info = json.loads(sidecar.read_text(encoding="utf-8"))
        if not isinstance(info, dict) or not all(isinstance(v, str) for v in info.values()):
            raise ValueError("expected a JSON object of strings")
        pattern = re.compile(info.get("name_pattern", "(?!)"))
    except (ValueError, re.error) as exc:
        raise CapturedFileError("file", f"{sidecar}: {exc}") from None
    out = {k: info[k] for k in ("dataset", "licence", "citation", "url") if k in info}
    match = pattern.fullmatch(path.stem)
    if match:
        out.update({k: v for k, v in match.groupdict().items() if v is not None})
    return out


def _number(field: str, value, lo: float, hi: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or not (
            lo <= value <= hi):
        raise CapturedFileError(field, f"expected a number in [{lo:g}, {hi:g}], got {value!r}")
    return float(value)


def _entry_labels(raw: dict, modality: str) -> dict:
    """Labels given in the entry, normalised as the other generators' (gait ``emotion`` vector; gesture
    ``emotion_label`` or ``vad``). At most one of them."""
    given = [k for k in ("emotion", "emotion_label", "vad") if k in raw]
    if len(given) > 1:
        raise CapturedFileError(given[1], f"give at most one of 'emotion', 'emotion_label', 'vad' (got {given})")
    if not given:
        return {}
    key, value = given[0], raw[given[0]]
    if modality == "gait":
        if key == "vad":
            raise CapturedFileError("vad", "a gait clip is labelled with 'emotion' (a vector or a gait emotion)")
        if isinstance(value, str) and value in GAIT_EMOTIONS:
            value = [1.0 if e == value else 0.0 for e in GAIT_EMOTIONS]
        if isinstance(value, dict):
            value = [value.get(e, 0.0) for e in GAIT_EMOTIONS] if set(value) <= set(GAIT_EMOTIONS) else None
        if not isinstance(value, (list, tuple)) or len(value) != len(GAIT_EMOTIONS) or any(
                isinstance(v, bool) or not isinstance(v, (int, float)) or v < 0 for v in value) or not sum(value) > 0:
            raise CapturedFileError(key, f"expected a gait emotion ({', '.join(GAIT_EMOTIONS)}) or "
                                         f"{len(GAIT_EMOTIONS)} non-negative numbers, got {raw[key]!r}")
        return {"emotion": [round(float(v) / sum(value), 6) for v in value]}
    if key == "vad":
        if not isinstance(value, (list, tuple)) or len(value) != 3:
            raise CapturedFileError("vad", f"expected [valence, arousal, dominance] in 0..1, got {value!r}")
        return {"vad": [_number("vad", v, 0.0, 1.0) for v in value]}
    label = str(value).strip().lower() if isinstance(value, str) else None
    if label not in GESTURE_VAD:
        raise CapturedFileError(key, f"expected a gesture emotion ({', '.join(GESTURE_VAD)}), got {value!r}")
    return {"emotion_label": label}


def _file_labels(meta: dict, modality: str) -> dict:
    """Labels the importer stored in the Motion's metadata (:mod:`generation.mocap.labels`)."""
    if modality == "gait" and isinstance(meta.get("emotion"), dict):
        vec = [float(meta["emotion"].get(e, 0.0)) for e in GAIT_EMOTIONS]
        return {"emotion": [round(v / sum(vec), 6) for v in vec]} if sum(vec) > 0 else {}
    if modality == "gesture":
        if meta.get("emotion_label") in GESTURE_VAD:
            return {"emotion_label": meta["emotion_label"]}
        if isinstance(meta.get("vad"), list) and len(meta["vad"]) == 3:
            return {"vad": [float(v) for v in meta["vad"]]}
    return {}


def captured_file_inputs(raw: dict) -> dict:
    """Normalised inputs of a ``captured_file`` entry: file (as given), sha256, format, start_s, labels and where
    they come from. Reads the file (an .npz fully; a .bvh is parsed when the clip is made). CapturedFileError names
    the field: a missing or unreadable file, a skeleton that is not the entry's modality, a bad label."""
    modality = raw.get("modality", MODALITIES[0])
    given = raw.get("file")
    if not isinstance(given, str) or not given.strip():
        raise CapturedFileError("file", f"required: the path of a Motion .npz (python -m generation.mocap import) "
                                        f"or a .bvh, got {given!r}")
    path = resolve_file(given.strip())
    if path.suffix.lower() not in SUFFIXES:
        raise CapturedFileError("file", f"{given!r}: expected a {' or '.join(SUFFIXES)} file")
    if not path.is_file():
        raise CapturedFileError("file", f"no such file {given!r} (relative paths are relative to {Path.cwd()} "
                                        f"or to {REPO_ROOT})")
    provenance(path)                        # a bad SOURCE.json fails here, before anything renders
    out = {"file": given.strip(), "sha256": file_digest(path), "format": path.suffix.lower().lstrip("."),
           "start_s": _number("start_s", raw.get("start_s", 0.0), 0.0, 86400.0)}
    seated = raw.get("seated", False)
    if not isinstance(seated, bool) or (seated and modality != "gesture"):
        raise CapturedFileError("seated", f"expected true or false, and true only with modality gesture (got "
                                          f"{seated!r} with modality {modality!r})")
    if seated:
        out["seated"] = True
    labels, source = _entry_labels(raw, modality), "entry"
    if out["format"] == "npz":
        motion = _load(str(path.resolve()), out["sha256"], modality, None)
        if motion.skeleton.name != modality:
            raise CapturedFileError("modality", f"{given!r} holds a motion on the {motion.skeleton.name!r} skeleton, "
                                                f"not {modality!r} (import it with --skeleton {modality})")
        if out["start_s"] >= motion.duration:
            raise CapturedFileError("start_s", f"{out['start_s']:g} s is past the end of {given!r} "
                                               f"({motion.duration:.2f} s)")
        if not labels:
            labels, source = _file_labels(motion.metadata, modality), "file"
    out.update(labels)
    out["labels_from"] = source if labels else None
    return out


def captured_file_motion(inputs: dict, modality: str, fps: float):
    """The Motion of a validated ``captured_file`` entry at ``fps``, from ``start_s`` on, with honest metadata."""
    path = resolve_file(inputs["file"])
    if not path.is_file() or file_digest(path) != inputs["sha256"]:
        raise CapturedFileError("file", f"{inputs['file']!r} is missing or changed since the plan was read")
    motion = _load(str(path.resolve()), inputs["sha256"], modality, None)
    if motion.skeleton.name != modality:
        raise CapturedFileError("modality", f"{inputs['file']!r} gives a {motion.skeleton.name!r} motion, "
                                            f"not {modality!r}")
    start = int(round(inputs["start_s"] * motion.fps))
    if start >= motion.num_frames - 1:
        raise CapturedFileError("start_s", f"{inputs['start_s']:g} s is past the end of {inputs['file']!r}")
    motion = motion.slice(start)            # a copy: the loaded Motion is cached and shared
    if inputs.get("seated"):
        motion = seat_gesture(motion)
    motion = motion.resample(fps) if abs(motion.fps - fps) > 1e-9 else motion
    meta = dict(motion.metadata)
    synthetic = bool(meta.get("synthetic", False))
    retarget = meta.get("retarget") or {}
    meta.update({
        "captured": not synthetic, "synthetic": synthetic, "imported_file": inputs["file"],
        "imported_sha256": inputs["sha256"], "imported_format": inputs["format"], "start_s": inputs["start_s"],
        "rig": {"skeleton": motion.skeleton.name, "source_format": meta.get("format", inputs["format"]),
                "source_file": meta.get("source", path.name), "joint_map": retarget.get("joint_map"),
                "retarget_max_error_m": retarget.get("max_error_m"), "unit_scale": meta.get("unit_scale"),
                "up_axis": meta.get("up_axis")},
        "labels_from": inputs.get("labels_from")})
    meta.update(provenance(path))
    for key in ("emotion", "emotion_label", "vad"):
        if key in inputs:
            meta[key] = dict(zip(GAIT_EMOTIONS, inputs[key], strict=True)) if key == "emotion" else inputs[key]
    motion.metadata = meta
    return motion


@dataclass(frozen=True)
class CapturedFileInputs(PlanInputs):
    """An imported motion file as the plan names it, its SHA-256 (16 hex digits) and format (npz | bvh), where the
    clip starts (s), whether a standing gesture is seated, and its labels (given in the entry or stored in the
    file, ``labels_from``)."""

    PLAN_FIELDS = frozenset({"file", "start_s", "emotion", "emotion_label", "vad", "seated"})

    file: str
    sha256: str
    format: str
    start_s: float = 0.0
    seated: bool | None = None
    emotion: tuple[float, ...] | None = None
    emotion_label: str | None = None
    vad: tuple[float, float, float] | None = None
    labels_from: str | None = None

    @classmethod
    def parse(cls, raw: dict, context: InputContext) -> CapturedFileInputs:
        try:
            out = captured_file_inputs({**raw, "modality": context.modality})
        except CapturedFileError as exc:
            raise FieldError(exc.field, exc.message) from None
        for key in ("emotion", "vad"):
            if key in out:
                out[key] = tuple(out[key])
        return cls(**out)


def make_captured_file(entry, context: MakeContext) -> Motion:
    try:
        return captured_file_motion(entry.inputs, entry.modality, context.fps)
    except CapturedFileError as exc:
        raise ClipGenerationError(f"{entry.where}: {exc}") from None


SPEC = register(GeneratorSpec(
    name="captured_file", summary="an imported motion-capture file (Motion .npz or .bvh), any modality",
    modality=None, origins=("source",), inputs=CapturedFileInputs, make=make_captured_file,
    requires=("generation.mocap.importer",), captured=True))
