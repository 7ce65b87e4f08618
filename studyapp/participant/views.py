"""Participant pages. All state lives in the database; the participant token travels in the URL (and the session
remembers it per study), so a reload, the back button, a second tab or a server restart resumes exactly where the
participant was. Every page is a server-rendered form with POST-redirect-GET, except that a clip page's own form
is answered with the next clip page directly (one request per answered clip, INLINE_NEXT_FIELD; the browser's
history entry then gets that page's URL); static/studyapp/study.js only enhances (plays, gates answers until the
clip has played, measures response time, preloads the next clip, sets that URL).
"""
from __future__ import annotations

import hashlib
import math
import secrets

from django.conf import settings
from django.db import IntegrityError, transaction
from django.db.models import F
from django.http import Http404, HttpResponse
from django.shortcuts import get_object_or_404, redirect, render
from django.urls import reverse
from django.utils import timezone
from django.utils.crypto import constant_time_compare
from django.utils.translation import gettext
from django.views.decorators.cache import never_cache
from django.views.decorators.http import require_http_methods, require_POST

from protocol.vocabulary import ATTENTION_CHECK

from ..data.section_pages import due_page
from ..i18n import activate_study_language
from ..models import Assignment, Clip, Participant, Response, Study
from ..permissions import has_staff_permission
from ..questions import AnswerError, clean_answers, questions_for
from . import start_throttle
from .assignment import StudyUnavailable, check_open, current_step, start_participant
from .device_check import device_context, device_record, refusal
from .duration import expected_minutes
from .forms import PARAM_MAX_LENGTH, PARAM_TOO_LONG, ConsentForm, DemographicsForm, FeedbackForm
from .item_questions import questions_html
from .media import accel_redirect_response, media_path, ranged_file_response
from .page_notes import page_note
from .page_reads import participant_by_token
from .section_wording import participant_wording
from .viewing import (
    MAX_COUNT,
    PLAYBACK_EVENTS,
    SCRIPT_FIELD,
    VIEWING_FORM_FIELDS,
    carried_counts,
    parse_viewing,
    player_options,
    plays_left,
)

SESSION_KEY = "study_tokens"
CONSENT_KEYS = "consent_keys"
PROLIFIC_PARAMS = ("PROLIFIC_PID", "STUDY_ID", "SESSION_ID")
PROLIFIC_CONFLICT = ("This Prolific ID has already started this study in another browser, with a different "
                     "study or session link. Please continue in the browser where you started, or open the study "
                     "again from the same Prolific link. If you think this is a mistake, message the researchers "
                     "on Prolific.")
MAX_RESPONSE_MS = 3_600_000
# A client-measured response time may exceed the server's (first display to answer) by at most this much (clock
# granularity, the time the POST took); anything beyond is not a measurement and the server's is kept.
RT_SLACK_MS = 5_000
# Fraction of a clip's duration that must pass between showing a clip and accepting its answer when the section
# requires the clip to play first (server-side check; JS gates the form on the `ended` event).
MIN_PLAY_FRACTION = 0.8


def home(request):
    """The site's front page: lists only open studies that ask to be listed (Study.listed_publicly); the others
    are reached by their link (Prolific, e-mail), so their slugs are not handed to anyone who asks."""
    studies = Study.objects.filter(status=Study.Status.OPEN, listed_publicly=True).order_by("title")
    return render(request, "studyapp/home.html", {"studies": studies})


def remember_participant(request, participant: Participant) -> None:
    """Keep the participant's token in the session under its study's slug, so that the study's link resumes it."""
    tokens = dict(request.session.get(SESSION_KEY, {}))
    tokens[participant.study.slug] = participant.token
    request.session[SESSION_KEY] = tokens


def _unavailable(request, study: Study, message: str, status: int = 200):
    activate_study_language(study)
    return render(request, "studyapp/unavailable.html", {"study": study, "message": message}, status=status)


def _prolific_params(request) -> dict[str, str]:
    """PROLIFIC_PID, STUDY_ID and SESSION_ID from the form or the URL (not truncated: the form checks lengths)."""
    return {k: (request.POST.get(k) or request.GET.get(k) or "").strip() for k in PROLIFIC_PARAMS}


