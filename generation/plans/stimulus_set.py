"""A stimulus set as a researcher describes it (one generator, its conditions, variants per condition, render
settings) turned into a plan (:mod:`generation.plans.schema`): the plan data, its YAML, and the expected render time.

The YAML is an ordinary plan file: ``manage.py generate_clips --plan FILE`` renders it, and the admin's stimulus
page renders the very same file, so the command line and the browser make the same clips (same ids).

Conditions are one line each, read by the fields the generator declares in the registry
(:mod:`generation.plans.generators`):

- ``emotion`` (walks): ``happy`` or a mixture ``happy 0.8 + neutral 0.2``; with ``transition`` also
  ``happy to sad 0.8 + neutral 0.2`` (initial to final);
- ``emotion_label`` (gestures): an NRC-VAD word, e.g. ``afraid``;
- ``theme`` and ``weight`` (RBF styles): ``tired 0.7`` (negative weights invert the style);
- ``clip`` (captured takes): a take's file name, e.g. ``turn_left0.txt``; ``file`` (imported capture): a path;
- any generator: a YAML mapping of its fields, e.g. ``{emotion: happy, trajectory: straight}``.

A generator with no condition field (the neutral input walk) takes no lines and makes ``variants`` clips.
Variant ``k`` of a condition gets the next seed; a walk whose lines and shared fields give no ``trajectory`` walks
path ``k`` of :data:`VARIANT_PATHS` (cycling), so variants differ in path as well as in seed.
"""
from __future__ import annotations

import json
import re
import statistics
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from protocol.titles import clip_titles
from protocol.vocabulary import GAIT_EMOTIONS

from .generators import get_generator
from .schema import Plan, PlanError, builtin_plans, intent_fields, validate_plan

CONDITION_FIELDS = ("transition", "emotion", "emotion_label", "theme", "clip", "file")
"""Plan fields a condition line can fill, in the order they are tried."""

CONDITION_EXAMPLES = {"emotion": "happy 0.8 + neutral 0.2", "transition": "happy to sad 0.8 + neutral 0.2",
                      "emotion_label": "afraid", "theme": "tired 0.7", "clip": "turn_left0.txt",
                      "file": "mocap/walk_happy_07.npz"}
"""An example condition line for each condition field (the stimulus page's help)."""


def condition_examples(generator: str) -> list[str]:
    """Example condition lines of a generator ([] when it takes none)."""
    fields = get_generator(generator).fields
    if "file" in fields:
        return [CONDITION_EXAMPLES["file"]]
    return [CONDITION_EXAMPLES[f] for f in CONDITION_FIELDS if f in fields]

VARIANT_PATHS = (
    {"kind": "curved", "radius_m": 3.0, "angle_deg": 330, "length_m": 14},
    {"kind": "sharp_turn", "angle_deg": 150, "length_m": 14},
    {"kind": "curved", "radius_m": 3.0, "angle_deg": -330, "length_m": 14},
    {"kind": "sharp_turn", "angle_deg": -150, "length_m": 14},
    {"kind": "straight", "length_m": 14},
)
"""The paths of walk variants (those of the seed 000 plan, then a straight walk), metres and degrees."""

MAX_CLIPS = 500
"""Most clips one stimulus set may plan."""

RENDER_SECONDS_PER_MEGAPIXEL_FRAME = {"gait": 0.028, "gesture": 0.053}
"""Default cost of rendering and encoding one frame of one megapixel, seconds, when no clip was rendered here yet:
docs/benchmarks/render.md (640x480 with FXAA: walks 116 frames/s, seated gestures 61 frames/s per process)."""
SECONDS_PER_CLIP = 3.0
"""Default fixed cost of one clip (making the motion, the quality checks), seconds."""

NAME_RE = re.compile(r"^[a-z0-9][a-z0-9_-]{0,59}$")


class StimulusSetError(ValueError):
    """A stimulus set that cannot become a plan: ``field`` names the form field, the message says why."""

    def __init__(self, field_name: str, message: str):
        super().__init__(message)
        self.field = field_name


@dataclass
class StimulusSet:
    """What the researcher chose.

    Attributes:
        name: the plan name (lower-case letters, digits, ``-`` and ``_``); the catalogue's ``plan`` of its clips.
        generator: a registered generator.
        conditions: condition lines (see the module docstring).
        variants: clips per condition (1..50).
        seed: the first seed; every clip gets its own.
        shared: plan fields every entry gets (e.g. ``{"weights": "real"}``, ``{"sentence": ...}``).
        render: plan render settings (width, height, fps, duration_s, camera, body...).
        sections: section-type hints of every clip.
        fallback: name the generator's first fallback (rendered, and recorded as such, while it is unavailable).
        description: the plan's description.
    """

    name: str
    generator: str
    conditions: list[str] = field(default_factory=list)
    variants: int = 1
    seed: int = 1
    shared: dict = field(default_factory=dict)
    render: dict = field(default_factory=dict)
    sections: list[str] = field(default_factory=list)
    fallback: bool = True
    description: str = ""


