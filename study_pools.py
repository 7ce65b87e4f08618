"""Section pools and options, checked against the study protocol. No Django import: the admin's SectionForm,
``Section.clean`` and the catalogue's ``pool_queryset`` share it, and none of them needs the database to know
whether a pool or an option is well formed.

A pool is a JSON object of catalogue filters: ``field`` or ``field__lookup`` -> value (a list without a lookup
means ``in``), plus two boolean shorthands, ``transition`` (the clip has a final emotion) and ``rbf`` (the clip
has a theme), and the switch ``include_flagged`` (true: clips whose quality record failed a check, ``qa_flag``, are
in the pool too; they are left out otherwise). A naturalness section may add ``generated`` and ``source``
sub-pools (filters of the same kind) for its two halves. Options are type-specific (``SECTION_OPTIONS``).
"""
from __future__ import annotations

import math

from study_protocol import (
    CLIP_THEMES,
    FINAL_EMOTION_COLUMNS,
    GAIT_EMOTIONS,
    GESTURE_EMOTIONS,
    MODALITIES,
    NATURALNESS,
    ORIGINS,
    SECTION_MODALITY,
    SECTION_QUESTIONS,
    SECTION_TYPES,
    VAD_DIMENSIONS,
    answer_values,
)

TEXT_FIELDS: dict[str, tuple[str, ...] | None] = {
    "clip_id": None, "plan": None, "modality": MODALITIES, "origin": ORIGINS, "emotion_label": GESTURE_EMOTIONS,
    "theme": CLIP_THEMES, "sections": SECTION_TYPES}
"""Catalogue text fields a pool may filter on -> the protocol vocabulary of their values (None: free text)."""

NUMBER_FIELDS = (*GAIT_EMOTIONS, *FINAL_EMOTION_COLUMNS, *VAD_DIMENSIONS, "weight", "duration_s")
INTEGER_FIELDS = ("n_features",)
POOL_FIELDS = frozenset((*TEXT_FIELDS, *NUMBER_FIELDS, *INTEGER_FIELDS))
TEXT_LOOKUPS = ("", "in", "startswith", "contains")
NUMBER_LOOKUPS = ("", "in", "lt", "lte", "gt", "gte", "isnull")
FLAGS = ("transition", "rbf")
INCLUDE_FLAGGED = "include_flagged"
"""Pool switch: also draw clips that failed a quality check (``Clip.qa_flag`` not empty)."""
SUB_POOLS = ("generated", "source")
"""Sub-pools of a naturalness section: extra filters for its generated and its source clips."""

SECTION_OPTIONS: dict[str, tuple[str, ...]] = {
    "naturalness": ("anchors", "question", "n_generated", "n_source"),
    "gesture_emotion": ("n_options", "categories"),
}
"""section_type -> the option keys it understands besides COMMON_OPTIONS."""

PLAYER_CONTROLS = ("replay-only", "full", "none")
"""``controls`` option: play/pause and replay only (no seek bar, no speed menu; the default), the browser's full
controls (seeking and speed allowed), or none (the clip plays by itself; seeking blocked)."""
DEFAULT_PLAYER_CONTROLS = "replay-only"
PLAYER_OPTIONS = ("controls", "max_replays")
"""The clip player of every section type: its controls and how often a clip may be replayed (absent or null:
unlimited; 0: played once)."""
MAX_REPLAYS_LIMIT = 100

COMMON_OPTIONS = ("attention_checks", "practice", "practice_clip", *PLAYER_OPTIONS)
"""Options of every section type (studyapp.trial_extras): attention checks, a practice item, the clip player."""
ATTENTION_KEYS = ("count", "answer", "positions", "question")

DEFAULT_GESTURE_OPTIONS = 4


class PoolError(ValueError):
    """A pool or options that cannot be used; ``errors`` maps a Section field to its messages."""

    def __init__(self, errors: dict[str, list[str]]):
        self.errors = errors
        super().__init__("; ".join(f"{field}: {msg}" for field, msgs in errors.items() for msg in msgs))


def _is_int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


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