def _param_errors(params: dict[str, str]) -> list[str]:
    return [PARAM_TOO_LONG.format(name=k) for k, v in params.items() if len(v) > PARAM_MAX_LENGTH]


def prolific_match(participant: Participant, params: dict[str, str]) -> bool:
    """True when the link's PROLIFIC_PID, STUDY_ID and SESSION_ID all equal the participant's stored ones. A
    participant stored without a SESSION_ID never matches: a bare PID is not a credential."""
    stored = (participant.external_id, participant.external_study_id, participant.external_session_id)
    if not all(stored):
        return False
    return all(constant_time_compare(a, params.get(k, "")) for a, k in zip(stored, PROLIFIC_PARAMS, strict=True))


def _consent_key(request, study: Study, posted: str, pid: str) -> str:
    """The stored form of this browser session's one-time consent key ('' if the posted key is not the one the
    session was given): equal for two submits of the same consent form, so the second finds the first's
    participant."""
    issued = request.session.get(CONSENT_KEYS, {}).get(study.slug, "")
    if not issued or not posted or not constant_time_compare(issued, posted):
        return ""
    return hashlib.sha256(f"{issued}\0{pid}".encode()).hexdigest()


def _issue_consent_key(request, study: Study) -> str:
    keys = dict(request.session.get(CONSENT_KEYS, {}))
    if study.slug not in keys:
        keys[study.slug] = secrets.token_urlsafe(24)
        request.session[CONSENT_KEYS] = keys
    return keys[study.slug]


def _retire_consent_key(request, study: Study) -> None:
    keys = dict(request.session.get(CONSENT_KEYS, {}))
    if keys.pop(study.slug, None) is not None:
        request.session[CONSENT_KEYS] = keys


def _prolific_conflict(request, study: Study):
    return _unavailable(request, study, PROLIFIC_CONFLICT, status=403)


def _too_many_starts(request, study: Study, wait_s: float):
    """429 with Retry-After: this address started many participants just now (studyapp.participant.start_throttle)."""
    seconds = max(1, math.ceil(wait_s))
    response = _unavailable(request, study, gettext(
        "Many people have just started this study from your network. Please wait %(seconds)d seconds, then open "
        "the study link again.") % {"seconds": seconds}, status=429)
    response["Retry-After"] = str(seconds)
    return response


@never_cache
@require_http_methods(["GET", "HEAD", "POST"])
def study_entry(request, slug: str):
    """Welcome + consent. Resumes a known participant instead of restarting: the one this browser session
    remembers, or the one whose stored PROLIFIC_PID, STUDY_ID and SESSION_ID all equal the link's (a Prolific
    participant on another device). A PID alone never resumes anyone."""
    study = get_object_or_404(Study, slug=slug)
    activate_study_language(study)
    params = _prolific_params(request)
    pid = params["PROLIFIC_PID"]
    remembered = request.session.get(SESSION_KEY, {}).get(study.slug)
    mine = Participant.objects.filter(study=study, token=remembered).first() if remembered else None
    if pid and len(pid) <= PARAM_MAX_LENGTH:
        existing = Participant.objects.filter(study=study, external_id=pid).first()
        if existing:
            if mine is not None and mine.pk == existing.pk:
                _store_missing_ids(existing, params)
                return redirect("studyapp:resume", token=existing.token)
            if prolific_match(existing, params):
                remember_participant(request, existing)
                return redirect("studyapp:resume", token=existing.token)
            return _prolific_conflict(request, study)
    if mine is not None and not pid:
        return redirect("studyapp:resume", token=mine.token)
    try:
        check_open(study)
    except StudyUnavailable as exc:
        return _unavailable(request, study, str(exc))
    if request.method == "POST":
        data = request.POST.copy()
        for key in PROLIFIC_PARAMS:        # the form carries them hidden; the URL may carry them too
            if not data.get(key) and request.GET.get(key):
                data[key] = request.GET[key]
        form = ConsentForm(data)
        device = device_record(request.POST, request.headers.get("User-Agent", ""))
        if (turned_away := refusal(study, device)) is not None:
            return render(request, "studyapp/device_refused.html", {"study": study, "message": turned_away})
        if form.is_valid():
            data = form.cleaned_data
            key = _consent_key(request, study, request.POST.get("consent_key", ""), data["PROLIFIC_PID"])
            wait = start_throttle.admit(request)
            if wait and not (key and Participant.objects.filter(study=study, consent_key=key).exists()):
                return _too_many_starts(request, study, wait)
            try:
                with transaction.atomic():
                    participant = Participant.objects.create(
                        study=study, external_id=data["PROLIFIC_PID"], external_study_id=data["STUDY_ID"],
                        external_session_id=data["SESSION_ID"], consent_key=key,
                        user_agent=request.headers.get("User-Agent", "")[:300], **device)
            except IntegrityError:
                # The same consent form submitted twice (double click), or the same Prolific PID consenting in
                # another tab a moment ago: only the same browser session or the same full Prolific triple
                # gets that participant.
                participant = Participant.objects.filter(study=study, consent_key=key).first() if key else None
                if participant is None and data["PROLIFIC_PID"]:
                    other = Participant.objects.filter(study=study, external_id=data["PROLIFIC_PID"]).first()
                    if other is not None and prolific_match(other, data):
                        participant = other
                if participant is None:
                    return _prolific_conflict(request, study)
            request.session.cycle_key()      # a session planted before consent does not carry over to the answers
            remember_participant(request, participant)
            _retire_consent_key(request, study)
            return redirect("studyapp:resume", token=participant.token)
    else:
        form = ConsentForm(initial={k: v for k, v in params.items() if len(v) <= PARAM_MAX_LENGTH})
    errors = _param_errors(params) if request.method != "POST" else [
        e for f in form.hidden_fields() for e in f.errors]
    link_params = {k: v for k, v in params.items() if len(v) <= PARAM_MAX_LENGTH}   # never echo an over-long one
    return render(request, "studyapp/consent.html", {"study": study, "form": form, "param_errors": errors,
                                                     "expected_minutes": expected_minutes(study),
                                                     "link_params": link_params,
                                                     "consent_key": _issue_consent_key(request, study),
                                                     **device_context(study)})


