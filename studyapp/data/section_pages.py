"""Instruction and break pages in a participant's flow: which page is due, and the record of each page on the
Participant (``Participant.pages``).

A page is a Section of a page type (protocol.section_types.pages). At the start (studyapp.participant.assignment) every
page of the participant's section order becomes one record, in the order taken::

    {"section": <Section pk>, "before": <the clip number (Assignment.seq) it comes before>,
     "shown_at": <ISO time of the first display, or None>, "continued_at": <ISO time of Continue, or None>}

``before`` is n_items + 1 for a page after the last clip. Page n (1-based, the URL's number) is due when every clip
before it is answered, every earlier page is continued and it is not continued yet; so a reload shows the same page,
a second Continue finds the next step instead of skipping one, and a server restart loses nothing (all of it is in
the database). The records are read with the participant (no extra query); writes go through :func:`record`.
"""
from __future__ import annotations

from datetime import datetime

from django.db import transaction
from django.utils import timezone
from django.utils.dateparse import parse_datetime

from protocol.section_types import is_page_type
from protocol.section_types.pages import makes_wait, wait_seconds

from ..models import Participant, Section


def is_page(section: Section) -> bool:
    """Whether a section is an instruction or break page (no clips, no questions)."""
    return is_page_type(section.section_type)


def page_records(order: list[Section], clips_per_section: dict[int, int]) -> list[dict]:
    """The page records of a participant's section ``order`` (pages included), given how many clip pages each
    other section has for them (section pk -> count)."""
    records, seq = [], 0
    for section in order:
        if is_page(section):
            records.append({"section": section.pk, "before": seq + 1, "shown_at": None, "continued_at": None})
        else:
            seq += clips_per_section.get(section.pk, 0)
    return records


def due_page(pages: list[dict] | None, open_seq: int | None) -> int | None:
    """The number (1-based) of the page the participant is on, or None: the first page not continued whose clips
    before it are all answered. ``open_seq``: the first unanswered clip's number (None: every clip is answered)."""
    for n, record in enumerate(pages or [], start=1):
        if record.get("continued_at"):
            continue
        if open_seq is None or record.get("before", 0) <= open_seq:
            return n
        return None
    return None


def when(value) -> datetime | None:
    """A record's stored time as an aware datetime (None when not set or unreadable)."""
    return parse_datetime(value) if isinstance(value, str) else None


def wait_left(section: Section, record: dict, now: datetime | None = None) -> float:
    """Seconds until a break page may be continued (0 for an instruction page, or once the wait has passed); the
    full wait when the page has not been shown yet."""
    if not makes_wait(section.section_type):
        return 0.0
    wait = wait_seconds(section.options)
    shown = when(record.get("shown_at"))
    if shown is None:
        return float(wait)
    return max(0.0, wait - ((now or timezone.now()) - shown).total_seconds())


def record(participant: Participant, n: int, field: str, now: datetime | None = None) -> bool:
    """Set ``field`` (shown_at or continued_at) of page n to ``now`` once: under the participant's row lock, so
    two requests never both write it; the participant's last activity too (a long break is not abandonment).
    Returns False when it was set already or there is no page n."""
    now = now or timezone.now()
    stamp = now.isoformat()
    with transaction.atomic():
        pages = (Participant.objects.select_for_update().filter(pk=participant.pk)
                 .values_list("pages", flat=True).first())
        if not pages or not 1 <= n <= len(pages) or pages[n - 1].get(field):
            return False
        pages[n - 1] = {**pages[n - 1], field: stamp}
        Participant.objects.filter(pk=participant.pk).update(pages=pages, last_active_at=now)
    participant.pages = pages
    return True
