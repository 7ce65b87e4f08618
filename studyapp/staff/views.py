"""Researcher pages (staff only): create from preset, preview without recording, progress, exports, report.

Each page needs a staff account (else the admin login) and one Django permission (else 403): creating a study
studyapp.add_study, preview and progress studyapp.view_study, CSV exports and the analysis report (participant
data, external ids pseudonymised unless the study asks) studyapp.export_participant_data, the external ids for
payment studyapp.download_payment_ids (studyapp.data.privacy). Every staff page and download is sent with
``Cache-Control: no-store`` (studyapp.security.NoStoreMiddleware). A study's pages also need access to that study
(its owner or a collaborator, or a superuser): another lab's study is a 404 (studyapp.permissions.study_of). The
researcher who creates a study from a preset becomes its owner.
"""
from __future__ import annotations

import tempfile
import zipfile
from pathlib import Path

from django.contrib import messages
from django.db.models import Count, Q
from django.http import Http404, StreamingHttpResponse
from django.shortcuts import redirect, render
from django.urls import reverse
from django.utils.html import format_html
from django.utils.http import content_disposition_header
from django.views.decorators.http import require_http_methods

from generation.plans.schema import PlanError, load_plan
from generation.render import contact_sheet
from protocol.presets import PRESET_PLANS
from protocol.section_types.pages import makes_wait, wait_seconds
from protocol.vocabulary import ATTENTION_CHECK

from ..data.catalogue import clip_label
from ..data.clip_display import clip_cells
from ..data.export import EXPORT_KINDS, csv_lines, stream_csv, write_data_package
from ..data.privacy import PAYMENT_COLUMNS, PAYMENT_PERMISSION, payment_rows
from ..data.section_pages import is_page
from ..i18n import activate_study_language
from ..models import Assignment, Clip, Participant, Response, Study
from ..participant.assignment import plan_study
from ..participant.forms import ConsentForm
from ..participant.media import media_path
from ..participant.streaming import body, file_body
from ..participant.views import item_context, item_questions
from ..participant.views_pages import page_wording
from ..permissions import EXPORT_PERMISSION, staff_permission_required, study_of
from ..questions import AnswerError, clean_answers
from .forms import CloneStudyForm, PresetStudyForm, SharePreviewForm
from .pilots import delete_pilot_data, pilot_count
from .presets import create_study_from_preset
from .progress_stats import progress_stats
from .reports import report_state, start_build
from .sharing import preview_token, prolific_completion_url, prolific_study_url
from .study_clone import clone_study


@staff_permission_required("studyapp.add_study")
@require_http_methods(["GET", "POST"])
def create_from_preset(request):
    """The "New study from preset" page (studyapp.add_study): creates a draft study owned by the researcher, offers to
    render the preset's plan when clips are missing and opens the study's admin page."""
    form = PresetStudyForm(request.POST or None)
    if request.method == "POST" and form.is_valid():
        d = form.cleaned_data
        study = create_study_from_preset(d["preset"], d["slug"], d["title"] or None)
        study.owners.add(request.user)
        messages.success(request, f"Created '{study.title}' from preset {d['preset']} (status: draft).")
        offer = render_offer(d["preset"])
        if offer:
            messages.warning(request, offer)
        return redirect(reverse("admin:studyapp_study_change", args=[study.pk]))
    return render(request, "studyapp/staff/create_from_preset.html", {"form": form, "title": "New study from preset"})


def render_offer(preset: str):
    """A message offering to render the preset's plan when the catalogue lacks some of its clips (None when it has
    them all): the study's pools draw only clips of that plan."""
    plan = PRESET_PLANS.get(preset)
    if not plan:
        return None
    try:
        planned = len(load_plan(plan).entries)
    except PlanError:
        return None
    have = Clip.objects.filter(plan=plan, retired=False).count()
    if have >= planned:
        return None
    url = reverse("admin:studyapp_clip_stimuli") + f"?plan={plan}#builtin-{plan}"
    return format_html('Its sections draw the clips of plan {}: the catalogue holds {} of its {}. '
                       '<a href="{}" id="render-preset-plan">Render the stimulus set {} now</a> (in the background).',
                       plan, have, planned, url, plan)


def _preview_plan(study: Study, seed: int):
    """The preview participant's steps in the study's order (a counterbalanced study rotates the sections per
    participant; the preview does not): (section, PlannedItem, position in section) for each clip page, practice
    items and attention checks included, and (section, None, 0) for each instruction or break page at its place."""
    sections = list(study.sections.order_by("order", "id"))
    planned = {section.pk: items for section, items in
               plan_study(study, seed, balanced=False, sections=sections, extras=True)}
    flat = []
    for section in sections:
        if is_page(section):
            flat.append((section, None, 0))
        else:
            flat += [(section, it, i) for i, it in enumerate(planned.get(section.pk, []))]
    return flat