def _store_missing_ids(participant: Participant, params: dict[str, str]) -> None:
    """Fill in a participant's STUDY_ID / SESSION_ID when they were not stored yet (older participants)."""
    updates = {}
    for field, key in (("external_study_id", "STUDY_ID"), ("external_session_id", "SESSION_ID")):
        value = params.get(key, "")
        if not getattr(participant, field) and value and len(value) <= PARAM_MAX_LENGTH:
            updates[field] = value
    if updates:
        Participant.objects.filter(pk=participant.pk).update(**updates)


def participant_or_404(token: str) -> Participant:
    """The participant of a URL token with its study (404 if none), the study's language activated."""
    participant = participant_by_token(token)
    if participant is None:
        raise Http404("No participant with this token")
    activate_study_language(participant.study)
    return participant


@never_cache
def resume(request, token: str):
    """Send the participant to the page where they are (computed from the database)."""
    participant = participant_or_404(token)
    step = current_step(participant)
    if step.kind == "start":
        try:
            start_participant(participant)
        except StudyUnavailable as exc:
            return _unavailable(request, participant.study, str(exc))
        step = current_step(participant)
    if step.kind == "demographics":
        return redirect("studyapp:demographics", token=token)
    if step.kind == "item":
        return redirect("studyapp:item", token=token, n=step.index)
    if step.kind == "page":
        return redirect("studyapp:page", token=token, n=step.index)
    if step.kind == "feedback":
        return redirect("studyapp:feedback", token=token)
    mark_completed(participant)
    return redirect("studyapp:done", token=token)


@never_cache
@require_http_methods(["GET", "HEAD", "POST"])
def demographics(request, token: str):
    participant = participant_or_404(token)
    if participant.demographics_done:
        return redirect("studyapp:resume", token=token)
    form = DemographicsForm(request.POST or None)
    if request.method == "POST" and form.is_valid():
        Participant.objects.filter(pk=participant.pk, demographics_done=False).update(
            gender=form.cleaned_data["gender"], age_group=form.cleaned_data["age_group"], demographics_done=True)
        return redirect("studyapp:resume", token=token)
    return render(request, "studyapp/demographics.html", {"participant": participant, "study": participant.study,
                                                          "form": form})


