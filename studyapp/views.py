"""Participant pages. All state lives in the database; the participant token travels in the URL (and the session
remembers it per study), so a reload, the back button, a second tab or a server restart resumes exactly where the
participant was. Every page is a server-rendered form with POST-redirect-GET; static/studyapp/study.js only
enhances (plays, gates answers until the clip has played, measures response time, preloads the next clip).
"""
from __future__ import annotations

from django.db import IntegrityError, transaction
from django.http import HttpResponse
from django.shortcuts import get_object_or_404, redirect, render
from django.urls import reverse
from django.utils import timezone
from django.views.decorators.cache import never_cache
from django.views.decorators.http import require_http_methods

from .assignment import StudyUnavailable, check_open, current_step, start_participant
from .forms import ConsentForm, DemographicsForm, FeedbackForm
from .media import media_path, ranged_file_response
from .models import Assignment, Clip, Participant, Response, Study
from .questions import AnswerError, clean_answers, questions_for

SESSION_KEY = "study_tokens"
PROLIFIC_PARAMS = ("PROLIFIC_PID", "STUDY_ID", "SESSION_ID")
MAX_RESPONSE_MS = 3_600_000
# Fraction of a clip's duration that must pass between showing a clip and accepting its answer when the section
# requires the clip to play first (server-side check; JS gates the form on the `ended` event).
MIN_PLAY_FRACTION = 0.8


def home(request):
    studies = Study.objects.filter(status=Study.Status.OPEN).order_by("title")
    return render(request, "studyapp/home.html", {"studies": studies})


def _remember(request, participant: Participant) -> None:
    tokens = dict(request.session.get(SESSION_KEY, {}))
    tokens[participant.study.slug] = participant.token
    request.session[SESSION_KEY] = tokens


def _unavailable(request, study: Study, message: str, status: int = 200):
    return render(request, "studyapp/unavailable.html", {"study": study, "message": message}, status=status)


@never_cache
@require_http_methods(["GET", "POST"])
def study_entry(request, slug: str):
    """Welcome + consent. Resumes a known participant (session, or the same Prolific PID) instead of restarting."""
    study = get_object_or_404(Study, slug=slug)
    pid = (request.POST.get("PROLIFIC_PID") or request.GET.get("PROLIFIC_PID") or "").strip()[:100]
    if pid:
        existing = Participant.objects.filter(study=study, external_id=pid).first()
        if existing:
            _remember(request, existing)
            return redirect("studyapp:resume", token=existing.token)
    token = request.session.get(SESSION_KEY, {}).get(study.slug)
    if token and not pid:
        existing = Participant.objects.filter(study=study, token=token).first()
        if existing:
            return redirect("studyapp:resume", token=existing.token)
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
        if form.is_valid():
            data = form.cleaned_data
            try:
                with transaction.atomic():
                    participant = Participant.objects.create(
                        study=study, external_id=data["PROLIFIC_PID"], external_study_id=data["STUDY_ID"],
                        external_session_id=data["SESSION_ID"],
                        user_agent=request.headers.get("User-Agent", "")[:300])
            except IntegrityError:       # the same Prolific PID consented in another tab a moment ago
                participant = Participant.objects.get(study=study, external_id=data["PROLIFIC_PID"])
            _remember(request, participant)
            return redirect("studyapp:resume", token=participant.token)
    else:
        form = ConsentForm(initial={k: request.GET.get(k, "") for k in PROLIFIC_PARAMS})
    return render(request, "studyapp/consent.html", {"study": study, "form": form})


def _participant(token: str) -> Participant:
    return get_object_or_404(Participant.objects.select_related("study"), token=token)


@never_cache
def resume(request, token: str):
    """Send the participant to the page where they are (computed from the database)."""
    participant = _participant(token)
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
    if step.kind == "feedback":
        return redirect("studyapp:feedback", token=token)
    if participant.status != Participant.Status.COMPLETED:
        Participant.objects.filter(pk=participant.pk, completed_at__isnull=True).update(
            status=Participant.Status.COMPLETED, completed_at=timezone.now())
    return redirect("studyapp:done", token=token)


@never_cache
@require_http_methods(["GET", "POST"])
def demographics(request, token: str):
    participant = _participant(token)
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
                 posted=None) -> dict:
    """Template context of a clip page (participant and preview share it)."""
    questions = questions_for(section.section_type, section.options, clip.theme, options)
    fields = [{"q": q, "selected": posted.getlist(q.key) if posted is not None else []} for q in questions]
    return {"section": section, "fields": fields, "sources": clip_sources(clip),
            "next_sources": clip_sources(next_clip) if next_clip else None,
            "loop": section.loop or clip.loop, "require_play": section.require_full_play,
            "index": index, "total": total, "percent": int(round(100 * (index - 1) / max(total, 1)))}


