"""Stimulus plans: which clips to make, from which generator and inputs; validation and content hashes.

A plan is a YAML (or JSON) file::

    name: demo
    description: ...
    render: {width: 640, height: 480, fps: 30, duration_s: 10}   # defaults for every clip
    bodies: [female, male]   # optional: every entry once per human body preset (an entry's own `bodies` wins)
    qa: {foot_skate_cm_s: 5, jerk: null}   # optional: thresholds (protocol.vocabulary.QA_THRESHOLDS; null = off)
    clips:
      - id: happy_straight          # unique within the plan; never shown to participants
        modality: gait              # gait | gesture
        generator: gait_net         # a registered generator (generation.plans.generators, docs/generators.md)
        fallback: procedural_walk   # optional: used (and recorded) while gait_net is unavailable
        origin: generated           # generated | source
        emotion: [1, 0, 0, 0]       # happy, sad, angry, neutral (l1-normalised)
        trajectory: {kind: straight, length_m: 12}
        weights: real               # optional, gait_net: real (default, trained on real capture) | procedural
        seed: 1
        sections: [emotion_choice]  # optional hint for the study set-up
        render: {camera: tracking}  # optional per-clip render overrides

An imported motion-capture file is a source clip: ``generator: captured_file, file: path.npz|.bvh`` with optional
labels (generation/plans/generators/captured_file.py); a generated entry links to it with ``pair``.

Each generator declares its own fields, defaults and checks once, in the generator registry; an entry's ``inputs``
are that generator's typed inputs (:class:`generation.plans.generators.PlanInputs`).

Entries are checked before anything is rendered; :class:`PlanError` names the entry (1-based), its id and
the field: ``entry 3 (id 'x'): field 'weight': expected a number, got 'abc'``.

Every clip's file name is a content hash of (normalised entry inputs, the generator actually used and its
version, render settings), so names reveal nothing about the condition and an unchanged clip is never
rendered twice (:func:`clip_hash`).
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from generation.quality.checks import QAThresholdError, resolve_thresholds
from generation.render.settings import RENDERER_VERSION, RenderSettings, RenderSettingsError
from protocol.vocabulary import MODALITIES, SECTION_TYPES

from .generators import InputContext, PlanInputs, generator_names, get_generator
from .generators.fields import FieldError, choice, integer, text

PLANS_DIR = Path(__file__).resolve().parent
COMMON_FIELDS = {"id", "modality", "generator", "fallback", "origin", "seed", "sections", "render", "loop", "pair",
                 "note"}


class PlanError(ValueError):
    """A plan that cannot be used; the message names the file, the entry and the field."""


@dataclass(frozen=True)
class ClipEntry:
    """One validated plan entry.

    Attributes:
        index: 1-based position in the plan's ``clips`` list.
        id: the entry's id (unique in the plan; a researcher's label, never shown to participants).
        modality, generator, origin: as in the plan (generator is the requested one; see ``fallback``).
        inputs: the generator's typed inputs (numbers as floats, emotions l1-normalised; a read-only mapping of the
            normalised plan fields for hashes and records).
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
    inputs: PlanInputs
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

    def with_generator(self, generator: str, inputs: PlanInputs) -> ClipEntry:
        """The same entry made by another generator (a fallback) from ``inputs``."""
        return ClipEntry(self.index, self.id, self.modality, generator, self.origin, inputs, self.seed, None,
                         self.loop, self.sections, self.pair, self.render, self.note)


@dataclass(frozen=True)
class Plan:
    name: str
    description: str
    render: RenderSettings
    entries: tuple[ClipEntry, ...]
    source: str = ""
    meta: dict = field(default_factory=dict)
    qa: dict = field(default_factory=dict)  # quality thresholds overriding protocol.vocabulary.QA_THRESHOLDS

    def entry(self, entry_id: str) -> ClipEntry:
        for e in self.entries:
            if e.id == entry_id:
                return e
        raise KeyError(f"plan {self.name!r} has no entry {entry_id!r}")


