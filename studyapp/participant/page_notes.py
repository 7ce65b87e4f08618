"""The note line above the questions of every clip page: a reminder on a rated clip, the instruction on an
attention check.

An instructed-response check must be read to be passed, by a person and by a script alike. What a script can
spot without reading is what the page gives away in its form: a separate element or class that only checks have,
a word such as "Attention check", fewer questions than the section's other pages, the answer's value in markup. So a
check page has the same structure as every clip page of its section: the same questions (only the instructed one
is stored), and one note line in the same place, with the same markup, that changes from page to page on rated
clips too (one of several reminders), so that a page's note differing from the last page's says nothing. The
instruction is ordinary text in reading order (screen readers read it before the questions, the way a sighted
person sees it); it names the question and the answer's visible label, as a person needs it.
"""
from __future__ import annotations

import zlib

from django.utils.translation import gettext
from django.utils.translation import gettext_noop as _

from protocol.vocabulary import ATTENTION_CHECK

REMINDERS = (
    _("Give your own impression: there are no right or wrong answers."),
    _("Answer from what you see in this clip."),
    _("Take the whole clip into account before you answer."),
    _("If you are unsure, choose the answer that comes closest."),
)
"""Notes of rated clips (and practice items), one per page, varying across the pages of a section."""

INSTRUCTIONS = (
    _("For this clip, please ignore the motion and answer “{question}” with {answer} only."),
    _("Whatever you see in this clip, please answer “{question}” with {answer} only."),
)
"""Notes of attention checks: {question} the instructed question's text, {answer} its answer's visible label."""


def _pick(options: tuple[str, ...], *key) -> str:
    return options[zlib.crc32(":".join(map(str, key)).encode()) % len(options)]


def page_note(questions: list, kind: str, instructed: str, section_pk: int, index: int) -> str:
    """The note line of a clip page in the active language. questions: the page's (studyapp.questions.Question);
    kind/instructed: the assignment's (``<question key>=<answer>`` for a check); index: the page's number."""
    if kind != ATTENTION_CHECK:
        return gettext(_pick(REMINDERS, section_pk, index))
    key, _sep, value = instructed.partition("=")
    q = next((q for q in questions if q.key == key), None)
    if q is None:
        return gettext(_pick(REMINDERS, section_pk, index))
    label = next((lbl for v, lbl in q.choices if v == value), "")
    answer = value if q.kind == "scale" or not label else label
    return gettext(_pick(INSTRUCTIONS, section_pk, index)).format(question=q.text, answer=answer)
