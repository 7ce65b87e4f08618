"""Section order counterbalancing: balanced Latin squares (Williams designs) and the order of one participant's
sections. Plain Python (no Django): the start of a participant and the tests share it.

Williams design: for an even number n of conditions, n rows in which every condition appears once in every
position and every condition is immediately followed by every other exactly once (first-order carry-over
balanced); for an odd n the n rows and their mirror images, 2n rows. Participants get rows by their arrival
index (row = arrival mod number of rows), so every complete block of rows is balanced.

What rotates (``section_order``): the sections marked ``counterbalance`` rotate; the others are pinned to their
place in the study's order. A section that reuses another section's clips must come after it. Two rules keep
that: (1) a rotating section that reuses a rotating section moves with it as one unit (the reusing section right
after its source, in study order), so the square rotates units, not single sections; (2) if a pinned section and
a rotating one are linked by reuse and the rotation would put the source after the reusing section, the reusing
section is moved to just after its source (the only change to the square's order).

Instruction and break pages (protocol.section_types.pages) are not conditions: they are left out of the square and
each travels with the section that follows it in the study's order (``attach_pages``); pages after the last
section stay at the end.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass


def williams_rows(n: int) -> list[list[int]]:
    """The rows of a balanced Latin square over conditions 0..n-1: n rows for even n, 2n for odd n (n >= 1)."""
    if n < 1:
        raise ValueError(f"a Latin square needs at least one condition, got {n}")
    first, low, high = [0], 1, n - 1
    while len(first) < n:          # 0, 1, n-1, 2, n-2, ...
        first.append(low)
        low += 1
        if len(first) < n:
            first.append(high)
            high -= 1
    rows = [[(c + r) % n for c in first] for r in range(n)]
    if n % 2:
        rows += [list(reversed(row)) for row in rows]
    return rows


@dataclass(frozen=True)
class SectionInfo:
    """What ordering needs of a section: its pk, whether it rotates, and the pk of the section it reuses."""
    pk: int
    rotates: bool = True
    reuses: int | None = None


def rotation_units(sections: Sequence[SectionInfo]) -> list[list[int]]:
    """The rotating units (lists of section pks in study order): a rotating section joins the unit of the
    rotating section it reuses (transitively); every other rotating section starts a unit."""
    rotating = {s.pk: s for s in sections if s.rotates}
    unit_of: dict[int, int] = {}
    units: list[list[int]] = []
    for s in sections:
        if not s.rotates:
            continue
        if s.reuses in rotating and s.reuses in unit_of:
            index = unit_of[s.reuses]
            units[index].append(s.pk)
        else:
            index = len(units)
            units.append([s.pk])
        unit_of[s.pk] = index
    return units


def section_order(sections: Sequence[SectionInfo], arrival: int) -> list[int]:
    """Section pks in the order participant number ``arrival`` (0-based) takes them: the rotating units in the
    Williams row ``arrival mod rows`` fill the places of the rotating sections; pinned sections keep theirs; then
    rule (2) of the module docstring puts any reusing section after its source."""
    units = rotation_units(sections)
    if len(units) < 2:
        return _reuse_after_source([s.pk for s in sections], sections)
    rows = williams_rows(len(units))
    row = rows[arrival % len(rows)]
    rotated = iter([pk for u in row for pk in units[u]])
    order = [next(rotated) if s.rotates else s.pk for s in sections]
    return _reuse_after_source(order, sections)


def _reuse_after_source(order: list[int], sections: Sequence[SectionInfo]) -> list[int]:
    """Move each section that comes before the section it reuses to just after that section."""
    reuses = {s.pk: s.reuses for s in sections if s.reuses is not None}
    order = list(order)
    for _ in range(len(order)):
        moved = False
        for pk, source in reuses.items():
            if source in order and order.index(pk) < order.index(source):
                order.remove(pk)
                order.insert(order.index(source) + 1, pk)
                moved = True
        if not moved:
            break
    return order


def attach_pages(order: Sequence[int], study_order: Sequence[int], pages: set[int] | frozenset[int]) -> list[int]:
    """``order`` (the pks of the question-bearing sections, in the participant's order) with the page sections put
    back: each page right before the section that follows it in ``study_order`` (several pages before one section
    keep their study order), the pages after the last section at the end."""
    leading: dict[int, list[int]] = {}
    waiting: list[int] = []
    for pk in study_order:
        if pk in pages:
            waiting.append(pk)
        else:
            leading[pk], waiting = waiting, []
    return [pk for section in order for pk in (*leading.get(section, ()), section)] + waiting