def pool_errors(pool, section_type: str | None = None, sub_pools: bool = True) -> list[str]:
    """Every problem of a pool filter, each message naming its key; [] when the pool is usable.

    section_type: also check that sub-pools belong to a naturalness section and that a ``modality`` filter agrees
    with the section type; sub_pools: whether ``generated``/``source`` keys are allowed at all.
    """
    if pool is None or pool == {}:
        return []
    if not isinstance(pool, dict):
        return [f"the pool must be a JSON object of filters, got {type(pool).__name__}"]
    errors = []
    for key, value in pool.items():
        if key in FLAGS or key == INCLUDE_FLAGGED:
            if not isinstance(value, bool):
                errors.append(f"{key!r} takes true or false, got {value!r}")
        elif key in SUB_POOLS and sub_pools:
            if section_type not in (None, "naturalness"):
                errors.append(f"sub-pool {key!r} is only for naturalness sections")
            elif not isinstance(value, dict):
                errors.append(f"sub-pool {key!r} must be a JSON object of filters, got {value!r}")
            else:
                errors += [f"sub-pool {key!r}: {msg}" for msg in pool_errors(value, None, sub_pools=False)]
        else:
            errors += _filter_errors(key, value)
    wanted = SECTION_MODALITY.get(section_type or "")
    if wanted and isinstance(pool.get("modality"), str) and pool["modality"] != wanted:
        errors.append(f"'modality' is {pool['modality']!r} but {section_type} sections show {wanted} clips")
    return errors


def pool_lookups(pool: dict | None) -> list[tuple[str, dict]]:
    """A valid pool as ORM calls: [("filter" | "exclude", keyword arguments), ...] (sub-pools left out).

    Raises PoolError when the pool is not valid (``pool_errors``)."""
    errors = pool_errors(pool)
    if errors:
        raise PoolError({"pool": errors})
    calls = []
    for key, value in (pool or {}).items():
        if key in SUB_POOLS or key == INCLUDE_FLAGGED:
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


def _count_error(options: dict, key: str, low: int, high: int | None = None) -> str | None:
    value = options[key]
    if not _is_int(value) or value < low or (high is not None and value > high):
        bound = f"from {low} to {high}" if high is not None else f"{low} or more"
        return f"{key!r} must be an integer {bound}, got {value!r}"
    return None


def _naturalness_errors(options: dict, clips_per_participant: int | None) -> list[str]:
    errors = []
    anchors = options.get("anchors")
    scale = answer_values(NATURALNESS)
    if "anchors" in options:
        if not isinstance(anchors, dict):
            errors.append(f"'anchors' must map scale values ({', '.join(scale)}) to labels, got {anchors!r}")
        else:
            errors += [f"'anchors': {k!r} is not a value of the naturalness scale ({', '.join(scale)})"
                       for k in anchors if str(k) not in scale]
            errors += [f"'anchors': the label of {k!r} must be text" for k, v in anchors.items()
                       if not isinstance(v, str)]
    if "question" in options and not (isinstance(options["question"], str) and options["question"].strip()):
        errors.append(f"'question' must be non-empty text, got {options['question']!r}")
    counts = [k for k in ("n_generated", "n_source") if k in options]
    count_errors = [msg for k in counts if (msg := _count_error(options, k, 0))]
    errors += count_errors
    if counts and not count_errors:
        given = {k: options[k] for k in counts}
        if len(counts) == 1 and not clips_per_participant:
            errors.append("give both 'n_generated' and 'n_source' when every clip of the pool is shown")
        elif len(counts) == 2 and clips_per_participant and sum(given.values()) != clips_per_participant:
            errors.append(f"'n_generated' + 'n_source' = {sum(given.values())} must equal the clips per "
                          f"participant ({clips_per_participant})")
        elif len(counts) == 2 and sum(given.values()) == 0:
            errors.append("'n_generated' + 'n_source' must be at least 1")
    return errors


def _gesture_errors(options: dict) -> list[str]:
    errors = []
    categories = options.get("categories", list(GESTURE_EMOTIONS))
    if not isinstance(categories, list) or not categories or not all(isinstance(c, str) for c in categories):
        errors.append(f"'categories' must be a non-empty list of gesture emotions, got {categories!r}")
        categories = list(GESTURE_EMOTIONS)
    else:
        errors += [f"'categories': {c!r} is not one of {', '.join(GESTURE_EMOTIONS)}" for c in categories
                   if c not in GESTURE_EMOTIONS]
        if len(set(categories)) != len(categories):
            errors.append("'categories' lists an emotion twice")
    if "n_options" in options:
        msg = _count_error(options, "n_options", 2, len(set(categories)))
        errors += [msg] if msg else []
    elif len(set(categories)) < DEFAULT_GESTURE_OPTIONS:
        errors.append(f"'categories' needs at least {DEFAULT_GESTURE_OPTIONS} emotions (or set 'n_options')")
    return errors