def clip_sources(clip: Clip) -> dict:
    """Opaque media URLs of a clip (its random media key, never its id or emotion)."""
    urls = {"mp4": reverse("studyapp:media", kwargs={"key": clip.media_key, "ext": "mp4"})}
    if clip.webm:
        urls["webm"] = reverse("studyapp:media", kwargs={"key": clip.media_key, "ext": "webm"})
    if clip.poster:
        urls["poster"] = reverse("studyapp:media", kwargs={"key": clip.media_key, "ext": "png"})
    return urls


def item_context(section, clip, index: int, total: int, next_clip: Clip | None, options: list[str] | None,
                 posted=None, kind: str = "", instructed: str = "", plays_before: int = 0,
                 ended_before: bool = False, playback_url: str = "") -> dict:
    """Template context of a clip page (participant and preview share it). kind/instructed: the assignment's
    (a practice item is marked "Practice"; an attention check asks one question with its instruction).
    plays_before / ended_before: the plays and the end the player reported during earlier displays of the page
    (a reload); playback_url: where the player reports them (none in the preview)."""
    questions = item_questions(section, clip, options, kind, instructed)
    fields = [{"q": q, "selected": posted.getlist(q.key) if posted is not None else []} for q in questions]
    player = player_options(section.options)
    left = plays_left(plays_before, player["max_replays"])
    section_title, section_text = participant_wording(section)
    return {"section": section, "section_title": section_title, "section_text": section_text, "fields": fields,
            "questions_html": questions_html(fields),
            "sources": clip_sources(clip),
            "next_sources": clip_sources(next_clip) if next_clip else None,
            "loop": section.loop or clip.loop, "require_play": section.require_full_play,
            "player": player, "viewing_fields": VIEWING_FORM_FIELDS, "script_field": SCRIPT_FIELD,
            "plays_before": plays_before, "ended_before": ended_before, "playback_url": playback_url,
            "autoplay": left is None or left > 0,
            "index": index, "total": total, "percent": int(round(100 * (index - 1) / max(total, 1))),
            "practice": kind == Assignment.Kind.PRACTICE,
            "page_note": page_note(questions, kind, instructed, section.pk or 0, index)}


def item_questions(section, clip, options: list[str] | None, kind: str = "", instructed: str = "") -> list:
    """The questions of one clip page: the section's, an attention check's too (its page looks like any other
    of the section; only the instructed question's answer is stored, studyapp.participant.page_notes)."""
    return questions_for(section.section_type, section.options, clip.theme, options)


def client_ms(raw, server_ms: int) -> int | None:
    """The browser's response time (ms) when it is a plausible measurement: finite, 0..MAX_RESPONSE_MS and not
    longer than the server's own measurement plus RT_SLACK_MS. None (use the server's) otherwise: "inf", "1e400",
    "nan", "-5", "9e99", text..."""
    try:
        value = float(str(raw)[:32])
    except (TypeError, ValueError):
        return None
    if not math.isfinite(value) or not 0 <= value <= min(MAX_RESPONSE_MS, server_ms + RT_SLACK_MS):
        return None
    return int(value)


def step_url(token: str, step) -> str:
    """The URL of a participant's step (the clip page, an instruction or break page, feedback or done), without
    going through /resume."""
    if step.kind in ("item", "page"):
        return reverse(f"studyapp:{step.kind}", kwargs={"token": token, "n": step.index})
    if step.kind in ("feedback", "done"):
        return reverse(f"studyapp:{step.kind}", kwargs={"token": token})
    return reverse("studyapp:resume", kwargs={"token": token})


def _after_answer_url(participant: Participant, n: int) -> str:
    """Where the answer to clip n sends the participant: an instruction or break page due before clip n + 1, or
    clip n + 1, or the feedback page, or the end (the participant is then marked completed). No query unless the
    study ends here."""
    token = participant.token
    page = due_page(participant.pages, n + 1 if n < participant.n_items else None)
    if page is not None:
        return reverse("studyapp:page", kwargs={"token": token, "n": page})
    if n < participant.n_items:
        return reverse("studyapp:item", kwargs={"token": token, "n": n + 1})
    if participant.study.feedback_questions and not participant.feedback_done:
        return reverse("studyapp:feedback", kwargs={"token": token})
    mark_completed(participant)
    return reverse("studyapp:done", kwargs={"token": token})


