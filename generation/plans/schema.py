"""Stimulus plans: which clips to make, from which generator and inputs; validation and content hashes.

A plan is a YAML (or JSON) file::

    name: demo
    description: ...
    render: {width: 640, height: 480, fps: 30, duration_s: 10}   # defaults for every clip
    qa: {foot_skate_cm_s: 5, jerk: null}   # optional: quality thresholds (study_protocol.QA_THRESHOLDS; null = off)
    clips:
      - id: happy_straight          # unique within the plan; never shown to participants
        modality: gait              # gait | gesture
        generator: gait_net         # see GENERATORS
        fallback: procedural_walk   # optional: used (and recorded) while gait_net is unavailable
        origin: generated           # generated | source
        emotion: [1, 0, 0, 0]       # happy, sad, angry, neutral (l1-normalised)
        trajectory: {kind: straight, length_m: 12}
        weights: real               # optional, gait_net: real (default, trained on real capture) | procedural
        seed: 1
        sections: [emotion_choice]  # optional hint for the study set-up
        render: {camera: tracking}  # optional per-clip render overrides

An imported motion-capture file is a source clip: ``generator: captured_file, file: path.npz|.bvh`` with optional
labels (generation/plans/captured_file.py); a generated entry links to it with ``pair``.

Entries are checked before anything is rendered; :class:`PlanError` names the entry (1-based), its id and
the field: ``entry 3 (id 'x'): field 'weight': expected a number, got 'abc'``.

Every clip's file name is a content hash of (normalised entry inputs, the generator actually used and its
version, render settings), so names reveal nothing about the condition and an unchanged clip is never
rendered twice (:func:`clip_hash`).
"""
from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from generation.quality.checks import QAThresholdError, resolve_thresholds
from generation.render.settings import RENDERER_VERSION, RenderSettings, RenderSettingsError
from study_protocol import (
    FINAL_EMOTION_COLUMNS,
    GAIT_EMOTIONS,
    GENDERS,
    GESTURE_TASKS,
    GESTURE_VAD,
    HANDEDNESS,
    MODALITIES,
    NEUTRAL_THEME,
    SECTION_TYPES,
    THEMES,
    VAD_DIMENSIONS,
)

from .captured_file import CapturedFileError, captured_file_inputs

PLANS_DIR = Path(__file__).resolve().parent
TRAJECTORY_KINDS = ("straight", "curved", "sharp_turn")
#: Named weights of the gait network (generation.gait.weights.NAMED_WEIGHTS; named here so that validating a plan
#: does not load torch): a gait_net entry's optional ``weights`` field, default real.
GAIT_WEIGHTS = ("real", "procedural")
#: Splits of the gesture network's sentence corpus (generation.gesture.data.split_sentences); a gesture_net
#: entry may say which one its sentence comes from (a record for the study: held-out inputs are "test").
SENTENCE_SPLITS = ("train", "val", "test")
#: Neutral base cycle of the RBF styliser: "real" (averaged real normal walks, generation/data/rbf/neutral_real.npz)
#: or "procedural" (averaged synthetic walks, generation.rbf.neutral_base.neutral_cycle).
RBF_BASES = ("real", "procedural")
#: Style features of an rbf entry: "expert" (Table III of seed 004) or "data" (fitted to real themed walks).
RBF_FEATURES = ("expert", "data")
CAPTURED_CLIPS = ("humanoid3d_walk.txt", "0walk_forward.txt", "turn_left0.txt", "turn_left1.txt",
                  "turn_right0.txt", "turn_right1.txt")

#: generator -> (modality, allowed origins, the generators it may fall back to); modality None: the entry's
#: ``modality`` (gait by default), for captured_file (an imported motion file, generation/plans/captured_file.py)
GENERATORS: dict[str, tuple[str | None, tuple[str, ...], tuple[str, ...]]] = {
    "gait_net": ("gait", ("generated",), ("procedural_walk",)),
    "procedural_walk": ("gait", ("generated", "source"), ()),
    "captured": ("gait", ("source",), ()),
    "neutral_walk": ("gait", ("source", "generated"), ()),
    "rbf": ("gait", ("generated",), ()),
    "gesture_net": ("gesture", ("generated",), ("procedural_gesture",)),
    "procedural_gesture": ("gesture", ("source", "generated"), ()),
    "captured_file": (None, ("source",), ()),
}
COMMON_FIELDS = {"id", "modality", "generator", "fallback", "origin", "seed", "sections", "render", "loop", "pair",
                 "note"}
