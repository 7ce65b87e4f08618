"""Move a section one place up or down in its study (the "Move up" / "Move down" buttons of the study page's
sections step).

A move swaps the ``order`` of the section and its neighbour; nothing else changes, so counterbalancing
(studyapp.participant.counterbalance: the rotating sections in study order, the pinned ones at their place) and
assignment (studyapp.participant.assignment: sections planned in study order, earlier sections' clips not shown again)
read the new order as if the researcher had typed it. A move is refused, with a sentence that says why, when

- a participant has taken part (withdrawn ones aside): a participant of a study without counterbalancing follows
  the study's order as it is now, so a move would reorder the pages of someone halfway through, and the clips
  each section gives depend on the sections before it;
- the section reuses the clips of the section it would pass, or that section reuses its clips (a reused section
  must come first: Section.clean, studyapp.participant.counterbalance);
- there is no neighbour on that side.

The section form refuses a typed change of ``order`` by the same first rule (:func:`move_refusal`).
"""
from __future__ import annotations

from django.db import transaction

from ..models import Participant, Section

DIRECTIONS = {"up": -1, "down": 1}


class MoveRefused(ValueError):
    """A move that cannot be made; the message says why, in the researcher's words."""


def describe(section: Section) -> str:
    """A section as the study page names it: "section 2 (naturalness, "realism")"."""
    return f"section {section.order} ({section.section_type}" + (f', "{section.name}")' if section.name else ")")


def participants_taking_part(study) -> int:
    """Participants of the study that are not withdrawn (pilot participants included)."""
    return study.participants.exclude(status=Participant.Status.WITHDRAWN).count()


def move_refusal(study) -> str:
    """Why no section of ``study`` may move now ("" when they may)."""
    n = participants_taking_part(study)
    if not n:
        return ""
    return (f"The sections cannot be reordered: {n} participant{' has' if n == 1 else 's have'} taken part, and "
            "their pages follow the section order. Delete pilot data on the progress page, or clone the study and "
            "reorder the copy.")


def move(section: Section, direction: str) -> Section:
    """Swap ``section`` with its neighbour above (``up``) or below (``down``) in study order; returns the
    neighbour. MoveRefused says why a move cannot be made (see the module's doc). Sections of equal ``order`` are
    first numbered 1..n in their current order (order, then id), so the swap always changes the page."""
    if direction not in DIRECTIONS:
        raise MoveRefused(f"Unknown direction {direction!r}: use {' or '.join(DIRECTIONS)}.")
    study = section.study
    with transaction.atomic():
        refusal = move_refusal(study)
        if refusal:
            raise MoveRefused(refusal)
        sections = list(Section.objects.select_for_update().filter(study=study).order_by("order", "id"))
        index = next(i for i, s in enumerate(sections) if s.pk == section.pk)
        other_index = index + DIRECTIONS[direction]
        if not 0 <= other_index < len(sections):
            raise MoveRefused(f"{describe(sections[index]).capitalize()} is already the "
                              f"{'first' if direction == 'up' else 'last'} section.")
        mover, other = sections[index], sections[other_index]
        first, second = (other, mover) if direction == "up" else (mover, other)
        if second.reuse_section_id == first.pk:
            raise MoveRefused(f"{describe(second).capitalize()} shows the clips of {describe(first)}, so it must "
                              "come after it: set its reuse section to none first.")
        if len({s.order for s in sections}) != len(sections):
            for i, s in enumerate(sections, start=1):
                s.order = i
        mover.order, other.order = other.order, mover.order
        Section.objects.bulk_update(sections, ["order"])
    section.order = mover.order
    return other