def mark_completed(participant: Participant) -> None:
    """Record the end of the study once (status completed, completed_at)."""
    if participant.status != Participant.Status.COMPLETED:
        Participant.objects.filter(pk=participant.pk, completed_at__isnull=True).update(
            status=Participant.Status.COMPLETED, completed_at=timezone.now())


# The clip page's form carries this field: its answer POST is then answered with the next clip page itself
# (static/studyapp/study.js puts that page's own URL into the address bar), one request per answered clip instead
# of POST + redirect + GET. A POST without it (a script, a page from before) gets the redirect.
INLINE_NEXT_FIELD = "inline_next"
# The clip number the form was shown for: an answer POST whose number is not its URL's is refused (see item).
PAGE_FIELD = "page"


@never_cache
@require_http_methods(["GET", "HEAD", "POST"])
def item(request, token: str, n: int):
    """Clip number n (1-based over all of the participant's clips): show it, or save its answers and go straight
    to the next clip (or the feedback / end page): the next clip page itself when the form asked for it
    (INLINE_NEXT_FIELD), else a redirect. A constant number of indexed queries: the participant, its first
    unanswered assignments, and on GET the one UPDATE of shown_at when first shown."""
    participant = participant_or_404(token)
    step = current_step(participant, lookahead=request.method != "POST")
    if step.kind != "item" or step.index != n:
        if request.method == "POST" and (step.kind != "item" or n < step.index):
            # An answer for a clip that is already answered: a double submit or a resubmitted old page.
            return redirect(step_url(token, step))
        if request.method == "POST":
            return _render_item(request, participant, step, status=409,
                                error=gettext("Please answer the clips in order: this is the clip you are on."))
        return redirect("studyapp:resume", token=token)
    assignment = step.assignment
    if request.method != "POST":
        return _show_item(request, participant, step)
    if request.POST.get(PAGE_FIELD, str(n)) != str(n):
        # The answers of another clip page sent to this page's URL: a browser that resends the POST which brought
        # this page when the page is reloaded (WebKit keeps that POST's data after history.replaceState). They are
        # not this clip's answers: show the page again.
        return redirect(step_url(token, step))
    section, clip = assignment.section, assignment.clip
    questions = item_questions(section, clip, assignment.options, assignment.kind, assignment.instructed)
    try:
        answers = clean_answers(questions, request.POST)
    except AnswerError as exc:
        return _render_item(request, participant, step, status=400, error=str(exc))
    now = timezone.now()
    shown = assignment.shown_at or now
    if section.require_full_play and clip.duration_s and (now - shown).total_seconds() < MIN_PLAY_FRACTION * min(
            clip.duration_s, 120):
        return _render_item(request, participant, step, status=400,
                            error=gettext("Please watch the whole clip before answering."))
    server_ms = min(max(int((now - shown).total_seconds() * 1000), 0), 2**31 - 1)
    response_ms = client_ms(request.POST.get("rt", ""), server_ms)
    if response_ms is None:
        response_ms = server_ms
    player = player_options(section.options)
    viewing = parse_viewing(request.POST, min(MAX_RESPONSE_MS, server_ms), clip.duration_s,
                            {"plays": assignment.plays, "ended_ms": assignment.play_ended_ms,
                             "shows": assignment.shows, "carried": assignment.carried},
                            time_slack_ms=RT_SLACK_MS, max_replays=player["max_replays"],
                            fetched=assignment.fetched_at is not None, controls=player["controls"])
    save_answers(assignment, answers, response_ms, viewing)
    if request.POST.get(INLINE_NEXT_FIELD) == "1" and n < participant.n_items:
        nxt = current_step(participant, lookahead=True)
        if nxt.kind == "item" and nxt.index == n + 1:
            return _show_item(request, participant, nxt)
    return redirect(_after_answer_url(participant, n))