GENERATOR_FIELDS: dict[str, set[str]] = {
    "gait_net": {"emotion", "transition", "trajectory", "duration_s", "weights"},
    "procedural_walk": {"emotion", "transition", "trajectory", "duration_s"},
    "captured": {"clip", "cycles"},
    "neutral_walk": {"n_cycles", "speed", "base"},
    "rbf": {"theme", "weight", "n_features", "n_cycles", "speed", "base", "features"},
    "gesture_net": {"sentence", "task", "emotion_label", "gender", "handedness", "noise", "sentence_split"},
    "procedural_gesture": {"emotion_label", "vad", "kind", "gender", "handedness", "duration_s"},
    "captured_file": {"file", "start_s", "emotion", "emotion_label", "vad", "seated"},
}


class PlanError(ValueError):
    """A plan that cannot be used; the message names the file, the entry and the field."""


@dataclass(frozen=True)
class ClipEntry:
    """One validated plan entry.

    Attributes:
        index: 1-based position in the plan's ``clips`` list.
        id: the entry's id (unique in the plan; a researcher's label, never shown to participants).
        modality, generator, origin: as in the plan (generator is the requested one; see ``fallback``).
        inputs: normalised generator inputs (numbers as floats, emotions l1-normalised, angles in radians).
        seed: integer seed for the generator.
        fallback: generator used when ``generator`` is unavailable, or None.
        loop: the player may loop this clip (short walk cycles).
        sections: study section types the clip is meant for (a hint for the study set-up).
        pair: id of the entry this clip corresponds to (a generated gesture's source), or None.
        render: render settings for this clip (plan defaults + entry overrides).
    """

    index: int
    id: str
    modality: str
    generator: str
    origin: str
    inputs: dict
    seed: int
    fallback: str | None
    loop: bool
    sections: tuple[str, ...]
    pair: str | None
    render: RenderSettings
    note: str = ""

    @property
    def where(self) -> str:
        return f"entry {self.index} (id {self.id!r})"

    def with_generator(self, generator: str) -> ClipEntry:
        """The same entry made by another generator (a fallback)."""
        return ClipEntry(self.index, self.id, self.modality, generator, self.origin, self.inputs, self.seed, None,
                         self.loop, self.sections, self.pair, self.render, self.note)


@dataclass(frozen=True)
class Plan:
    name: str
    description: str
    render: RenderSettings
    entries: tuple[ClipEntry, ...]
    source: str = ""
    meta: dict = field(default_factory=dict)
    qa: dict = field(default_factory=dict)  # quality thresholds overriding study_protocol.QA_THRESHOLDS

    def entry(self, entry_id: str) -> ClipEntry:
        for e in self.entries:
            if e.id == entry_id:
                return e
        raise KeyError(f"plan {self.name!r} has no entry {entry_id!r}")


# ---- field checks ------------------------------------------------------------------------------
class _FieldError(Exception):
    def __init__(self, field_name: str, message: str):
        super().__init__(message)
        self.field = field_name
        self.message = message


