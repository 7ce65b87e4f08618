"""Section pools and options, checked against the study protocol. No Django import: the admin's SectionForm,
``Section.clean`` and the catalogue's ``pool_queryset`` share it, and none of them needs the database to know
whether a pool or an option is well formed.

A pool is a JSON object of catalogue filters: ``field`` or ``field__lookup`` -> value (a list without a lookup
means ``in``), plus two boolean shorthands, ``transition`` (the clip has a final emotion) and ``rbf`` (the clip
has a theme), and the switches ``include_flagged`` (true: clips whose quality record failed a check, ``qa_flag``, are
in the pool too; every flagged clip is left out otherwise), ``keep_advisory`` (true: a clip that failed only advisory
checks, ``protocol.vocabulary.QA_ADVISORY_CHECKS``, stays in) and ``observer_advisory`` (true: the automatic
observer's flag is disregarded too). A naturalness section may add ``generated`` and ``source``
sub-pools (filters of the same kind) for its two halves. Options are type-specific (``SECTION_OPTIONS``).
"""
from __future__ import annotations

import math
from typing import NamedTuple

from .norming import NORMING_OPTION
from .section_types import find_section_type, is_page_type, section_type_names
from .section_types.checks import count_error as _count_error
from .section_types.checks import is_int as _is_int
from .section_types.gesture_emotion import DEFAULT_OPTIONS as DEFAULT_GESTURE_OPTIONS  # noqa: F401 - the editor reads it here
from .section_types.naturalness import HALVES
from .section_types.registry import TypeMapView
from .vocabulary import (
    CLIP_MODALITIES,
    CLIP_THEMES,
    FINAL_EMOTION_COLUMNS,
    GAIT_EMOTIONS,
    GESTURE_EMOTIONS,
    ORIGINS,
    QA_ADVISORY_CHECKS,
    QA_CHECKS,
    SECTION_MODALITY,
    SECTION_TYPES,
    VAD_DIMENSIONS,
    answer_values,
)

TEXT_FIELDS: dict[str, tuple[str, ...] | None] = {
    "clip_id": None, "plan": None, "modality": CLIP_MODALITIES, "origin": ORIGINS, "emotion_label": GESTURE_EMOTIONS,
    "theme": CLIP_THEMES, "sections": SECTION_TYPES, "body": None}
"""Catalogue text fields a pool may filter on -> the protocol vocabulary of their values (None: free text)."""

NUMBER_FIELDS = (*GAIT_EMOTIONS, *FINAL_EMOTION_COLUMNS, *VAD_DIMENSIONS, "weight", "duration_s")
INTEGER_FIELDS = ("n_features",)
POOL_FIELDS = frozenset((*TEXT_FIELDS, *NUMBER_FIELDS, *INTEGER_FIELDS))
TEXT_LOOKUPS = ("", "in", "startswith", "contains")
NUMBER_LOOKUPS = ("", "in", "lt", "lte", "gt", "gte", "isnull")
FLAGS = ("transition", "rbf")
INCLUDE_FLAGGED = "include_flagged"
"""Pool switch: also draw clips that failed any quality check (``Clip.qa_flag`` not empty); off, every flagged clip is
left out unless one of the two switches below names its checks."""
KEEP_ADVISORY = "keep_advisory"
"""Pool switch: a clip that failed only advisory checks (``protocol.vocabulary.QA_ADVISORY_CHECKS``: realism, which
also flags about 10 % of real takes) stays in; any other failed check still keeps it out."""
OBSERVER_ADVISORY = "observer_advisory"
"""Pool switch: the automatic observer's flag does not keep a clip out (people judge the clip: a norming section's
candidates are rated precisely because an observer's reading is a weak judge); other failed checks still do."""
SWITCHES = (INCLUDE_FLAGGED, KEEP_ADVISORY, OBSERVER_ADVISORY)
NORMS_RULE = "norms"
"""Pool rule admitting only clips whose per-clip norms pass: ``{"from": <study slug or clip_norms.csv path>,
"min_ratings": 10, "min_intended_share": 0.5, "max_entropy_bits": 1.5}`` (studyapp.data.norms_rule applies it)."""
NORMS_FIELDS = {"from": None, "min_ratings": (int, 1, 1_000_000), "min_intended_share": (float, 0.0, 1.0),
                "max_entropy_bits": (float, 0.0, 64.0)}