def _show_item(request, participant: Participant, step):
    """The clip page of `step` as first shown (no answer selected), recording shown_at the first time it is
    shown and counting every display (a GET, or the answer POST that brings the next clip page; a HEAD, e.g. an
    uptime monitor's, shows nothing and records nothing). The browser session is given the participant, so its
    player may fetch the clip (``media``)."""
    assignment = step.assignment
    if request.method != "HEAD":
        if assignment.shown_at is None:
            Assignment.objects.filter(pk=assignment.pk, shown_at__isnull=True).update(
                shown_at=timezone.now(), shows=F("shows") + 1)
        else:
            Assignment.objects.filter(pk=assignment.pk).update(shows=F("shows") + 1)
        if request.session.get(SESSION_KEY, {}).get(participant.study.slug) != participant.token:
            remember_participant(request, participant)
    return _render_item(request, participant, step, posted=None)


def save_answers(assignment: Assignment, answers: dict[str, str], response_ms: int,
                 viewing: dict | None = None) -> bool:
    """Store the answers of one clip exactly once (one transaction: a conditional UPDATE claims the assignment
    and stores its viewing record, one INSERT of its responses, one UPDATE of the participant's last activity).
    Returns False if they were already stored. A practice item stores no responses; an attention check stores the
    answer to its instructed question only, with kind ATTENTION_CHECK and question ``<key>=<instructed answer>``."""
    now = timezone.now()
    try:
        with transaction.atomic():
            claimed = Assignment.objects.filter(pk=assignment.pk, answered_at__isnull=True).update(
                answered_at=now, viewing=viewing)
            if not claimed:
                return False
            if assignment.kind != Assignment.Kind.PRACTICE:
                attention = assignment.kind == ATTENTION_CHECK
                asked = assignment.instructed.partition("=")[0]
                Response.objects.bulk_create([
                    Response(participant_id=assignment.participant_id, section_id=assignment.section_id,
                             clip_id=assignment.clip_id, question=assignment.instructed if attention else key,
                             answer=value, response_ms=response_ms, kind=assignment.kind)
                    for key, value in answers.items() if not attention or key == asked])
            Participant.objects.filter(pk=assignment.participant_id).update(last_active_at=now)
    except IntegrityError:      # unique_response caught a concurrent duplicate
        return False
    return True


_POSTED = object()


def _render_item(request, participant: Participant, step, status: int = 200, error: str = "", posted=_POSTED):
    """The clip page of `step`; posted: the answers to show selected (default: this request's POST, if any)."""
    assignment = step.assignment
    nxt = step.next_assignment
    if posted is _POSTED:
        posted = request.POST if request.method == "POST" else None
    ctx = item_context(assignment.section, assignment.clip, step.index, step.total, nxt.clip if nxt else None,
                       assignment.options, posted, assignment.kind, assignment.instructed,
                       plays_before=assignment.plays, ended_before=assignment.play_ended_ms is not None,
                       playback_url=reverse("studyapp:playback", kwargs={"token": participant.token,
                                                                        "n": step.index}))
    ctx.update({"participant": participant, "study": participant.study, "error": error,
                "first_of_section": assignment.position == 0,
                "form_action": reverse("studyapp:item", kwargs={"token": participant.token, "n": step.index}),
                "inline_next_field": INLINE_NEXT_FIELD, "page_field": PAGE_FIELD})
    return render(request, "studyapp/item.html", ctx, status=status)


@never_cache
@require_POST
def playback(request, token: str, n: int):
    """The player's report (static/studyapp/study.js) of a play from the start, of the clip's first end, or of the
    counts of a display being left without an answer (a reload) on clip page n, kept on the assignment while it is
    unanswered: a reload then keeps the plays (max_replays holds), the end and the counts. 204; 400 for an unknown
    event; 404 when page n is not the participant's current page."""
    participant = participant_or_404(token)
    event = request.POST.get("event", "")
    if event not in PLAYBACK_EVENTS:
        return HttpResponse(status=400)
    unanswered = Assignment.objects.filter(participant=participant, answered_at__isnull=True)
    if unanswered.filter(seq__lt=n).exists():         # not the page the participant is on
        return HttpResponse(status=404)
    pending = unanswered.filter(seq=n)
    if event == "play":
        found = pending.filter(plays__lt=MAX_COUNT).update(plays=F("plays") + 1) or pending.exists()
    else:
        shown = pending.values_list("shown_at", flat=True).first()
        found = shown is not None
        if found:
            ms = min(max(int((timezone.now() - shown).total_seconds() * 1000), 0), 2**31 - 1)
            if event == "ended":
                pending.filter(play_ended_ms__isnull=True).update(play_ended_ms=ms)
            else:
                with transaction.atomic():
                    row = pending.select_for_update().only("pk", "carried").first()
                    if row is not None:
                        pending.filter(pk=row.pk).update(carried=carried_counts(request.POST, ms, row.carried))
    return HttpResponse(status=204 if found else 404)