def _mix(text: str, where: str) -> dict:
    """``happy 0.8 + neutral 0.2`` (or ``happy``) -> {"happy": 0.8, "neutral": 0.2}."""
    out: dict[str, float] = {}
    for part in text.split("+"):
        words = part.split()
        if not words or words[0] not in GAIT_EMOTIONS or len(words) > 2:
            raise StimulusSetError("conditions", f"{where}: {part.strip()!r} is not an emotion "
                                                 f"({', '.join(GAIT_EMOTIONS)}) with an optional share")
        try:
            share = float(words[1]) if len(words) == 2 else 1.0
        except ValueError:
            raise StimulusSetError("conditions", f"{where}: {words[1]!r} is not a number") from None
        if share <= 0:
            raise StimulusSetError("conditions", f"{where}: a share must be positive, got {words[1]!r}")
        out[words[0]] = out.get(words[0], 0.0) + share
    return out


def parse_condition(generator: str, line: str, where: str = "condition") -> dict:
    """One condition line -> the plan fields it sets for ``generator`` (StimulusSetError names the line)."""
    spec = get_generator(generator)
    line = line.strip()
    if line.startswith("{"):
        try:
            data = yaml.safe_load(line)
        except yaml.YAMLError as exc:
            raise StimulusSetError("conditions", f"{where}: not a YAML mapping ({exc})") from None
        if not isinstance(data, dict):
            raise StimulusSetError("conditions", f"{where}: expected a mapping of plan fields")
        return data
    fields = spec.fields
    if "transition" in fields and re.search(r"\bto\b", line):
        initial, final = re.split(r"\bto\b", line, maxsplit=1)
        return {"transition": {"initial": _mix(initial, where), "final": _mix(final, where)}}
    if "emotion" in fields and "file" not in fields:
        return {"emotion": _mix(line, where)}
    if "theme" in fields:
        words = line.split()
        try:
            return {"theme": words[0], "weight": float(words[1])} if len(words) == 2 else {"theme": line}
        except ValueError:
            raise StimulusSetError("conditions", f"{where}: expected a theme and a weight, e.g. 'tired 0.7'") from None
    for name in ("emotion_label", "clip", "file"):
        if name in fields:
            return {name: line}
    raise StimulusSetError("conditions", f"{where}: generator {generator!r} takes no condition line; write its "
                                         f"fields as a mapping, e.g. {{{', '.join(sorted(fields)[:2])}: ...}}")


def takes_conditions(generator: str) -> bool:
    """Whether the generator has a field a condition line fills (else its clips differ only by seed)."""
    return bool(set(CONDITION_FIELDS) & get_generator(generator).fields)


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")[:40] or "clip"


def plan_data(s: StimulusSet) -> dict:
    """The plan (a dict ready for YAML) of a stimulus set; StimulusSetError names the form field at fault."""
    if not NAME_RE.match(s.name or ""):
        raise StimulusSetError("name", "use 1-60 lower-case letters, digits, '-' or '_', starting with a letter or "
                                       "digit")
    if s.name in builtin_plans():
        raise StimulusSetError("name", f"{s.name!r} is a built-in plan: render it as it is, or pick another name")
    try:
        spec = get_generator(s.generator)
    except KeyError as exc:
        raise StimulusSetError("generator", str(exc)) from None
    if not 1 <= s.variants <= 50:
        raise StimulusSetError("variants", "between 1 and 50 clips per condition")
    lines = [ln.strip() for ln in s.conditions if ln.strip() and not ln.strip().startswith("#")]
    if lines:
        conditions = [(_slug(ln), parse_condition(s.generator, ln, f"line {i} ({ln!r})"))
                      for i, ln in enumerate(lines, start=1)]
    elif takes_conditions(s.generator):
        raise StimulusSetError("conditions", "give at least one condition, one per line")
    else:
        conditions = [(_slug(s.generator), {})]
    if len(conditions) * s.variants > MAX_CLIPS:
        raise StimulusSetError("variants", f"{len(conditions) * s.variants} clips: at most {MAX_CLIPS} per set")
    walks = "trajectory" in spec.fields
    entries, seed, used = [], s.seed, set()
    for slug, fields in conditions:
        base = slug
        n = 2
        while slug in used:
            slug, n = f"{base}_{n}", n + 1
        used.add(slug)
        for k in range(1, s.variants + 1):
            entry = {"id": f"{slug}_v{k}" if s.variants > 1 else slug, "generator": s.generator}
            if s.fallback and spec.fallbacks:
                entry["fallback"] = spec.fallbacks[0]
            entry.update(s.shared)
            entry.update(fields)
            if walks and "trajectory" not in entry:
                entry["trajectory"] = dict(VARIANT_PATHS[(k - 1) % len(VARIANT_PATHS)])
            entry["seed"] = seed
            if s.sections:
                entry["sections"] = list(s.sections)
            entries.append(entry)
            seed += 1
    data = {"name": s.name, "description": s.description or f"stimulus set {s.name} ({s.generator})",
            "render": dict(s.render), "clips": entries}
    return data


