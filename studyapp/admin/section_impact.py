"""What a change to one section does to the others: the clips each section gives a participant, before and after.

Sections of a study share the catalogue: a participant never sees a clip twice, so a section whose pool overlaps
an earlier section's gets only the clips the earlier sections left (studyapp.participant.assignment.plan_study), and a
section that reuses another shows exactly the clips that one gave. Saving one section (a wider pool, more clips per
participant, a new place in the order) can therefore change what another section gives, without the researcher
touching it. This module measures that: :func:`clips_given` plans the study for a few participants (no writes,
no balancing counts: every participant as if first) and keeps, per section, the fewest clips one of them gets;
:func:`impacts` compares two such measures and names each other section whose count changed.
"""
from __future__ import annotations

from dataclasses import dataclass

from django.db import DatabaseError

from ..data.pool_cache import load_section_pool
from ..data.pool_filters import CatalogueError
from ..models import Section
from ..participant.assignment import plan_study
from .section_order import describe

SEEDS = range(8)
"""The participants planned per measure (seeds); the fewest clips over them is reported."""


def study_sections(study) -> list[Section]:
    """The study's sections in study order, as saved."""
    return list(Section.objects.filter(study=study).order_by("order", "id"))


PLAN_FIELDS = ("order", "section_type", "pool", "options", "clips_per_participant", "reuse_section_id",
               "randomize_order")
"""The section fields a participant's plan reads (what a save must change to change what sections give)."""


def plan_inputs(sections: list[Section]) -> dict[int, tuple]:
    """Section pk -> the values of its PLAN_FIELDS, to tell which sections a save changed."""
    return {s.pk: tuple(getattr(s, name) for name in PLAN_FIELDS) for s in sections}


def changed_sections(before: list[Section], after: list[Section]) -> set[int]:
    """The pks of the sections of ``after`` that are new or whose plan inputs differ from ``before``."""
    old = plan_inputs(before)
    return {pk for pk, values in plan_inputs(after).items() if old.get(pk) != values}


def clips_given(sections: list[Section], seeds=SEEDS) -> dict[int, int] | None:
    """Section pk -> the fewest clips a participant gets there over the planned ``seeds`` (practice items and
    attention checks not counted), ``sections`` taken in the order given. None when the study cannot be planned
    (a pool the catalogue cannot read, a reuse of a later section): the section's own checks say why."""
    sections = [s for s in sections if s.pk is not None]
    if not sections:
        return {}
    try:
        pools = {s.pk: load_section_pool(s) for s in sections}
        fewest: dict[int, int] = {}
        for seed in seeds:
            for section, items in plan_study(sections[0].study, seed, balanced=False, sections=sections,
                                             pools=pools):
                fewest[section.pk] = min(fewest.get(section.pk, len(items)), len(items))
    except (CatalogueError, DatabaseError, ValueError, TypeError, KeyError, LookupError):
        return None
    return fewest


@dataclass(frozen=True)
class Impact:
    """Another section's clips per participant, before and after a change of ``changed`` (the sections edited)."""

    section: Section
    before: int
    after: int
    changed: tuple[Section, ...]

    def why(self) -> str:
        """Why the section's clips changed: it reuses an edited section's clips, or its pool overlaps another's."""
        reused = next((s for s in self.changed if s.pk == self.section.reuse_section_id), None)
        if reused is not None:
            return f"it shows the clips {describe(reused)} gives"
        return "its pool shares clips with another section, and a participant never sees a clip twice"

    def message(self, verb: str = "Saving") -> str:
        """The admin message of this impact, e.g. "Saving section 2 changes what section 3 gives each participant: 6
        clips before, 4 now (...)"."""
        names = ", ".join(describe(s) for s in self.changed) or "this change"
        return (f"{verb} {names} changes what {describe(self.section)} gives each participant: {self.before} "
                f"clip{'' if self.before == 1 else 's'} before, {self.after} now ({self.why()}).")


def impacts(before: dict[int, int] | None, after: dict[int, int] | None, sections: list[Section],
            changed_pks: set[int]) -> list[Impact]:
    """Each section not among ``changed_pks`` whose clips per participant differ between ``before`` and ``after``
    (sections in study order; [] when either measure is missing)."""
    if before is None or after is None:
        return []
    changed = tuple(s for s in sections if s.pk in changed_pks)
    return [Impact(s, before[s.pk], after[s.pk], changed) for s in sections
            if s.pk not in changed_pks and s.pk in before and s.pk in after and before[s.pk] != after[s.pk]]


def short_of(section: Section, given: dict[int, int] | None, pool_total: int | None) -> str:
    """The note beside a section's clip count when earlier sections leave it fewer clips than its pool matches
    and than it shows each participant ("" otherwise)."""
    if not given or section.pk not in given or section.reuse_section_id or pool_total is None:
        return ""
    n, wanted = given[section.pk], section.clips_per_participant
    wanted = pool_total if wanted == 0 else min(wanted, pool_total)
    if n >= wanted:
        return ""
    return (f"earlier sections use some of these clips: a participant gets {n} here, not {wanted} (a participant "
            "never sees a clip twice)")
