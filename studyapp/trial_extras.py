"""Practice trials and attention checks added to a section's planned clips (Section.options, checked by
protocol.pools.options_errors).

- ``"practice": true`` or ``"practice_clip": "<clip_id>"``: one practice item first in the section, on a clip
  outside the section's pool (``practice``: a clip of the section's modality drawn with the participant's seed),
  with the section's questions, marked "Practice" on the page. Its answers are never stored as responses.
- ``"attention_checks": {"count": 1, "answer": "sad", "positions": "random" | [3], "question": "perceived"}``:
  instructed-response items (Prolific's rules: the instruction is explicit and shown above the question, no trick,
  no memory test). Each shows a real clip of the section's pool (one this participant does not rate in the section
  when there is one, else one of the section's clips) with one question of the section (``question``, default the
  first) and the instruction to give ``answer``. ``positions``: 1-based places among the section's rated items
  (trials and checks, practice not counted), clamped to the section's length; ``"random"`` draws them with the
  participant's seed, never the first place when the section has more than one item. The answer is stored with
  section_type ``attention_check`` and question ``<key>=<answer>`` (protocol.vocabulary.attention_question).
"""
from __future__ import annotations

import random
from dataclasses import dataclass, field

from protocol.pools import DEFAULT_GESTURE_OPTIONS
from protocol.section_types import get_section_type
from protocol.vocabulary import ATTENTION_CHECK, answer_values, attention_question

from .models import Assignment, Clip, Section

PRACTICE = Assignment.Kind.PRACTICE.value


@dataclass
class PlannedItem:
    """One clip page of a plan: the clip, the gesture options shown, its kind (Assignment.Kind) and, for an
    attention check, ``<question key>=<instructed answer>``."""
    clip: Clip
    options: list[str] = field(default_factory=list)
    kind: str = ""
    instructed: str = ""


def gesture_options(rng: random.Random, section: Section, intended: str) -> list[str]:
    """The shuffled answer options of a gesture_emotion clip: ``intended`` and n_options - 1 other categories."""
    (kind,) = get_section_type(section.section_type).question_kinds.values()
    categories = list(section.options.get("categories") or answer_values(kind))
    n_options = int(section.options.get("n_options", DEFAULT_GESTURE_OPTIONS))
    others = [c for c in categories if c != intended]
    shown = [intended, *rng.sample(others, min(n_options - 1, len(others)))]
    rng.shuffle(shown)
    return shown


def draws_choices(section: Section) -> bool:
    """Whether the section's type draws its answer choices per participant and clip (gesture_emotion)."""
    return get_section_type(section.section_type).drawn_choices


def check_question(section: Section) -> str:
    """The question key an attention check of this section asks."""
    config = section.options.get("attention_checks") or {}
    return config.get("question") or get_section_type(section.section_type).questions[0].key


def check_count(config: dict) -> int:
    """How many checks a section's ``attention_checks`` asks for (``count``, else the number of positions, else 1)."""
    positions = config.get("positions")
    return int(config.get("count") or (len(positions) if isinstance(positions, list) else 1))


def check_positions(config: dict, n_items: int, rng: random.Random) -> list[int]:
    """1-based positions of the checks among ``n_items`` rated items (trials + checks)."""
    count = check_count(config)
    positions = config.get("positions", "random")
    if isinstance(positions, list):
        return sorted({min(max(int(p), 1), n_items) for p in positions})[:count]
    places = list(range(2, n_items + 1)) if n_items > count else list(range(1, n_items + 1))
    return sorted(rng.sample(places, min(count, len(places))))


def _check_clips(rng: random.Random, pool: list[Clip], trials: list[PlannedItem], count: int) -> list[Clip]:
    """Distinct clips for the checks: pool clips the participant does not rate here first, then rated ones."""
    rated = {it.clip.pk for it in trials}
    spare = [c for c in pool if c.pk not in rated]
    rng.shuffle(spare)
    own = [it.clip for it in trials]
    rng.shuffle(own)
    return (spare + own)[:count]


def _attention_items(section: Section, trials: list[PlannedItem], pool: list[Clip], rng: random.Random
                     ) -> list[PlannedItem]:
    """The section's rated items with its attention checks placed among the trials."""
    config = section.options.get("attention_checks")
    if not config or not trials:
        return list(trials)
    answer = str(config["answer"])
    count = check_count(config)
    clips = _check_clips(rng, pool, trials, count)
    positions = check_positions(config, len(trials) + len(clips), rng)
    instructed = attention_question(check_question(section), answer)
    checks = []
    for clip in clips[:len(positions)]:
        options = gesture_options(rng, section, answer) if draws_choices(section) else []
        checks.append(PlannedItem(clip, options, ATTENTION_CHECK, instructed))
    items, trial_iter, check_iter = [], iter(trials), iter(checks)
    for place in range(1, len(trials) + len(checks) + 1):
        items.append(next(check_iter) if place in positions else next(trial_iter))
    return items


def _practice_item(section: Section, candidates: list[Clip], used: set[int], rng: random.Random
                   ) -> PlannedItem | None:
    """The practice item of a section, or None when it asks for none or no clip outside the pool exists."""
    options = section.options
    if not (options.get("practice") or options.get("practice_clip")):
        return None
    free = [c for c in candidates if c.pk not in used] or list(candidates)
    if not free:
        return None
    clip = free[0] if options.get("practice_clip") else rng.choice(free)
    shown = (gesture_options(rng, section, clip.emotion_label or "neutral")
             if draws_choices(section) else [])
    return PlannedItem(clip, shown, PRACTICE)


def with_extras(section: Section, trials: list[PlannedItem], pool: list[Clip], practice_candidates: list[Clip],
                used: set[int], seed: int) -> list[PlannedItem]:
    """A section's items in the order shown: its practice item (if any), then trials and attention checks.

    trials: the planned clips; pool: the section's pool clips (check clips come from it, or from the trials
    when it is empty, as in a reusing section); used: pks of clips this participant sees elsewhere (practice
    avoids them); seed: the participant's seed (a separate stream, so the trials do not change)."""
    if not isinstance(section.options, dict) or not section.options:
        return list(trials)
    rng = random.Random(f"{seed}:{section.pk}:extras")
    items = _attention_items(section, trials, pool or [it.clip for it in trials], rng)
    practice = _practice_item(section, practice_candidates, used, rng)
    return ([practice] if practice else []) + items