def _preview_label(it) -> str:
    """The preview banner's clip label: the clip id, and for a practice item or an attention check its kind (and
    the instructed answer), so the researcher sees what a participant would be scored on."""
    if it.kind == ATTENTION_CHECK:
        return f"{it.clip.clip_id} (attention check, instructed {it.instructed})"
    if it.kind == Assignment.Kind.PRACTICE:
        return f"{it.clip.clip_id} (practice, never stored)"
    return it.clip.clip_id


def _preview_seed(request) -> int:
    """The preview participant's seed from ?seed= (12345 when absent or not a whole number)."""
    raw = request.GET.get("seed", "")[:20]
    return int(raw) if raw.lstrip("-").isdigit() else 12345


@staff_permission_required("studyapp.view_study")
def preview_start(request, study_id: int):
    """The preview's consent page (studyapp.view_study), in the study's language, for a preview participant with the
    ?seed= seed."""
    study = study_of(request, study_id)
    activate_study_language(study)     # the preview shows the pages as participants see them
    seed = _preview_seed(request)
    return render(request, "studyapp/consent.html", {"study": study, "form": ConsentForm(), "preview": True,
                                                     "seed": seed})


@staff_permission_required("studyapp.view_study")
@require_http_methods(["GET", "POST"])
def preview_item(request, study_id: int, n: int):
    """Step n of a preview participant with the given seed: a clip page (answers are validated, never stored) or an
    instruction or break page, in the study's order."""
    study = study_of(request, study_id)
    activate_study_language(study)     # the preview shows the pages as participants see them
    seed = _preview_seed(request)
    flat = _preview_plan(study, seed)
    if not any(it for _, it, _ in flat):
        messages.warning(request, "No section of this study has clips: the catalogue has none matching the pools.")
        return redirect(reverse("admin:studyapp_study_change", args=[study.pk]))
    if n < 1 or n > len(flat):
        return render(request, "studyapp/done.html", {"study": study, "preview": True, "seed": seed})
    page = reverse("studyapp:preview_item", args=[study.pk, n]) + f"?seed={seed}"
    after = reverse("studyapp:preview_item", args=[study.pk, n + 1]) + f"?seed={seed}"
    it = flat[n - 1][1]
    return preview_page(request, study, flat, n, seed, page, after, {"clip_label": _preview_label(it) if it else ""})


def preview_page(request, study, flat: list, n: int, seed: int, page_url: str, next_url: str, extra: dict):
    """Step n (1-based) of a preview plan ``flat`` (_preview_plan): a clip page, whose answers posted to
    ``page_url`` are checked like a participant's and never stored (valid ones go on to ``next_url``, invalid ones
    show the page again, 400), or an instruction or break page (preview_section_page)."""
    section, it, position = flat[n - 1]
    clips = [step for step in flat if step[1] is not None]
    index = sum(1 for step in flat[:n] if step[1] is not None)          # the clip's number, as participants see it
    if it is None:
        return preview_section_page(request, study, section, seed, next_url, index, len(clips), extra)
    error = ""
    if request.method == "POST":
        try:
            clean_answers(item_questions(section, it.clip, it.options, it.kind, it.instructed), request.POST)
            return redirect(next_url)
        except AnswerError as exc:
            error = str(exc)
    nxt = clips[index][1].clip if index < len(clips) else None
    ctx = item_context(section, it.clip, index, len(clips), nxt, it.options,
                       request.POST if request.method == "POST" else None, kind=it.kind, instructed=it.instructed)
    ctx.update({"study": study, "preview": True, "seed": seed, "error": error, "first_of_section": position == 0,
                "form_action": page_url, **extra})
    return render(request, "studyapp/item.html", ctx, status=400 if error else 200)


def preview_section_page(request, study, section, seed: int, next_url: str, done: int, total: int, extra: dict):
    """An instruction or break page in a preview, with the participant's template and wording: Continue (a POST)
    goes on to ``next_url`` and records nothing. A break page's Continue is enabled at once; the page says how long
    participants wait (templates/studyapp/page.html)."""
    if request.method == "POST":
        return redirect(next_url)
    title, text = page_wording(section)
    return render(request, "studyapp/page.html", {
        "study": study, "section": section, "title": title, "text": text, "preview": True, "seed": seed,
        "is_break": makes_wait(section.section_type), "wait_left": 0, "wait_seconds": wait_seconds(section.options),
        "error": "", "percent": int(round(100 * done / max(total, 1))), **extra})


