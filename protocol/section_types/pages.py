"""instruction_page and break_page: pages a researcher places between sections. They show no clip and ask
nothing: an instruction page shows its title and text until the participant continues; a break page asks the
participant to rest and enables Continue only after ``wait_seconds`` (the server refuses an earlier continue too).

A page is a Section like any other (it has an ``order``); under counterbalancing it travels with the section that
follows it (``studyapp.participant.counterbalance.attach_pages``). When and how long each participant spent on each page
is exported as pages.csv (``protocol.vocabulary.PAGE_COLUMNS``).
"""
from __future__ import annotations

from .checks import count_error
from .registry import Found, OptionSpec, SectionType, register

WAIT_OPTION = "wait_seconds"
"""The break page's option: seconds from the page's first display until Continue is enabled."""
DEFAULT_WAIT_SECONDS = 30
MAX_WAIT_SECONDS = 3600
"""The longest break a page may impose (one hour)."""


def check_break_options(options: dict, clips_per_participant: int | None = None) -> Found:
    """The problem of ``wait_seconds`` (an integer 0..MAX_WAIT_SECONDS), if any."""
    if WAIT_OPTION in options and (msg := count_error(options, WAIT_OPTION, 0, MAX_WAIT_SECONDS)):
        return [((WAIT_OPTION,), f"{msg} (seconds before Continue is enabled)")]
    return []


def wait_seconds(options) -> int:
    """The break's minimum wait in seconds (DEFAULT_WAIT_SECONDS when not set; 0 for a malformed value, which the
    section's checks refuse on save)."""
    value = (options or {}).get(WAIT_OPTION, DEFAULT_WAIT_SECONDS) if isinstance(options, dict) else 0
    return value if isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= MAX_WAIT_SECONDS else 0


INSTRUCTION = register(SectionType(
    name="instruction_page", label="Instruction page (text, then Continue)",
    summary="A page between sections: its title and text, then Continue. No clip, no question; when the "
            "participant saw it and continued is exported (pages.csv).",
    modality=None, questions=(), page=True, module=__name__))

BREAK = register(SectionType(
    name="break_page", label="Break page (rest, Continue after a wait)",
    summary="A rest page between sections: Continue is enabled after the wait (also enforced by the server). "
            "No clip, no question; when the participant saw it and continued is exported (pages.csv).",
    modality=None, questions=(),
    options=(OptionSpec(WAIT_OPTION, f"seconds before Continue is enabled, 0..{MAX_WAIT_SECONDS} (default "
                                     f"{DEFAULT_WAIT_SECONDS})"),),
    check_options=check_break_options, page=True, module=__name__))


def makes_wait(section_type: str | None) -> bool:
    """Whether a page of this type holds Continue back for a wait (a break page) rather than showing text only."""
    return section_type == BREAK.name