@never_cache
@require_http_methods(["GET", "HEAD", "POST"])
def feedback(request, token: str):
    participant = participant_or_404(token)
    step = current_step(participant)
    if step.kind != "feedback":
        return redirect("studyapp:resume", token=token)
    form = FeedbackForm(participant.study.feedback_questions, request.POST or None)
    if request.method == "POST" and form.is_valid():
        Participant.objects.filter(pk=participant.pk, feedback_done=False).update(
            feedback=form.cleaned_data, feedback_done=True)
        mark_completed(participant)
        return redirect("studyapp:done", token=token)
    return render(request, "studyapp/feedback.html", {"participant": participant, "study": participant.study,
                                                      "form": form, "total": step.total})


@never_cache
def done(request, token: str):
    participant = participant_or_404(token)
    if current_step(participant).kind != "done":
        return redirect("studyapp:resume", token=token)
    mark_completed(participant)      # writes only for a participant who finished before this was recorded
    study = participant.study
    return render(request, "studyapp/done.html", {"participant": participant, "study": study,
                                                  "completion_url": study.completion_url()})


MEDIA_PAGES = 2
"""How many of a participant's unanswered clip pages may fetch their clip: the current page and the next one,
whose clip the player preloads once the current one can play (static/studyapp/study.js, preloadNext)."""


def media_allowed(request, clip: Clip) -> bool:
    """Whether this request may fetch ``clip``: a participant of this browser session (views.SESSION_KEY) is on
    the page showing it or on the page before, whose player preloads it (MEDIA_PAGES: the first two unanswered
    pages by seq), or a staff member who may see the catalogue (admin and preview). The URL alone is never
    enough; a clip further on in the study is not served until its page comes near, and a clip's URL stops
    working for a participant once it is answered. One query per participant of the session."""
    return bool(_near_assignments(request, clip)) or has_staff_permission(request.user, "studyapp.view_clip")


def _near_assignments(request, clip: Clip) -> list[tuple[int, object]]:
    """(pk, fetched_at) of the session's participants' near pages (MEDIA_PAGES) that show ``clip``."""
    tokens = [t for t in request.session.get(SESSION_KEY, {}).values() if isinstance(t, str)]
    for token in tokens:
        near = list(Assignment.objects.filter(participant__token=token, answered_at__isnull=True)
                    .order_by("seq").values_list("pk", "clip_id", "fetched_at")[:MEDIA_PAGES])
        found = [(pk, fetched) for pk, clip_id, fetched in near if clip_id == clip.pk]
        if found:
            return found
    return []


def _record_fetch(assignments: list[tuple[int, object]]) -> None:
    """Mark the pages whose clip this session fetched (the viewing record's server evidence), once each."""
    first = [pk for pk, fetched in assignments if fetched is None]
    if first:
        Assignment.objects.filter(pk__in=first, fetched_at__isnull=True).update(fetched_at=timezone.now())


def media(request, key: str, ext: str):
    """A clip's MP4/WebM/poster by its opaque media key, for a session that may see it (``media_allowed``, else
    403), with HTTP Range support; behind nginx (settings.MEDIA_ACCEL_REDIRECT) the bytes are handed to nginx with
    X-Accel-Redirect after these checks."""
    clip = get_object_or_404(Clip, media_key=key)
    relative = {"mp4": clip.video, "webm": clip.webm, "png": clip.poster}.get(ext, "")
    if not relative:
        return HttpResponse(status=404)
    near = _near_assignments(request, clip)
    if not near and not has_staff_permission(request.user, "studyapp.view_clip"):
        return HttpResponse("This clip is shown on its study page only.", status=403,
                            content_type="text/plain; charset=utf-8")
    if ext != "png" and request.method == "GET":
        _record_fetch(near)
    if settings.MEDIA_ACCEL_REDIRECT:
        return accel_redirect_response(media_path(relative), settings.MEDIA_ACCEL_REDIRECT)
    return ranged_file_response(request, media_path(relative))