def build_plan(s: StimulusSet) -> tuple[dict, Plan]:
    """(plan data, validated Plan); StimulusSetError names the form field (a plan error: ``conditions``)."""
    data = plan_data(s)
    try:
        return data, validate_plan(data, f"stimulus set {s.name}")
    except PlanError as exc:
        raise StimulusSetError("render" if "field 'render'" in str(exc) else "conditions", str(exc)) from None


class _PlainDumper(yaml.SafeDumper):
    """YAML without anchors and aliases (a plan a researcher reads and edits)."""

    def ignore_aliases(self, data) -> bool:
        return True


def plan_yaml(data: dict) -> str:
    """The plan as YAML, headed by a comment saying how to render it."""
    head = (f"# Stimulus set {data['name']}: render with\n"
            f"#   python manage.py generate_clips --plan {data['name']}.yaml\n")
    return head + yaml.dump(data, Dumper=_PlainDumper, sort_keys=False, allow_unicode=True)


@dataclass(frozen=True)
class RenderEstimate:
    """Expected render time of a plan: ``seconds`` in all, ``frames`` to render, and ``basis`` (what it rests on:
    clips rendered here, or the benchmark)."""

    seconds: float
    frames: int
    basis: str


def estimate_render(plan: Plan, past_records: list[dict] = (), workers: int = 1) -> RenderEstimate:
    """Expected wall time of rendering ``plan`` on one worker (``workers`` divides it).

    ``past_records``: clip records rendered on this machine (their ``metadata.timing_s.total``, ``n_frames`` and
    ``render`` size); with at least 3 of a modality, its cost per megapixel-frame is their median (generation and
    quality checks included, so no fixed cost is added); else the benchmark's figure plus SECONDS_PER_CLIP.
    """
    measured: dict[str, list[float]] = {}
    for rec in past_records:
        meta = rec.get("metadata") or {}
        total = (meta.get("timing_s") or {}).get("total")
        n_frames, render = meta.get("n_frames"), meta.get("render") or {}
        try:
            mp_frames = n_frames * render["width"] * render["height"] / 1e6
            if total and mp_frames > 0:
                measured.setdefault(rec.get("modality", "gait"), []).append(float(total) / mp_frames)
        except (KeyError, TypeError):
            continue
    seconds, frames, basis = 0.0, 0, set()
    for e in plan.entries:
        duration = float(e.inputs["duration_s"]) if "duration_s" in e.inputs else e.render.duration_s
        n = int(round(duration * e.render.fps))
        mp_frames = n * e.render.width * e.render.height / 1e6
        frames += n
        past = measured.get(e.modality, [])
        if len(past) >= 3:
            seconds += statistics.median(past) * mp_frames
            basis.add(f"{len(past)} {e.modality} clips rendered here")
        else:
            seconds += RENDER_SECONDS_PER_MEGAPIXEL_FRAME.get(e.modality, 0.05) * mp_frames + SECONDS_PER_CLIP
            basis.add(f"the {e.modality} render benchmark")
    return RenderEstimate(seconds / max(1, workers), frames, "; ".join(sorted(basis)))


def read_records(records_dir: str | Path, limit: int = 400) -> list[dict]:
    """The newest ``limit`` clip records of a records folder (for :func:`estimate_render`); unreadable ones
    skipped."""
    folder = Path(records_dir)
    if not folder.is_dir():
        return []
    files = sorted(folder.glob("*.json"), key=lambda p: p.stat().st_mtime, reverse=True)[:limit]
    out = []
    for f in files:
        try:
            out.append(json.loads(f.read_text(encoding="utf-8")))
        except (OSError, ValueError):
            continue
    return out


def planned_titles(plan: Plan) -> list[tuple[str, str]]:
    """(entry id, the title its clip will get) for every entry of ``plan`` (protocol.titles, from the entry's
    intent and inputs; a clip rendered by a fallback says so in its catalogued title)."""
    rows = [{"clip_id": e.id, "modality": e.modality, "origin": e.origin, "plan": plan.name, **intent_fields(e),
             "metadata": {"generator": e.generator, "seed": e.seed, "entry_id": e.id, "inputs": e.inputs.as_dict()}}
            for e in plan.entries]
    titles = clip_titles(rows)
    return [(e.id, titles[e.id]) for e in plan.entries]