"""Fields of the norms rule -> (type, lowest, highest); ``from`` is text."""
OBSERVER_CHECK = "observer"


def kept_checks(pool: dict | None, normed: bool = False) -> tuple[str, ...]:
    """The quality checks (``QA_CHECKS`` order) whose failure does not keep a clip out of ``pool``: all of them with
    ``include_flagged``; else the advisory ones with ``keep_advisory`` and the observer's with ``observer_advisory``
    or, ``normed``, for a clip with norms under the pool's norms rule (people's ratings outrank the observer's
    reading); none otherwise, so an unticked "include flagged" keeps every flagged clip out."""
    pool = pool if isinstance(pool, dict) else {}
    if pool.get(INCLUDE_FLAGGED) is True:
        return QA_CHECKS
    kept = set(QA_ADVISORY_CHECKS) if pool.get(KEEP_ADVISORY) is True else set()
    if pool.get(OBSERVER_ADVISORY) is True or normed:
        kept.add(OBSERVER_CHECK)
    return tuple(c for c in QA_CHECKS if c in kept)


def blocking_checks(flag: str | None, pool: dict | None, normed: bool = False) -> list[str]:
    """The failed checks of a clip's ``qa_flag`` (names joined by ';') that keep it out of ``pool`` ([] = in)."""
    kept = kept_checks(pool, normed)
    return [c for c in (flag or "").split(";") if c and c not in kept]


SUB_POOLS = HALVES
"""Sub-pools a section type may declare (``SectionType.sub_pools``, naturalness): extra filters for its generated
and its source clips."""

SECTION_OPTIONS = TypeMapView(lambda t: t.option_keys, keep=lambda t: bool(t.options), pages=True)
"""section_type -> the option keys it understands besides COMMON_OPTIONS (a live view of the section-type
registry; a page type's, e.g. break_page's ``wait_seconds``, too: a page takes only its own)."""

PLAYER_CONTROLS = ("replay-only", "full", "none")
"""``controls`` option: play/pause and replay only (no seek bar, no speed menu; the default), the browser's full
controls (seeking and speed allowed), or none (the clip plays by itself; seeking blocked)."""
DEFAULT_PLAYER_CONTROLS = "replay-only"
PLAYER_OPTIONS = ("controls", "max_replays")
"""The clip player of every section type: its controls and how often a clip may be replayed (absent or null:
unlimited; 0: played once)."""
MAX_REPLAYS_LIMIT = 100

COMMON_OPTIONS = ("attention_checks", "practice", "practice_clip", *PLAYER_OPTIONS)
"""Options of every section type (studyapp.participant.trial_extras): attention checks, a practice item, the clip
player."""
ATTENTION_KEYS = ("count", "answer", "positions", "question", "clip")
"""``clip``: the clip_id of a dedicated check clip, one no participant rates (studyapp.participant.trial_extras)."""


class SectionError(NamedTuple):
    """One problem of a section: the Section ``field`` it is about (section_type, pool, options or
    clips_per_participant), the ``message``, and the ``keys`` of that field's JSON the message is about, dotted into
    a sub-pool or an option object (``"weight__gte"``, ``"generated.weight__gte"``, ``"attention_checks.answer"``;
    empty for the field as a whole)."""

    field: str
    message: str
    keys: tuple[str, ...] = ()


Found = list[tuple[tuple[str, ...], str]]
"""(keys, message) pairs: the problems of one field's JSON, each with the keys it is about."""


def _messages(found: Found) -> list[str]:
    return [message for _, message in found]


def _at(key: str, messages: list[str]) -> Found:
    return [((key,), message) for message in messages]