def _client_ms(request) -> int | None:
    try:
        value = int(float(request.POST.get("rt", "")))
    except (TypeError, ValueError):
        return None
    return value if 0 <= value <= MAX_RESPONSE_MS else None


@never_cache
@require_http_methods(["GET", "POST"])
def item(request, token: str, n: int):
    """Clip number n (1-based over all of the participant's clips): show it, or save its answers."""
    participant = _participant(token)
    step = current_step(participant)
    if step.kind != "item" or step.index != n:
        if request.method == "POST" and (step.kind != "item" or n < step.index):
            # An answer for a clip that is already answered: a double submit or a resubmitted old page.
            return redirect("studyapp:resume", token=token)
        if request.method == "POST":
            return _render_item(request, participant, step, status=409,
                                error="Please answer the clips in order: this is the clip you are on.")
        return redirect("studyapp:resume", token=token)
    assignment = step.assignment
    if request.method == "GET":
        if assignment.shown_at is None:
            Assignment.objects.filter(pk=assignment.pk, shown_at__isnull=True).update(shown_at=timezone.now())
        return _render_item(request, participant, step)
    section, clip = assignment.section, assignment.clip
    questions = questions_for(section.section_type, section.options, clip.theme, assignment.options)
    try:
        answers = clean_answers(questions, request.POST)
    except AnswerError as exc:
        return _render_item(request, participant, step, status=400, error=str(exc))
    now = timezone.now()
    shown = assignment.shown_at or now
    if section.require_full_play and clip.duration_s and (now - shown).total_seconds() < MIN_PLAY_FRACTION * min(
            clip.duration_s, 120):
        return _render_item(request, participant, step, status=400,
                            error="Please watch the whole clip before answering.")
    response_ms = _client_ms(request)
    if response_ms is None:
        response_ms = int((now - shown).total_seconds() * 1000)
    save_answers(assignment, answers, response_ms)
    return redirect("studyapp:resume", token=token)


def save_answers(assignment: Assignment, answers: dict[str, str], response_ms: int) -> bool:
    """Store the answers of one clip exactly once. Returns False if they were already stored."""
    try:
        with transaction.atomic():
            locked = Assignment.objects.select_for_update().get(pk=assignment.pk)
            if locked.answered_at is not None:
                return False
            Response.objects.bulk_create([
                Response(participant_id=locked.participant_id, section_id=locked.section_id, clip_id=locked.clip_id,
                         question=key, answer=value, response_ms=response_ms) for key, value in answers.items()])
            locked.answered_at = timezone.now()
            locked.save(update_fields=["answered_at"])
            Participant.objects.filter(pk=locked.participant_id).update(last_active_at=locked.answered_at)
    except IntegrityError:      # unique_response caught a concurrent duplicate
        return False
    return True


def _render_item(request, participant: Participant, step, status: int = 200, error: str = ""):
    assignment = step.assignment
    nxt = (participant.assignments.filter(answered_at__isnull=True)
           .exclude(pk=assignment.pk).select_related("clip", "section")
           .order_by("section__order", "section_id", "position").first())
    ctx = item_context(assignment.section, assignment.clip, step.index, step.total, nxt.clip if nxt else None,
                       assignment.options, request.POST if request.method == "POST" else None)
    ctx.update({"participant": participant, "study": participant.study, "error": error,
                "first_of_section": assignment.position == 0})
    return render(request, "studyapp/item.html", ctx, status=status)


@never_cache
@require_http_methods(["GET", "POST"])
def feedback(request, token: str):
    participant = _participant(token)
    step = current_step(participant)
    if step.kind != "feedback":
        return redirect("studyapp:resume", token=token)
    form = FeedbackForm(participant.study.feedback_questions, request.POST or None)
    if request.method == "POST" and form.is_valid():
        Participant.objects.filter(pk=participant.pk, feedback_done=False).update(
            feedback=form.cleaned_data, feedback_done=True)
        return redirect("studyapp:resume", token=token)
    return render(request, "studyapp/feedback.html", {"participant": participant, "study": participant.study,
                                                      "form": form, "total": step.total})


@never_cache
def done(request, token: str):
    participant = _participant(token)
    if current_step(participant).kind != "done":
        return redirect("studyapp:resume", token=token)
    study = participant.study
    return render(request, "studyapp/done.html", {"participant": participant, "study": study,
                                                  "completion_url": study.completion_url()})


def media(request, key: str, ext: str):
    """A clip's MP4/WebM/poster by its opaque media key, with HTTP Range support."""
    clip = get_object_or_404(Clip, media_key=key)
    relative = {"mp4": clip.video, "webm": clip.webm, "png": clip.poster}.get(ext, "")
    if not relative:
        return HttpResponse(status=404)
    return ranged_file_response(request, media_path(relative))
