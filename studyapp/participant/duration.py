"""The expected duration of a study for one participant, shown on the consent page: an honest
duration, computed from what the participant will get rather than typed in.

    seconds = sum over sections of  items x (mean clip duration of the section's pool + PAGE_SECONDS
                                              + questions x ANSWER_SECONDS_PER_QUESTION)
              + practice items and attention checks (each a clip page like a trial's)
              + READING_SECONDS per instruction page + (its wait + PAGE_SECONDS) per break page
              + DEMOGRAPHICS_SECONDS (when asked) + FEEDBACK_SECONDS_PER_QUESTION x feedback questions
    minutes = ceil(seconds / 60)

items: the section's clips per participant (all of its pool when 0; capped at the pool's size; a reusing
section: as many as its source section). Clips without a duration count DEFAULT_CLIP_SECONDS.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from protocol.norming import ratings_per_clip
from protocol.section_types import is_page_type
from protocol.section_types.pages import makes_wait, wait_seconds
from protocol.vocabulary import SECTION_QUESTIONS, section_questions

from ..data.pool_cache import SectionPool, section_pools
from ..models import Section, Study
from .trial_extras import check_count

ANSWER_SECONDS_PER_QUESTION = 5.0
"""Time to read one question and choose an answer (s); a rough figure for short closed questions."""
PAGE_SECONDS = 3.0
"""Time per clip page besides watching and answering: loading, the button, the next page (s)."""
DEFAULT_CLIP_SECONDS = 5.0
"""Duration assumed for a clip whose duration is not in the catalogue (s)."""
DEMOGRAPHICS_SECONDS = 30.0
READING_SECONDS = 20.0
"""Time to read an instruction page and continue (s)."""
FEEDBACK_SECONDS_PER_QUESTION = 15.0


@dataclass(frozen=True)
class SectionTime:
    """One section's share: clip pages (trials + checks + practice), mean clip length and questions per page."""
    items: int
    checks: int
    practice: int
    mean_clip_s: float
    questions: int

    @property
    def seconds(self) -> float:
        per_page = self.mean_clip_s + PAGE_SECONDS + self.questions * ANSWER_SECONDS_PER_QUESTION
        return (self.items + self.practice + self.checks) * per_page


def mean_duration(pool: SectionPool) -> float:
    """Mean duration_s (s) of the pool's clips that have one; DEFAULT_CLIP_SECONDS when none has."""
    known = [c.duration_s for c in pool.clips if c.duration_s]
    return sum(known) / len(known) if known else DEFAULT_CLIP_SECONDS


def _trial_count(section: Section, pool: SectionPool) -> int:
    """Clips one participant rates in a section: clips_per_participant capped at the pool size (0 = all)."""
    k = section.clips_per_participant
    return min(k, len(pool.clips)) if k else len(pool.clips)


def section_times(sections: list[Section], pools: dict[int, SectionPool]) -> list[SectionTime]:
    """The SectionTime of each section (study order), from the sections' pools."""
    out: dict[int, SectionTime] = {}
    for s in sections:
        source = out.get(s.reuse_section_id) if s.reuse_section_id else None
        pool = pools.get(s.reuse_section_id if source else s.pk) or SectionPool()
        items = source.items if source else _trial_count(s, pool)
        options = s.options if isinstance(s.options, dict) else {}
        checks = check_count(options["attention_checks"]) if options.get("attention_checks") and items else 0
        practice = 1 if options.get("practice") or options.get("practice_clip") else 0
        out[s.pk] = SectionTime(items, checks, practice, source.mean_clip_s if source else mean_duration(pool),
                                len(section_questions(s.section_type, ratings_per_clip(options) is not None))
                                if s.section_type in SECTION_QUESTIONS else 0)
    return [out[s.pk] for s in sections]


def page_seconds(section: Section) -> float:
    """The time an instruction page (READING_SECONDS) or a break page (its wait + PAGE_SECONDS) takes (s)."""
    if makes_wait(section.section_type):
        return wait_seconds(section.options) + PAGE_SECONDS
    return READING_SECONDS


def expected_seconds(study: Study) -> float:
    """The formula of the module docstring, in seconds."""
    sections = list(study.sections.order_by("order", "id"))
    questions = [s for s in sections if not is_page_type(s.section_type)]
    total = sum(t.seconds for t in section_times(questions, section_pools(study.pk, questions)))
    total += sum(page_seconds(s) for s in sections if is_page_type(s.section_type))
    if study.ask_demographics:
        total += DEMOGRAPHICS_SECONDS
    return total + FEEDBACK_SECONDS_PER_QUESTION * len(study.feedback_questions or [])


def expected_minutes(study: Study) -> int:
    """The study's expected duration for one participant in whole minutes, rounded up (at least 1)."""
    return max(1, math.ceil(expected_seconds(study) / 60))