class PoolError(ValueError):
    """A pool or options that cannot be used; ``errors`` maps a Section field to its messages."""

    def __init__(self, errors: dict[str, list[str]]):
        self.errors = errors
        super().__init__("; ".join(f"{field}: {msg}" for field, msgs in errors.items() for msg in msgs))


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _value_error(key: str, name: str, lookup: str, value) -> str | None:
    """What is wrong with one (non-list) value of filter ``key``, or None."""
    if lookup == "isnull":
        return None if isinstance(value, bool) else f"{key!r} takes true or false, got {value!r}"
    if name in TEXT_FIELDS:
        if not isinstance(value, str):
            return f"{key!r} takes text, got {value!r}"
        vocabulary = TEXT_FIELDS[name]
        if vocabulary is None or lookup == "startswith" or value == "":
            return None
        parts = value.split(",") if name == "sections" and lookup == "" else [value]
        bad = [p for p in parts if p not in vocabulary]
        return f"{key!r}: {bad[0]!r} is not one of {', '.join(vocabulary)}" if bad else None
    if name in INTEGER_FIELDS:
        ok = _is_int(value) and -2**63 <= value < 2**63          # the database's integer
        return None if ok else f"{key!r} takes an integer (64-bit), got {value!r}"
    ok = _is_number(value) and math.isfinite(value)               # JSON may carry NaN / Infinity
    return None if ok else f"{key!r} takes a finite number, got {value!r}"


def _filter_errors(key: str, value) -> list[str]:
    """The problems of one pool filter ``key: value`` (each about ``key``)."""
    name, _, lookup = key.partition("__")
    if name not in POOL_FIELDS:
        return [f"unknown filter {key!r}: {name!r} is not a catalogue field (fields: {', '.join(sorted(POOL_FIELDS))}; "
                f"shorthands: {', '.join(FLAGS)})"]
    lookups = TEXT_LOOKUPS if name in TEXT_FIELDS else NUMBER_LOOKUPS
    if lookup not in lookups:
        return [f"unknown lookup in {key!r}: {name} takes {', '.join(x or '(exact)' for x in lookups)}"]
    if isinstance(value, list) or lookup == "in":
        if lookup not in ("", "in") or not isinstance(value, list) or not value:
            return [f"{key!r} takes a non-empty list" if lookup == "in" else f"{key!r} takes one value, not a list"]
        return [msg for item in value if (msg := _value_error(key, name, lookup, item))]
    msg = _value_error(key, name, lookup, value)
    return [msg] if msg else []


def pool_problems(pool, section_type: str | None = None, sub_pools: bool = True) -> Found:
    """Every problem of a pool filter as (keys, message), each message naming its key; [] when usable.

    section_type: also check that sub-pools belong to a naturalness section and that a ``modality`` filter agrees
    with the section type; sub_pools: whether ``generated``/``source`` keys are allowed at all.
    """
    if pool is None or pool == {}:
        return []
    if not isinstance(pool, dict):
        return [((), f"the pool must be a JSON object of filters, got {type(pool).__name__}")]
    found: Found = []
    for key, value in pool.items():
        if key == NORMS_RULE:
            found += _norms_rule_problems(value)
        elif key in FLAGS or key in SWITCHES:
            if not isinstance(value, bool):
                found.append(((key,), f"{key!r} takes true or false, got {value!r}"))
        elif key in SUB_POOLS and sub_pools:
            if section_type is not None and key not in _sub_pools_of(section_type):
                takers = " or ".join(t for t in _sub_pool_takers() if key in _sub_pools_of(t))
                found.append(((key,), f"sub-pool {key!r} is only for {takers} sections"))
            elif not isinstance(value, dict):
                found.append(((key,), f"sub-pool {key!r} must be a JSON object of filters, got {value!r}"))
            else:
                found += [(tuple(f"{key}.{k}" for k in keys) or (key,), f"sub-pool {key!r}: {msg}")
                          for keys, msg in pool_problems(value, None, sub_pools=False)]
        else:
            found += _at(key, _filter_errors(key, value))
    wanted = SECTION_MODALITY.get(section_type or "")
    if wanted and isinstance(pool.get("modality"), str) and pool["modality"] != wanted:
        found.append((("modality",), f"'modality' is {pool['modality']!r} but {section_type} sections show {wanted} "
                                     "clips"))
    return found