def _number(name: str, value, lo: float | None = None, hi: float | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise _FieldError(name, f"expected a number, got {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise _FieldError(name, f"expected a number in [{lo}, {hi}], got {value!r}")
    return float(value)


def _integer(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise _FieldError(name, f"expected an integer, got {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise _FieldError(name, f"expected an integer in [{lo}, {hi}], got {value!r}")
    return int(value)


def _choice(name: str, value, choices) -> str:
    if not isinstance(value, str) or value not in choices:
        raise _FieldError(name, f"expected one of {list(choices)}, got {value!r}")
    return value


def _text(name: str, value) -> str:
    if not isinstance(value, str) or not value.strip():
        raise _FieldError(name, f"expected non-empty text, got {value!r}")
    return value.strip()


def _emotion(name: str, value) -> list[float]:
    """A gait emotion vector: non-negative numbers in GAIT_EMOTIONS order, a mapping or one emotion name;
    l1-normalised."""
    if isinstance(value, str) and value in GAIT_EMOTIONS:
        value = [1.0 if e == value else 0.0 for e in GAIT_EMOTIONS]
    if isinstance(value, dict):
        unknown = set(value) - set(GAIT_EMOTIONS)
        if unknown:
            raise _FieldError(name, f"unknown emotion(s) {sorted(unknown)}; expected keys of {list(GAIT_EMOTIONS)}")
        value = [value.get(e, 0.0) for e in GAIT_EMOTIONS]
    if not isinstance(value, (list, tuple)) or len(value) != len(GAIT_EMOTIONS):
        raise _FieldError(name, f"expected {len(GAIT_EMOTIONS)} numbers ({', '.join(GAIT_EMOTIONS)}), got {value!r}")
    vec = [_number(name, v, 0.0) for v in value]
    total = sum(vec)
    if total <= 0:
        raise _FieldError(name, f"expected at least one positive component, got {value!r}")
    return [round(v / total, 6) for v in vec]


def _trajectory(value) -> dict:
    if value is None:
        value = {"kind": "straight"}
    if isinstance(value, str):
        value = {"kind": value}
    if not isinstance(value, dict):
        raise _FieldError("trajectory", f"expected a mapping with 'kind', got {value!r}")
    kind = _choice("trajectory.kind", value.get("kind", "straight"), TRAJECTORY_KINDS)
    allowed = {"straight": {"kind", "length_m"}, "curved": {"kind", "length_m", "radius_m", "angle_deg"},
               "sharp_turn": {"kind", "length_m", "angle_deg", "at_fraction"}}[kind]
    unknown = set(value) - allowed
    if unknown:
        raise _FieldError(f"trajectory.{sorted(unknown)[0]}", f"not used by a {kind} trajectory "
                                                             f"(allowed: {sorted(allowed)})")
    out = {"kind": kind, "length_m": _number("trajectory.length_m", value.get("length_m", 14.0), 1.0, 200.0)}
    if kind == "curved":
        out["radius_m"] = _number("trajectory.radius_m", value.get("radius_m", 4.0), 0.5, 100.0)
        out["angle_deg"] = _number("trajectory.angle_deg", value.get("angle_deg", 90.0), -720.0, 720.0)
    if kind == "sharp_turn":
        out["angle_deg"] = _number("trajectory.angle_deg", value.get("angle_deg", 90.0), -179.0, 179.0)
        out["at_fraction"] = _number("trajectory.at_fraction", value.get("at_fraction", 0.5), 0.05, 0.95)
    return out


def _gesture_label(name: str, value) -> str:
    if not isinstance(value, str) or value.strip().lower() not in GESTURE_VAD:
        raise _FieldError(name, f"expected an NRC-VAD emotion word ({', '.join(sorted(GESTURE_VAD))}), got {value!r}")
    return value.strip().lower()


def _generator_inputs(gen: str, raw: dict, duration_default: float) -> dict:
    """Normalised inputs of one generator (raises _FieldError)."""
    out: dict = {}
    if gen in ("gait_net", "procedural_walk"):
        has_e, has_t = "emotion" in raw, "transition" in raw
        if has_e == has_t:
            raise _FieldError("emotion", "give exactly one of 'emotion' (4 numbers) or 'transition' "
                                         "({initial: [...], final: [...]})")
        if has_e:
            out["emotion"] = _emotion("emotion", raw["emotion"])
        else:
            t = raw["transition"]
            if not isinstance(t, dict) or set(t) != {"initial", "final"}:
                raise _FieldError("transition", f"expected a mapping with 'initial' and 'final', got {t!r}")
            out["transition"] = {"initial": _emotion("transition.initial", t["initial"]),
                                 "final": _emotion("transition.final", t["final"])}
        out["trajectory"] = _trajectory(raw.get("trajectory"))
        out["duration_s"] = _number("duration_s", raw.get("duration_s", duration_default), 1.0, 120.0)
        if gen == "gait_net" and "weights" in raw:
            out["weights"] = _choice("weights", raw["weights"], GAIT_WEIGHTS)
    elif gen == "captured_file":
        try:
            out.update(captured_file_inputs(raw))
        except CapturedFileError as exc:
            raise _FieldError(exc.field, exc.message) from None
    elif gen == "captured":
        out["clip"] = _choice("clip", raw.get("clip", "0walk_forward.txt"), CAPTURED_CLIPS)
        out["cycles"] = _integer("cycles", raw.get("cycles", 1), 1, 100)
    elif gen == "neutral_walk":
        out["n_cycles"] = _integer("n_cycles", raw.get("n_cycles", 3), 1, 50)
        out["speed"] = _number("speed", raw.get("speed", 1.0), 0.2, 3.0)
        out["base"] = _choice("base", raw.get("base", RBF_BASES[0]), RBF_BASES)
    elif gen == "rbf":
        if "theme" not in raw:
            raise _FieldError("theme", f"required; one of {list(THEMES)}")
        out["theme"] = _choice("theme", raw["theme"], THEMES)
        if "weight" not in raw:
            raise _FieldError("weight", "required (the paper uses 0.4, 0.7, 1.0, 1.3 and -0.7)")
        out["weight"] = _number("weight", raw["weight"], -3.0, 3.0)
        out["n_features"] = _integer("n_features", raw.get("n_features", 10), 1, 10)
        out["n_cycles"] = _integer("n_cycles", raw.get("n_cycles", 3), 1, 50)
        out["speed"] = _number("speed", raw.get("speed", 1.0), 0.2, 3.0)
        out["base"] = _choice("base", raw.get("base", RBF_BASES[0]), RBF_BASES)
        out["features"] = _choice("features", raw.get("features", RBF_FEATURES[0]), RBF_FEATURES)
    elif gen == "gesture_net":
        out["sentence"] = _text("sentence", raw.get("sentence"))
        out["task"] = _choice("task", raw.get("task", GESTURE_TASKS[0]), GESTURE_TASKS)
        if "emotion_label" not in raw:
            raise _FieldError("emotion_label", "required (an NRC-VAD word, e.g. proud)")
        out["emotion_label"] = _gesture_label("emotion_label", raw["emotion_label"])
        out["gender"] = _choice("gender", raw.get("gender", "female"), GENDERS)
        out["handedness"] = _choice("handedness", raw.get("handedness", "right"), HANDEDNESS)
        out["noise"] = _number("noise", raw.get("noise", 0.0), 0.0, 1.0)
        if "sentence_split" in raw:
            out["sentence_split"] = _choice("sentence_split", raw["sentence_split"], SENTENCE_SPLITS)
    elif gen == "procedural_gesture":
        if ("emotion_label" in raw) == ("vad" in raw):
            raise _FieldError("emotion_label", "give exactly one of 'emotion_label' or 'vad' ([v, a, d] in 0..1)")
        if "emotion_label" in raw:
            out["emotion_label"] = _gesture_label("emotion_label", raw["emotion_label"])
        else:
            vad = raw["vad"]
            if not isinstance(vad, (list, tuple)) or len(vad) != 3:
                raise _FieldError("vad", f"expected [valence, arousal, dominance], got {vad!r}")
            out["vad"] = [_number("vad", v, 0.0, 1.0) for v in vad]
        kind = raw.get("kind")
        out["kind"] = None if kind is None else _choice("kind", kind, ("beat", "pointing", "descriptive"))
        out["gender"] = _choice("gender", raw.get("gender", "female"), GENDERS)
        out["handedness"] = _choice("handedness", raw.get("handedness", "right"), HANDEDNESS)
        out["duration_s"] = _number("duration_s", raw.get("duration_s", 6.0), 1.0, 60.0)
    return out


def _validate_entry(i: int, raw, plan_render: RenderSettings) -> ClipEntry:
    if not isinstance(raw, dict):
        raise PlanError(f"entry {i}: expected a mapping of fields, got {type(raw).__name__}")
    entry_id = raw.get("id")
    where = f"entry {i} (id {entry_id!r})"
    try:
        if not isinstance(entry_id, (str, int)) or isinstance(entry_id, bool) or not str(entry_id).strip():
            raise _FieldError("id", f"expected a non-empty name, got {entry_id!r}")
        entry_id = str(entry_id).strip()
        gen = _choice("generator", raw.get("generator"), GENERATORS)
        modality, origins, fallbacks = GENERATORS[gen]
        given_modality = raw.get("modality", modality or MODALITIES[0])
        if modality is None:
            modality = _choice("modality", given_modality, MODALITIES)
        elif given_modality != modality:
            raise _FieldError("modality", f"generator {gen!r} makes {modality} clips, got {given_modality!r}")
        origin = _choice("origin", raw.get("origin", origins[0]), origins)
        unknown = set(raw) - COMMON_FIELDS - GENERATOR_FIELDS[gen]
        if unknown:
            name = sorted(unknown)[0]
            raise _FieldError(name, f"not a field of a {gen!r} entry (allowed: "
                                    f"{sorted(COMMON_FIELDS | GENERATOR_FIELDS[gen])})")
        fallback = raw.get("fallback")
        if fallback is not None and fallback not in fallbacks:
            raise _FieldError("fallback", f"generator {gen!r} can fall back to {list(fallbacks) or 'nothing'}, "
                                          f"got {fallback!r}")
        seed = _integer("seed", raw.get("seed", 0), 0, 2**31 - 1)
        sections = raw.get("sections", [])
        if isinstance(sections, str):
            sections = [sections]
        if not isinstance(sections, list):
            raise _FieldError("sections", f"expected a list of section types, got {sections!r}")
        sections = tuple(_choice("sections", s, SECTION_TYPES) for s in sections)
        loop_default = gen in ("rbf", "neutral_walk")
        loop = raw.get("loop", loop_default)
        if not isinstance(loop, bool):
            raise _FieldError("loop", f"expected true or false, got {loop!r}")
        pair = raw.get("pair")
        if pair is not None:
            pair = _text("pair", str(pair))
        overrides = raw.get("render") or {}
        if not isinstance(overrides, dict):
            raise _FieldError("render", f"expected a mapping of render settings, got {overrides!r}")
        try:
            render = RenderSettings.from_dict(overrides, plan_render)
        except (RenderSettingsError, TypeError) as exc:
            raise _FieldError("render", str(exc)) from None
        inputs = _generator_inputs(gen, raw, render.duration_s)
        note = raw.get("note", "")
        if not isinstance(note, str):
            raise _FieldError("note", f"expected text, got {note!r}")
    except _FieldError as exc:
        raise PlanError(f"{where}: field {exc.field!r}: {exc.message}") from None
    return ClipEntry(i, entry_id, modality, gen, origin, inputs, seed, fallback, loop, sections, pair, render, note)


def validate_plan(data, source: str = "<plan>") -> Plan:
    """A :class:`Plan` from parsed YAML/JSON, or PlanError naming the entry and field."""
    if not isinstance(data, dict):
        raise PlanError(f"{source}: a plan must be a mapping with 'name' and 'clips', got {type(data).__name__}")
    unknown = set(data) - {"name", "description", "render", "clips", "meta", "qa"}
    if unknown:
        raise PlanError(f"{source}: unknown top-level field(s) {sorted(unknown)}")
    name = data.get("name")
    if not isinstance(name, str) or not name.strip() or len(name) > 100:
        raise PlanError(f"{source}: field 'name': expected a short non-empty name, got {name!r}")
    try:
        render = RenderSettings.from_dict(data.get("render") or {})
    except (RenderSettingsError, TypeError) as exc:
        raise PlanError(f"{source}: field 'render': {exc}") from None
    clips = data.get("clips")
    if not isinstance(clips, list) or not clips:
        raise PlanError(f"{source}: field 'clips': expected a non-empty list of entries")
    entries = [_validate_entry(i, raw, render) for i, raw in enumerate(clips, start=1)]
    seen: dict[str, ClipEntry] = {}
    for e in entries:
        if e.id in seen:
            raise PlanError(f"{e.where}: field 'id': duplicate of entry {seen[e.id].index}")
        seen[e.id] = e
    for e in entries:
        if e.pair is not None and e.pair not in seen:
            raise PlanError(f"{e.where}: field 'pair': no entry with id {e.pair!r} in the plan")
    # Identical inputs would render the same file twice under two ids.
    keys: dict[str, ClipEntry] = {}
    for e in entries:
        key = _canonical({"g": e.generator, "i": e.inputs, "s": e.seed, "o": e.origin, "r": e.render.content_dict()})
        if key in keys:
            raise PlanError(f"{e.where}: field 'seed': same generator, inputs and seed as entry {keys[key].index} "
                            f"(id {keys[key].id!r}); change the seed to get a different clip")
        keys[key] = e
    description = data.get("description", "")
    qa = data.get("qa") or {}
    try:
        resolve_thresholds(qa)
    except QAThresholdError as exc:
        raise PlanError(f"{source}: {exc}") from None
    return Plan(name.strip(), str(description), render, tuple(entries), source, dict(data.get("meta") or {}),
                dict(qa))


def plan_path(name_or_path: str | Path) -> Path:
    """A built-in plan name (``demo``, ``seed000``...) or a file path -> the file."""
    p = Path(name_or_path)
    if p.suffix.lower() in (".yaml", ".yml", ".json") or p.exists():
        if not p.is_file():
            raise PlanError(f"{p}: plan file not found")
        return p
    for ext in (".yaml", ".yml", ".json"):
        candidate = PLANS_DIR / f"{name_or_path}{ext}"
        if candidate.is_file():
            return candidate
    known = sorted(x.stem for x in PLANS_DIR.glob("*.y*ml"))
    raise PlanError(f"no plan {str(name_or_path)!r}: not a file and not a built-in plan ({', '.join(known)})")


def load_plan(name_or_path: str | Path) -> Plan:
    """Read and validate a plan file or built-in plan."""
    path = plan_path(name_or_path)
    text = path.read_text(encoding="utf-8")
    try:
        if path.suffix.lower() == ".json":
            data = json.loads(text)
        else:
            data = yaml.safe_load(text)
    except Exception as exc:  # noqa: BLE001 - json.JSONDecodeError / yaml.YAMLError carry the line and column
        raise PlanError(f"{path}: cannot parse ({exc})") from None
    try:
        return validate_plan(data, str(path))
    except PlanError as exc:
        msg = str(exc)
        raise PlanError(msg if msg.startswith(str(path)) else f"{path}: {msg}") from None


def builtin_plans() -> list[str]:
    return sorted(x.stem for x in PLANS_DIR.glob("*.yaml"))


# ---- hashing -----------------------------------------------------------------------------------
def _canonical(obj) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), default=str)


def clip_hash(entry: ClipEntry, generator: str, generator_version: str) -> str:
    """16 hex digits of SHA-256 over the generator actually used, its version, the normalised inputs, origin,
    seed, the render settings that change the pictures and the renderer's version. The entry id, plan name,
    sections, notes and the WebM option are not part of it."""
    payload = {"generator": generator, "version": generator_version, "inputs": entry.inputs, "seed": entry.seed,
               "origin": entry.origin, "modality": entry.modality, "render": entry.render.content_dict(),
               "renderer": RENDERER_VERSION}
    return hashlib.sha256(_canonical(payload).encode()).hexdigest()[:16]


# ---- catalogue fields --------------------------------------------------------------------------
def intent_fields(entry: ClipEntry) -> dict:
    """The clips.csv intent columns of an entry (blank = None): emotion vectors, gesture label and VAD,
    RBF theme/weight/feature count. Source motions carry no intended emotion."""
    out = {k: None for k in (*GAIT_EMOTIONS, *FINAL_EMOTION_COLUMNS, "emotion_label", *VAD_DIMENSIONS, "theme",
                             "weight", "n_features")}
    inp = entry.inputs
    if "emotion" in inp:
        out.update(zip(GAIT_EMOTIONS, inp["emotion"]))
    elif "transition" in inp:
        out.update(zip(GAIT_EMOTIONS, inp["transition"]["initial"]))
        out.update(zip(FINAL_EMOTION_COLUMNS, inp["transition"]["final"]))
    if entry.modality == "gesture":
        if "emotion_label" in inp:
            out["emotion_label"] = inp["emotion_label"]
            out.update(zip(VAD_DIMENSIONS, GESTURE_VAD[inp["emotion_label"]]))
        elif "vad" in inp:
            out.update(zip(VAD_DIMENSIONS, inp["vad"]))
    if entry.generator == "rbf":
        out["theme"], out["weight"], out["n_features"] = inp["theme"], inp["weight"], inp["n_features"]
    if entry.generator == "neutral_walk":
        # The neutral base walk (seed 004's input sequence): theme "neutral", no features applied.
        out["theme"], out["weight"], out["n_features"] = NEUTRAL_THEME, 0.0, 0
    return out
