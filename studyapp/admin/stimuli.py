"""The admin's stimulus pages (under the clip list): describe a stimulus set or pick a built-in plan, see its clips,
their titles and the expected render time, and render it as a background job (studyapp.data.render_jobs) whose page
shows its progress, log and contact sheet, and resumes it when it was interrupted.

Staff who may add clips (studyapp.add_clip) only; every page is wrapped by the admin site's admin_view.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from django.conf import settings
from django.contrib import messages
from django.core.exceptions import PermissionDenied
from django.http import FileResponse, Http404, HttpResponseRedirect
from django.template.response import TemplateResponse
from django.urls import reverse

from generation.plans.generators import registered
from generation.plans.schema import PlanError, builtin_plans, load_plan
from generation.plans.stimulus_set import (
    condition_examples,
    estimate_render,
    plan_yaml,
    planned_titles,
    read_records,
)

from ..data import render_jobs
from ..models import Clip
from .forms_stimuli import StimulusSetForm


@dataclass(frozen=True)
class BuiltinPlan:
    """A built-in plan as the stimulus page lists it: clips planned, in the catalogue now, expected render time."""

    name: str
    description: str
    n_clips: int
    in_catalogue: int
    estimate_s: float


def _past_records() -> list[dict]:
    return read_records(Path(settings.MEDIA_ROOT) / "clip_records")


def builtin_rows(past: list[dict]) -> list[BuiltinPlan]:
    """The stimuli page's list of built-in plans (unloadable or empty ones left out), with the expected render time (s)
    from ``past`` clip records."""
    rows = []
    for name in builtin_plans():
        try:
            plan = load_plan(name)
        except PlanError:
            continue
        if not plan.entries:
            continue
        rows.append(BuiltinPlan(name, plan.description.split(";")[0][:160], len(plan.entries),
                                Clip.objects.filter(plan=name, retired=False).count(),
                                estimate_render(plan, past).seconds))
    return rows


def generator_rows() -> list[dict]:
    """The registry as the page's help table: name, summary, modality, fields and example condition lines."""
    return [{"name": spec.name, "summary": spec.summary, "modality": spec.modality or "any",
             "fields": ", ".join(sorted(spec.fields)), "examples": condition_examples(spec.name),
             "fallbacks": ", ".join(spec.fallbacks)} for spec in registered()]


def _check(request, model_admin) -> None:
    if not model_admin.has_add_permission(request):
        raise PermissionDenied


def stimuli_view(request, model_admin):
    """GET: the form, the built-in plans and the recent renders. POST ``action=check``: the plan's clips, titles,
    YAML and estimate; ``action=render``: start rendering the set; ``action=builtin`` with ``plan``: start a
    built-in plan."""
    _check(request, model_admin)
    past = _past_records()
    initial_plan = request.GET.get("plan", "") if request.GET.get("plan") in builtin_plans() else ""
    form = StimulusSetForm(request.POST if request.method == "POST" and request.POST.get("action") != "builtin"
                           else None)
    checked = None
    if request.method == "POST":
        action = request.POST.get("action")
        user = request.user.get_username()
        if action == "builtin":
            name = request.POST.get("plan", "")
            if name not in builtin_plans():
                messages.error(request, f"No built-in plan {name!r}.")
                return HttpResponseRedirect(reverse("admin:studyapp_clip_stimuli"))
            plan = load_plan(name)
            job = render_jobs.new_job(name, len(plan.entries), estimate_render(plan, past).seconds, user,
                                      builtin=name)
            render_jobs.start(job)
            return HttpResponseRedirect(reverse("admin:studyapp_clip_render", args=[job]))
        if form.is_valid():
            estimate = estimate_render(form.plan, past)
            if action == "render":
                job = render_jobs.new_job(form.plan.name, len(form.plan.entries), estimate.seconds, user,
                                          plan_text=plan_yaml(form.plan_data))
                render_jobs.start(job)
                return HttpResponseRedirect(reverse("admin:studyapp_clip_render", args=[job]))
            checked = {"plan": form.plan, "estimate": estimate, "yaml": plan_yaml(form.plan_data),
                       "titles": planned_titles(form.plan),
                       "existing": Clip.objects.filter(plan=form.plan.name, retired=False).count()}
    context = {**model_admin.admin_site.each_context(request), "opts": Clip._meta, "form": form,
               "title": "Stimulus sets", "checked": checked, "builtins": builtin_rows(past),
               "generators": generator_rows(), "jobs": render_jobs.recent_jobs(), "initial_plan": initial_plan}
    return TemplateResponse(request, "admin/studyapp/clip/stimuli.html", context)


def render_view(request, model_admin, job: str):
    """A render's status page; POST resumes an interrupted or failed render."""
    _check(request, model_admin)
    try:
        state = render_jobs.render_state(job)
    except render_jobs.RenderJobError:
        raise Http404("no such render") from None
    if request.method == "POST":
        if state.resumable:
            render_jobs.start(job)
            messages.info(request, "Resumed: clips already rendered are kept, only the others are rendered.")
        return HttpResponseRedirect(reverse("admin:studyapp_clip_render", args=[job]))
    context = {**model_admin.admin_site.each_context(request), "opts": Clip._meta, "state": state,
               "title": f"Render {state.plan}",
               "clips_url": reverse("admin:studyapp_clip_changelist") + f"?plan={state.plan}"}
    return TemplateResponse(request, "admin/studyapp/clip/render_status.html", context)


def render_file_view(request, model_admin, job: str, kind: str):
    """The job's plan YAML (a download) or its contact sheet (a PNG)."""
    _check(request, model_admin)
    try:
        path = render_jobs.plan_file(job) if kind == "plan" else render_jobs.sheet_file(job)
        name = render_jobs.render_state(job).plan
    except render_jobs.RenderJobError:
        raise Http404("no such file") from None
    if kind == "plan":
        return FileResponse(open(path, "rb"), as_attachment=True, filename=f"{name}.yaml",
                            content_type="application/x-yaml")
    return FileResponse(open(path, "rb"), content_type="image/png")