def _norms_rule_problems(rule) -> Found:
    """Problems of a pool's ``norms`` rule as written (the source itself is checked by studyapp.data.norms_rule)."""
    example = '{"from": "my-pilot", "min_ratings": 10, "min_intended_share": 0.5}'
    if not isinstance(rule, dict):
        return [(("norms",), f"'norms' must be an object like {example}, got {rule!r}")]
    found: Found = [((f"norms.{k}",), f"'norms': unknown field {k!r} (fields: {', '.join(NORMS_FIELDS)})")
                    for k in rule if k not in NORMS_FIELDS]
    source = rule.get("from")
    if not isinstance(source, str) or not source.strip():
        found.append((("norms.from",), f"'norms': 'from' must name a study (its slug) or a clip_norms.csv file, "
                                       f"got {source!r}"))
    for name, spec in NORMS_FIELDS.items():
        if spec is None or name not in rule:
            continue
        kind, low, high = spec
        value = rule[name]
        ok = _is_int(value) if kind is int else _is_number(value)
        if not ok or not low <= value <= high:
            what = "an integer" if kind is int else "a number"
            found.append(((f"norms.{name}",), f"'norms': {name!r} must be {what} from {low:g} to {high:g}, got "
                                              f"{value!r}"))
    if not any(k in rule for k in ("min_ratings", "min_intended_share", "max_entropy_bits")):
        found.append((("norms",), "'norms' needs at least one of min_ratings, min_intended_share, max_entropy_bits"))
    return found


def pool_errors(pool, section_type: str | None = None, sub_pools: bool = True) -> list[str]:
    """The messages of :func:`pool_problems` (each naming its key); [] when the pool is usable."""
    return _messages(pool_problems(pool, section_type, sub_pools))


def pool_lookups(pool: dict | None) -> list[tuple[str, dict]]:
    """A valid pool as ORM calls: [("filter" | "exclude", keyword arguments), ...] (sub-pools left out).

    Raises PoolError when the pool is not valid (``pool_errors``)."""
    errors = pool_errors(pool)
    if errors:
        raise PoolError({"pool": errors})
    calls = []
    for key, value in (pool or {}).items():
        if key in SUB_POOLS or key in SWITCHES or key == NORMS_RULE:   # NORMS_RULE: studyapp.data.norms_rule
            continue
        if key == "transition":
            calls.append(("filter", {f"{FINAL_EMOTION_COLUMNS[0]}__isnull": not value}))
        elif key == "rbf":
            calls.append(("exclude" if value else "filter", {"theme": ""}))
        elif isinstance(value, list) and "__" not in key:
            calls.append(("filter", {f"{key}__in": value}))
        else:
            calls.append(("filter", {key: value}))
    return calls


def _sub_pools_of(section_type: str | None) -> tuple[str, ...]:
    """The sub-pools a section type declares (none for an unknown type)."""
    spec = find_section_type(section_type)
    return spec.sub_pools if spec else ()


def _sub_pool_takers() -> tuple[str, ...]:
    """The registered section types that declare sub-pools."""
    return tuple(t for t in SECTION_TYPES if _sub_pools_of(t))