@staff_permission_required("studyapp.view_study")
def progress(request, study_id: int):
    """The study's progress page (studyapp.view_study): participants by status, the funnel and times, per-section clip
    assignments and answers, the report's state, the participant and Prolific links and the pilot count."""
    study = study_of(request, study_id)
    counts = {row["status"]: row["n"] for row in study.participants.values("status").annotate(n=Count("id"))}
    sections = []
    for section in study.sections.order_by("order", "id"):
        per_clip = (Assignment.objects.filter(section=section)
                    .values("clip__clip_id")
                    .annotate(assigned=Count("id"), answered=Count("id", filter=Q(answered_at__isnull=False)))
                    .order_by("clip__clip_id"))
        sections.append({"section": section, "clips": list(per_clip),
                         "responses": Response.objects.filter(section=section).count()})
    cells = clip_cells(c["clip__clip_id"] for s in sections for c in s["clips"])
    for s in sections:
        for c in s["clips"]:
            c["cell"] = cells.get(c["clip__clip_id"])
    report = report_state(study)
    ctx = {"study": study, "counts": counts, "sections": sections, "title": f"Progress: {study.title}",
           "report": report, "stats": progress_stats(study, report),
           "started": counts.get(Participant.Status.STARTED, 0),
           "completed": counts.get(Participant.Status.COMPLETED, 0),
           "consented": counts.get(Participant.Status.CONSENTED, 0),
           "participant_url": request.build_absolute_uri(reverse("studyapp:study_entry", args=[study.slug])),
           "prolific_url": prolific_study_url(request, study), "prolific_completion": prolific_completion_url(study),
           "n_pilot": pilot_count(study), "share_form": SharePreviewForm()}
    return render(request, "studyapp/staff/progress.html", ctx)


@staff_permission_required("studyapp.add_study")
@require_http_methods(["GET", "POST"])
def clone(request, study_id: int):
    """A draft copy of the study (texts, sections, pools; no participants), owned by whoever clones it."""
    study = study_of(request, study_id)
    form = CloneStudyForm(request.POST or None, initial={"slug": f"{study.slug}-copy"[:80],
                                                         "title": f"Copy of {study.title}"[:200]})
    if request.method == "POST" and form.is_valid():
        copy = clone_study(study, form.cleaned_data["slug"], form.cleaned_data["title"], request.user)
        messages.success(request, f"Cloned '{study.title}' as '{copy.title}' (a draft, no participants).")
        return redirect(reverse("admin:studyapp_study_change", args=[copy.pk]))
    return render(request, "studyapp/staff/clone.html", {"form": form, "study": study,
                                                         "title": f"Clone {study.title}"})


@staff_permission_required("studyapp.change_study")
@require_http_methods(["POST"])
def delete_pilot(request, study_id: int):
    """Delete the study's pilot participants and their answers (a ticked confirmation is required)."""
    study = study_of(request, study_id)
    if request.POST.get("confirm") != "yes":
        messages.error(request, "Tick the box to confirm deleting the pilot data.")
    else:
        n = delete_pilot_data(study)
        messages.success(request, f"Deleted {n} pilot participant(s) with their answers.")
    return redirect(reverse("studyapp:progress", args=[study.pk]) + "#pilot")


@staff_permission_required("studyapp.view_study")
@require_http_methods(["POST"])
def share_preview(request, study_id: int):
    """Make a signed preview link of the study (studyapp.staff.sharing) and show it on the progress page."""
    study = study_of(request, study_id)
    form = SharePreviewForm(request.POST)
    if not form.is_valid():
        messages.error(request, "A preview link lasts between 1 and 90 days.")
    else:
        days = form.cleaned_data["days"]
        url = request.build_absolute_uri(reverse("studyapp:shared_preview", args=[preview_token(study, days)]))
        messages.success(request, format_html(
            'Preview link, valid for {} day(s), for anyone who has it (no account; nothing is recorded): '
            '<input type="text" readonly class="copy-text" id="shared-preview-url" value="{}" size="60"> '
            '<button type="button" class="copy-button" data-copy="shared-preview-url">Copy</button>', days, url))
    return redirect(reverse("studyapp:progress", args=[study.pk]) + "#share")


@staff_permission_required(EXPORT_PERMISSION)
def export_csv(request, study_id: int, kind: str):
    """One CSV export of the study (``kind`` one of EXPORT_KINDS, else 404), streamed as a download; needs the export
    permission."""
    study = study_of(request, study_id)
    if kind not in EXPORT_KINDS:
        raise Http404("unknown export")
    response = StreamingHttpResponse(body(request, stream_csv(study, kind)), content_type="text/csv; charset=utf-8")
    response["Content-Disposition"] = f'attachment; filename="{study.slug}-{kind}.csv"'
    return response


