"""The participant's instruction and break pages (studyapp.data.section_pages): ``p/<token>/page/<n>/``.

GET shows page n when it is the participant's current step (anything else is redirected to where the participant
is) and records its first display; POST is Continue. A break page's Continue is refused with 400 until its wait
has passed since that first display, and nothing is recorded then; static/studyapp/page.js only counts down and
enables the button. A second Continue (double click, resubmitted form) finds the page passed and is sent on to the
participant's current step, so it never skips one.
"""
from __future__ import annotations

import math

from django.shortcuts import redirect, render
from django.utils.translation import gettext
from django.views.decorators.cache import never_cache
from django.views.decorators.http import require_http_methods

from protocol.section_types.pages import makes_wait

from ..data import section_pages
from ..models import Participant, Section
from .assignment import current_step
from .views import SESSION_KEY, mark_completed, participant_or_404, remember_participant, step_url


def page_wording(section: Section) -> tuple[str, str]:
    """(title, text) of a page: the section's own, else the plain words of its kind."""
    if makes_wait(section.section_type):
        title = section.title or gettext("Short break")
        text = section.instructions or gettext(
            "Take a short rest before the next part of the study: look away from the screen, stretch, relax.")
    else:
        title = section.title or gettext("Instructions")
        text = section.instructions
    return title, text


def _render_page(request, participant: Participant, section: Section, n: int, status: int = 200, error: str = ""):
    record = participant.pages[n - 1]
    title, text = page_wording(section)
    total = participant.n_items
    done = min(max(record.get("before", 1) - 1, 0), total)
    left = math.ceil(section_pages.wait_left(section, record))
    return render(request, "studyapp/page.html", {
        "participant": participant, "study": participant.study, "section": section, "title": title, "text": text,
        "is_break": makes_wait(section.section_type), "wait_left": left, "error": error, "n": n,
        "percent": int(round(100 * done / max(total, 1)))}, status=status)


def _onwards(participant: Participant):
    """A redirect to the participant's step after a page; the end of the study is recorded when it ends here."""
    step = current_step(participant)
    if step.kind == "done":
        mark_completed(participant)
    return redirect(step_url(participant.token, step))


@never_cache
@require_http_methods(["GET", "HEAD", "POST"])
def page(request, token: str, n: int):
    """Instruction or break page n of the participant: show it, or continue from it (see the module docstring)."""
    participant = participant_or_404(token)
    step = current_step(participant)
    if step.kind != "page" or step.index != n:
        return redirect(step_url(token, step))
    record = participant.pages[n - 1]
    section = Section.objects.filter(pk=record.get("section"), study_id=participant.study_id).first()
    if section is None:            # the page was deleted from the study after this participant started
        section_pages.record(participant, n, "continued_at")
        return _onwards(participant)
    if request.method == "POST":
        left = section_pages.wait_left(section, record)
        if left > 0:
            return _render_page(request, participant, section, n, status=400, error=gettext(
                "Please rest a little longer: you can continue in %(seconds)d seconds.") % {
                "seconds": math.ceil(left)})
        section_pages.record(participant, n, "shown_at")         # a Continue without a display (no script)
        section_pages.record(participant, n, "continued_at")
        return _onwards(participant)
    if request.method != "HEAD":
        section_pages.record(participant, n, "shown_at")
        if request.session.get(SESSION_KEY, {}).get(participant.study.slug) != participant.token:
            remember_participant(request, participant)
    return _render_page(request, participant, section, n)