def _attention_errors(section_type: str, config, clips_per_participant: int | None, categories) -> Found:
    """Problems of Section.options["attention_checks"], each naming 'attention_checks' and the bad field (keys
    ``attention_checks.<field>``)."""
    name = "'attention_checks'"
    if not isinstance(config, dict):
        return [(("attention_checks",), f"{name} must be an object like {{\"count\": 1, \"answer\": \"sad\", "
                                        f"\"positions\": \"random\"}}, got {config!r}")]
    errors = [((f"attention_checks.{k}",), f"{name}: unknown field {k!r} (fields: {', '.join(ATTENTION_KEYS)})")
              for k in config if k not in ATTENTION_KEYS]
    spec = find_section_type(section_type)
    questions = spec.question_kinds if spec else {}
    key = config.get("question", next(iter(questions), ""))
    if key not in questions:
        return errors + [(("attention_checks.question",), f"{name}: 'question' {key!r} is not a question of "
                                                          f"{section_type} sections ({', '.join(questions)})")]
    allowed = list(categories) if spec.drawn_choices else list(answer_values(questions[key]))
    answer = config.get("answer")
    if not isinstance(answer, (str, int)) or isinstance(answer, bool) or str(answer) not in allowed:
        errors.append((("attention_checks.answer",), f"{name}: 'answer' must be one of the answers to {key!r} "
                                                     f"({', '.join(allowed)}), got {answer!r}"))
    clip = config.get("clip")
    if clip is not None and not (isinstance(clip, str) and clip.strip()):
        errors.append((("attention_checks.clip",), f"{name}: 'clip' must be the clip_id of a catalogue clip that "
                                                   f"no participant rates, got {clip!r}"))
    count = config.get("count", 1)
    if not _is_int(count) or count < 1:
        errors.append((("attention_checks.count",), f"{name}: 'count' must be an integer 1 or more, got "
                                                    f"{count!r}"))
        count = 1
    positions = config.get("positions", "random")
    if positions != "random":
        longest = clips_per_participant + count if clips_per_participant else None
        if (not isinstance(positions, list) or len(positions) != count
                or not all(_is_int(p) and p >= 1 and (longest is None or p <= longest) for p in positions)):
            where = f" from 1 to {longest}" if longest else " of 1 or more"
            errors.append((("attention_checks.positions",), f"{name}: 'positions' must be \"random\" or a list of "
                                                            f"{count} integer place(s){where}, got {positions!r}"))
    return errors


def _extras_errors(section_type: str, options: dict, clips_per_participant: int | None) -> Found:
    """Problems of the options every section type takes (COMMON_OPTIONS)."""
    found: Found = []
    if "attention_checks" in options:
        categories = options.get("categories") if isinstance(options.get("categories"), list) else GESTURE_EMOTIONS
        found += _attention_errors(section_type, options["attention_checks"], clips_per_participant, categories)
    if "practice" in options and not isinstance(options["practice"], bool):
        found.append((("practice",), f"'practice' takes true or false, got {options['practice']!r}"))
    if "practice_clip" in options and not (isinstance(options["practice_clip"], str)
                                           and options["practice_clip"].strip()):
        found.append((("practice_clip",), f"'practice_clip' must be the clip_id of a catalogue clip, got "
                                          f"{options['practice_clip']!r}"))
    return found + _player_problems(options)


MAX_RATINGS_PER_CLIP = 10_000


def _norming_errors(config) -> Found:
    """Problems of Section.options["norming"] (``{"ratings_per_clip": K}``), each naming its field."""
    if not isinstance(config, dict):
        return [(("norming",), f"'norming' must be an object like {{\"ratings_per_clip\": 20}}, got {config!r}")]
    found: Found = [((f"norming.{k}",), f"'norming': unknown field {k!r} (fields: ratings_per_clip)")
                    for k in config if k != "ratings_per_clip"]
    k = config.get("ratings_per_clip", 1)
    if not _is_int(k) or not 1 <= k <= MAX_RATINGS_PER_CLIP:
        found.append((("norming.ratings_per_clip",), f"'norming': 'ratings_per_clip' must be an integer from 1 to "
                                                     f"{MAX_RATINGS_PER_CLIP}, got {k!r}"))
    return found


def _player_problems(options: dict) -> Found:
    found: Found = []
    if "controls" in options and options["controls"] not in PLAYER_CONTROLS:
        found.append((("controls",), f"'controls' must be one of {', '.join(PLAYER_CONTROLS)}, got "
                                     f"{options['controls']!r}"))
    if options.get("max_replays") is not None:
        msg = _count_error(options, "max_replays", 0, MAX_REPLAYS_LIMIT)
        found += _at("max_replays", [f"{msg} (blank or null: unlimited)"] if msg else [])
    return found