def _attention_errors(section_type: str, config, clips_per_participant: int | None, categories) -> list[str]:
    """Problems of Section.options["attention_checks"], each naming 'attention_checks' and the bad field."""
    name = "'attention_checks'"
    if not isinstance(config, dict):
        return [f"{name} must be an object like {{\"count\": 1, \"answer\": \"sad\", \"positions\": \"random\"}}, "
                f"got {config!r}"]
    errors = [f"{name}: unknown field {k!r} (fields: {', '.join(ATTENTION_KEYS)})" for k in config
              if k not in ATTENTION_KEYS]
    questions = SECTION_QUESTIONS.get(section_type, {})
    key = config.get("question", next(iter(questions), ""))
    if key not in questions:
        return errors + [f"{name}: 'question' {key!r} is not a question of {section_type} sections "
                         f"({', '.join(questions)})"]
    allowed = list(categories) if section_type == "gesture_emotion" else list(answer_values(questions[key]))
    answer = config.get("answer")
    if not isinstance(answer, (str, int)) or isinstance(answer, bool) or str(answer) not in allowed:
        errors.append(f"{name}: 'answer' must be one of the answers to {key!r} ({', '.join(allowed)}), "
                      f"got {answer!r}")
    count = config.get("count", 1)
    if not _is_int(count) or count < 1:
        errors.append(f"{name}: 'count' must be an integer 1 or more, got {count!r}")
        count = 1
    positions = config.get("positions", "random")
    if positions != "random":
        longest = clips_per_participant + count if clips_per_participant else None
        if (not isinstance(positions, list) or len(positions) != count
                or not all(_is_int(p) and p >= 1 and (longest is None or p <= longest) for p in positions)):
            where = f" from 1 to {longest}" if longest else " of 1 or more"
            errors.append(f"{name}: 'positions' must be \"random\" or a list of {count} integer place(s){where}, "
                          f"got {positions!r}")
    return errors


def _extras_errors(section_type: str, options: dict, clips_per_participant: int | None) -> list[str]:
    """Problems of the options every section type takes (COMMON_OPTIONS)."""
    errors = []
    if "attention_checks" in options:
        categories = options.get("categories") if isinstance(options.get("categories"), list) else GESTURE_EMOTIONS
        errors += _attention_errors(section_type, options["attention_checks"], clips_per_participant, categories)
    if "practice" in options and not isinstance(options["practice"], bool):
        errors.append(f"'practice' takes true or false, got {options['practice']!r}")
    if "practice_clip" in options and not (isinstance(options["practice_clip"], str)
                                           and options["practice_clip"].strip()):
        errors.append(f"'practice_clip' must be the clip_id of a catalogue clip, got {options['practice_clip']!r}")
    return errors + player_errors(options)


def player_errors(options: dict) -> list[str]:
    """Problems of the clip player's options (PLAYER_OPTIONS), each message naming its key."""
    errors = []
    if "controls" in options and options["controls"] not in PLAYER_CONTROLS:
        errors.append(f"'controls' must be one of {', '.join(PLAYER_CONTROLS)}, got {options['controls']!r}")
    if options.get("max_replays") is not None:
        msg = _count_error(options, "max_replays", 0, MAX_REPLAYS_LIMIT)
        errors += [f"{msg} (blank or null: unlimited)"] if msg else []
    return errors


def options_errors(section_type: str, options, clips_per_participant: int | None = None) -> list[str]:
    """Every problem of a section's type-specific options, each message naming its key."""
    if options is None or options == {}:
        return []
    if not isinstance(options, dict):
        return [f"the options must be a JSON object, got {type(options).__name__}"]
    own = SECTION_OPTIONS.get(section_type, ())
    known = (*own, *COMMON_OPTIONS)
    listed = (f"options: {', '.join(known)}" if own else
              f"this section type takes no options of its own; every section takes {', '.join(COMMON_OPTIONS)}")
    errors = [f"unknown option {key!r} for {section_type} sections ({listed})" for key in options if key not in known]
    errors += _extras_errors(section_type, options, clips_per_participant)
    if section_type == "naturalness":
        errors += _naturalness_errors(options, clips_per_participant)
    elif section_type == "gesture_emotion":
        errors += _gesture_errors(options)
    return errors


def validate_section(section_type: str, pool, options, clips_per_participant: int | None = None
                     ) -> dict[str, list[str]]:
    """Section field -> messages for everything wrong with a section's type, pool and options ({} when none)."""
    if section_type not in SECTION_TYPES:
        return {"section_type": [f"{section_type!r} is not a section type ({', '.join(SECTION_TYPES)})"]}
    errors = {"pool": pool_errors(pool, section_type), "options": options_errors(section_type, options,
                                                                                  clips_per_participant)}
    if clips_per_participant is not None and (not _is_int(clips_per_participant) or clips_per_participant < 0):
        errors["clips_per_participant"] = [f"must be an integer 0 or more, got {clips_per_participant!r}"]
    return {field: msgs for field, msgs in errors.items() if msgs}
