"""A norming study's design and progress: K ratings per clip, M clips per participant, the N it needs.

A section is a norming section when its options hold ``"norming": {"ratings_per_clip": K}`` (protocol.norming) and
its type is one of protocol.vocabulary.NORMING_SECTION_TYPES. The planned N is the study's participant limit
(``Study.max_participants``). :func:`design_rows` is what the admin shows before the study opens; :func:`open_errors`
is why it refuses to open (the admin action and the study form both ask); :func:`ratings_so_far` feeds the staff
monitor page.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from django.db.models import Count

from protocol.norming import design_errors, min_ratings, ratings_per_clip, required_participants
from protocol.vocabulary import NORMING_SECTION_TYPES, SECTION_QUESTIONS

from ..models import Response, Section, SectionClipCount, Study
from .pool_cache import load_section_pool


def is_norming(section: Section) -> bool:
    return section.section_type in NORMING_SECTION_TYPES and ratings_per_clip(section.options) is not None


@dataclass
class NormingRow:
    """One norming section's design: C candidate clips, M shown to each participant, K ratings wanted, N needed,
    the planned N and the fewest ratings a clip gets with it; ``errors`` say why it cannot give K."""
    section: Section
    n_clips: int
    m: int
    k: int
    n_needed: int
    n_planned: int
    min_with_planned: int
    errors: list[str] = field(default_factory=list)


def norming_sections(study: Study) -> list[Section]:
    return [s for s in study.sections.order_by("order", "id") if is_norming(s)]


def design_rows(study: Study, n_planned: int | None = None) -> list[NormingRow]:
    """The design of every norming section of ``study`` (none: not a norming study), from its saved pools, with
    ``n_planned`` participants (default the study's participant limit)."""
    rows = []
    n = study.max_participants if n_planned is None else n_planned
    for section in norming_sections(study):
        c = len(load_section_pool(section).clips)
        m = min(section.clips_per_participant or c, c)
        k = ratings_per_clip(section.options)
        rows.append(NormingRow(section, c, m, k, required_participants(c, k, m), n,
                               min_ratings(c, m, n) if n else 0, design_errors(c, k, m, n)))
    return rows


def open_errors(study: Study, n_planned: int | None = None) -> list[str]:
    """Why ``study`` must not open ([] when it may): a norming section whose design cannot give every clip its K
    ratings with the planned N participants, each message naming the section."""
    return [f"Norming section {row.section.order} ({row.section.section_type}): {msg}"
            for row in design_rows(study, n_planned) for msg in row.errors]


@dataclass
class ClipProgress:
    clip_id: str
    assigned: int
    rated: int


def ratings_so_far(section: Section) -> list[ClipProgress]:
    """Per pool clip of a norming section: participants given it and answers to the section's emotion question
    (attention checks not counted), fewest ratings first."""
    key = next(iter(SECTION_QUESTIONS[section.section_type]))
    rated = dict(Response.objects.filter(section=section, question=key, kind="")
                 .values_list("clip__clip_id").annotate(n=Count("id")).values_list("clip__clip_id", "n"))
    assigned = dict(SectionClipCount.objects.filter(section=section).values_list("clip__clip_id", "n"))
    rows = [ClipProgress(c.clip_id, assigned.get(c.clip_id, 0), rated.get(c.clip_id, 0))
            for c in load_section_pool(section).clips]
    return sorted(rows, key=lambda r: (r.rated, r.clip_id))