def player_errors(options: dict) -> list[str]:
    """Problems of the clip player's options (PLAYER_OPTIONS), each message naming its key."""
    return _messages(_player_problems(options))


def options_problems(section_type: str, options, clips_per_participant: int | None = None) -> Found:
    """Every problem of a section's options as (keys, message), each message naming its key."""
    if options is None or options == {}:
        return []
    if not isinstance(options, dict):
        return [((), f"the options must be a JSON object, got {type(options).__name__}")]
    own = SECTION_OPTIONS.get(section_type, ())
    known = (*own, *COMMON_OPTIONS)
    listed = (f"options: {', '.join(known)}" if own else
              f"this section type takes no options of its own; every section takes {', '.join(COMMON_OPTIONS)}")
    found: Found = [((key,), f"unknown option {key!r} for {section_type} sections ({listed})")
                    for key in options if key not in known]
    found += _extras_errors(section_type, options, clips_per_participant)
    if NORMING_OPTION in options and NORMING_OPTION in own:
        found += _norming_errors(options[NORMING_OPTION])
    spec = find_section_type(section_type)
    if spec is not None and spec.check_options is not None:
        found += spec.check_options(options, clips_per_participant)
    return found


def options_errors(section_type: str, options, clips_per_participant: int | None = None) -> list[str]:
    """The messages of :func:`options_problems` (each naming its key); [] when the options are usable."""
    return _messages(options_problems(section_type, options, clips_per_participant))


def page_problems(section_type: str, pool, options) -> list[SectionError]:
    """Everything wrong with a page section (instruction or break page, ``protocol.section_types.pages``): it shows
    no clips, so its pool must be empty, and it takes only its own options (no player, practice or checks)."""
    errors = []
    if pool not in (None, {}):
        errors.append(SectionError("pool", f"a {section_type} shows no clips: leave its pool empty (got {pool!r})"))
    if options in (None, {}):
        return errors
    if not isinstance(options, dict):
        return errors + [SectionError("options", f"the options must be a JSON object, got {type(options).__name__}")]
    own = SECTION_OPTIONS.get(section_type, ())
    listed = f"options: {', '.join(own)}" if own else "it takes no options"
    errors += [SectionError("options", f"unknown option {key!r} for {section_type} sections ({listed})", (key,))
               for key in options if key not in own]
    spec = find_section_type(section_type)
    if spec is not None and spec.check_options is not None:
        errors += [SectionError("options", msg, keys) for keys, msg in spec.check_options(options, None)]
    return errors


def validate_section(section_type: str, pool, options, clips_per_participant: int | None = None
                     ) -> list[SectionError]:
    """Everything wrong with a section's type, pool, options and clip count ([] when nothing), each error with its
    Section field and the JSON keys it is about (:class:`SectionError`). A page type (instruction or break page)
    is checked by :func:`page_problems`; its clip count is not used."""
    if is_page_type(section_type):
        return page_problems(section_type, pool, options)
    if section_type not in SECTION_TYPES:
        names = ", ".join(section_type_names(pages=True))
        return [SectionError("section_type", f"{section_type!r} is not a section type ({names})")]
    errors = [SectionError("pool", msg, keys) for keys, msg in pool_problems(pool, section_type)]
    errors += [SectionError("options", msg, keys)
               for keys, msg in options_problems(section_type, options, clips_per_participant)]
    if clips_per_participant is not None and (not _is_int(clips_per_participant) or clips_per_participant < 0):
        errors.append(SectionError("clips_per_participant",
                                   f"must be an integer 0 or more, got {clips_per_participant!r}"))
    return errors


def errors_by_field(errors: list[SectionError]) -> dict[str, list[str]]:
    """Section field -> messages (the form Django's ValidationError takes)."""
    out: dict[str, list[str]] = {}
    for error in errors:
        out.setdefault(error.field, []).append(error.message)
    return out