@staff_permission_required(PAYMENT_PERMISSION)
def payment_ids(request, study_id: int):
    """The study's external ids (Prolific IDs) with status and completion time, for paying participants: no
    participant id and no answer, so the file cannot be joined to the data."""
    study = study_of(request, study_id)
    response = StreamingHttpResponse(body(request, csv_lines(PAYMENT_COLUMNS, payment_rows(study))),
                                     content_type="text/csv; charset=utf-8")
    response["Content-Disposition"] = f'attachment; filename="{study.slug}-payment-ids.csv"'
    return response


@staff_permission_required(EXPORT_PERMISSION)
def data_zip(request, study_id: int):
    """Every CSV export in one zip with its data dictionary and a Psych-DS dataset_description.json (pilot
    participants included, marked by their ids)."""
    study = study_of(request, study_id)
    archive = tempfile.TemporaryFile(suffix=".zip")        # unlinked: gone when the response closes it
    with tempfile.TemporaryDirectory(prefix="data-zip-") as tmp:
        paths = write_data_package(study, tmp)
        with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as zf:
            for path in paths.values():
                zf.write(path, f"{study.slug}/data/{path.name}")
    archive.seek(0)
    blocks = iter(lambda: archive.read(1 << 20), b"")     # read as sent (async under ASGI), closed with the file
    response = StreamingHttpResponse(body(request, blocks), content_type="application/zip")
    response["Content-Disposition"] = content_disposition_header(True, f"{study.slug}-data.zip")
    response._resource_closers.append(archive.close)
    return response


@staff_permission_required(EXPORT_PERMISSION)
@require_http_methods(["GET", "POST"])
def report_zip(request, study_id: int):
    """The analysis report of the study's current data. POST starts a detached build (studyapp.staff.reports) and
    returns at once to the progress page, which shows the build's status; GET sends the finished zip of the
    current data version, or goes back to the progress page when there is none yet."""
    study = study_of(request, study_id)
    if request.method == "POST":
        try:
            state = start_build(study)
        except OSError as exc:              # REPORTS_DIR not writable, no disk space, no Python to start
            messages.error(request, f"Could not start the report build: {exc}")
            return redirect(reverse("studyapp:progress", args=[study.pk]) + "#report")
        if state.status == "ready":
            messages.info(request, "The report of the current data is ready.")
        else:
            messages.info(request, "Building the report in the background; this page shows when it is ready.")
        return redirect(reverse("studyapp:progress", args=[study.pk]) + "#report")
    state = report_state(study)
    try:
        size = state.zip_path.stat().st_size if state.status == "ready" else None
    except FileNotFoundError:        # pruned by a newer build a moment ago
        size = None
    if size is None:
        messages.warning(request, "No report of the current data yet: build it first.")
        return redirect(reverse("studyapp:progress", args=[study.pk]) + "#report")
    return file_download(request, state.zip_path, size, "application/zip", f"{study.slug}-report-{state.version}.zip")


def file_download(request, path: Path, size: int, content_type: str, filename: str) -> StreamingHttpResponse:
    """An attachment streamed from ``path`` (studyapp.participant.streaming: async under ASGI, never read whole)."""
    response = StreamingHttpResponse(file_body(request, path, 0, size), content_type=content_type)
    response["Content-Length"] = str(size)
    response["Content-Disposition"] = content_disposition_header(True, filename)
    return response


def contact_sheet_response(request, clips):
    """A PNG grid of the posters of ``clips`` (a Clip queryset), captioned like generate_clips' contact sheets.

    To get a plan's sheet in the admin: filter the clip list by plan, select all, run the action.
    """


    clips = [c for c in clips.order_by("plan", "clip_id") if c.poster]
    if not clips:
        messages.error(request, "None of the selected clips has a poster image.")
        return redirect(reverse("admin:studyapp_clip_changelist"))
    try:
        posters = [media_path(c.poster) for c in clips]
    except Http404:
        messages.error(request, "Some poster files are missing from MEDIA_ROOT; rerun generate_clips for the plan.")
        return redirect(reverse("admin:studyapp_clip_changelist"))
    out = Path(tempfile.mkdtemp(prefix="contact-sheet-")) / "contact_sheet.png"
    contact_sheet(posters, [clip_label({"clip_id": c.clip_id, "origin": c.origin, "metadata": c.metadata})
                            for c in clips], out)
    plans = sorted({c.plan for c in clips if c.plan}) or ["clips"]
    return file_download(request, out, out.stat().st_size, "image/png", f"{'-'.join(plans)}-contact-sheet.png")