def _validate_entry(i: int, raw, plan_render: RenderSettings) -> ClipEntry:
    if not isinstance(raw, dict):
        raise PlanError(f"entry {i}: expected a mapping of fields, got {type(raw).__name__}")
    entry_id = raw.get("id")
    where = f"entry {i} (id {entry_id!r})"
    try:
        if not isinstance(entry_id, (str, int)) or isinstance(entry_id, bool) or not str(entry_id).strip():
            raise FieldError("id", f"expected a non-empty name, got {entry_id!r}")
        entry_id = str(entry_id).strip()
        gen = choice("generator", raw.get("generator"), generator_names())
        spec = get_generator(gen)
        modality, origins, fallbacks = spec.modality, spec.origins, spec.fallbacks
        given_modality = raw.get("modality", modality or MODALITIES[0])
        if modality is None:
            modality = choice("modality", given_modality, MODALITIES)
        elif given_modality != modality:
            raise FieldError("modality", f"generator {gen!r} makes {modality} clips, got {given_modality!r}")
        origin = choice("origin", raw.get("origin", origins[0]), origins)
        unknown = set(raw) - COMMON_FIELDS - spec.fields
        if unknown:
            name = sorted(unknown)[0]
            raise FieldError(name, f"not a field of a {gen!r} entry (allowed: "
                                   f"{sorted(COMMON_FIELDS | spec.fields)})")
        fallback = raw.get("fallback")
        if fallback is not None and fallback not in fallbacks:
            raise FieldError("fallback", f"generator {gen!r} can fall back to {list(fallbacks) or 'nothing'}, "
                                          f"got {fallback!r}")
        seed = integer("seed", raw.get("seed", 0), 0, 2**31 - 1)
        sections = raw.get("sections", [])
        if isinstance(sections, str):
            sections = [sections]
        if not isinstance(sections, list):
            raise FieldError("sections", f"expected a list of section types, got {sections!r}")
        sections = tuple(choice("sections", s, SECTION_TYPES) for s in sections)
        loop = raw.get("loop", spec.loops)
        if not isinstance(loop, bool):
            raise FieldError("loop", f"expected true or false, got {loop!r}")
        pair = raw.get("pair")
        if pair is not None:
            pair = text("pair", str(pair))
        overrides = raw.get("render") or {}
        if not isinstance(overrides, dict):
            raise FieldError("render", f"expected a mapping of render settings, got {overrides!r}")
        try:
            render = RenderSettings.from_dict(overrides, plan_render)
        except (RenderSettingsError, TypeError) as exc:
            raise FieldError("render", str(exc)) from None
        inputs = spec.inputs.parse(raw, InputContext(render.duration_s, modality))
        note = raw.get("note", "")
        if not isinstance(note, str):
            raise FieldError("note", f"expected text, got {note!r}")
    except FieldError as exc:
        raise PlanError(f"{where}: field {exc.field!r}: {exc.message}") from None
    return ClipEntry(i, entry_id, modality, gen, origin, inputs, seed, fallback, loop, sections, pair, render, note)


def cross_bodies(clips: list, plan_bodies, source: str) -> list:
    """Raw plan entries crossed with human bodies: an entry with ``bodies: [female, male]`` (or, without its own,
    the plan's top-level ``bodies``) becomes one entry per body preset, ``id`` suffixed with ``-<preset>`` and
    ``render: {body: human, body_preset: <preset>}``; other entries stay as they are. PlanError for a list that is
    not one of distinct names (an unknown preset is refused with the entry's render settings)."""
    out = []
    for i, raw in enumerate(clips, start=1):
        bodies = raw.get("bodies", plan_bodies) if isinstance(raw, dict) else None
        if bodies is None:
            out.append(raw)
            continue
        if (not isinstance(bodies, list) or not bodies or len(set(map(str, bodies))) != len(bodies)
                or not all(isinstance(b, str) and b.strip() for b in bodies)):
            raise PlanError(f"{source}: entry {i}: field 'bodies': expected a list of distinct body preset names, "
                            f"got {bodies!r}")
        base = {k: v for k, v in raw.items() if k != "bodies"}
        for body in bodies:
            render = {**(base.get("render") or {}), "body": "human", "body_preset": body.strip()}
            out.append({**base, "id": f"{base.get('id')}-{body.strip()}", "render": render})
    return out


def validate_plan(data, source: str = "<plan>") -> Plan:
    """A :class:`Plan` from parsed YAML/JSON, or PlanError naming the entry and field."""
    if not isinstance(data, dict):
        raise PlanError(f"{source}: a plan must be a mapping with 'name' and 'clips', got {type(data).__name__}")
    unknown = set(data) - {"name", "description", "render", "clips", "meta", "qa", "bodies"}
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
    clips = cross_bodies(clips, data.get("bodies"), source)
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
        key = _canonical({"g": e.generator, "i": e.inputs.as_dict(), "s": e.seed, "o": e.origin,
                          "r": e.render.content_dict()})
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
    payload = {"generator": generator, "version": generator_version, "inputs": entry.inputs.as_dict(),
               "seed": entry.seed,
               "origin": entry.origin, "modality": entry.modality, "render": entry.render.content_dict(),
               "renderer": RENDERER_VERSION}
    return hashlib.sha256(_canonical(payload).encode()).hexdigest()[:16]


# ---- catalogue fields --------------------------------------------------------------------------
def intent_fields(entry: ClipEntry) -> dict:
    """The clips.csv intent columns of an entry (blank = None): emotion vectors, gesture label and VAD, RBF
    theme/weight/feature count, as its generator's inputs declare them (``PlanInputs.intent``)."""
    return entry.inputs.intent(entry.modality)
