"""The study admin page in steps (studyapp.admin.study_steps), the section order buttons (studyapp.admin.section_order)
and the warnings when a save changes what other sections give (studyapp.admin.section_impact): mixins for StudyAdmin and
its SectionInline, kept out of studyapp.admin.model_admins so that module keeps to what each page shows.

- A step's page holds only its fieldsets; the section forms appear on the sections step (type, texts, options;
  sections are added and deleted there) and on the clips step (clips per participant and the pool; the type rides
  along as a hidden field so the page shows the pool fields of that type and the checks know it).
- The study list links to the first step; "Save and continue editing" stays on the step (Django keeps the query
  string); an unknown step is an error message and the whole page.
- The sections step lists the sections with "Move up" / "Move down" buttons, each its own small POST form (CSRF
  token, no script), answered by :meth:`StudyStepsMixin.move_section_view` (change permission on the study).
"""
from __future__ import annotations

from django.contrib import messages
from django.contrib.admin.utils import flatten_fieldsets, unquote
from django.contrib.admin.views.main import ChangeList
from django.core.exceptions import PermissionDenied
from django.forms import HiddenInput
from django.http import Http404, HttpResponseNotAllowed, HttpResponseRedirect
from django.shortcuts import get_object_or_404
from django.urls import path, reverse

from ..models import Section
from . import section_impact, section_order, study_steps


def step_url(study_pk, step_key: str) -> str:
    """The change page of a study at one step."""
    return f"{reverse('admin:studyapp_study_change', args=[study_pk])}?{study_steps.STEP_PARAM}={step_key}"


class FirstStepChangeList(ChangeList):
    """The study list, whose links open a study at its first step."""

    def url_for_result(self, result):
        """The row's change URL at the first step of the study page."""
        return f"{super().url_for_result(result)}?{study_steps.STEP_PARAM}={study_steps.STEPS[0].key}"


class SectionStepsMixin:
    """For the section inline: the fieldsets of the page's step, adding only where the type is chosen, and the
    clips each section gives a participant, for the note beside each pool (measured once per page that shows the
    pools: the inline admin lives for one request)."""

    clips_given: dict[int, int] | None = None

    def get_fieldsets(self, request, obj=None):
        """The section fieldsets of the page's step (all without a step); the section type is added where the step's
        fieldsets lack it, so the checks and the page's script know it."""
        fieldsets = super().get_fieldsets(request, obj)
        step = study_steps.page_step(request, obj)
        if step is None:
            return fieldsets
        chosen = study_steps.step_fieldsets(fieldsets, step.section_fieldsets)
        if chosen and "section_type" not in flatten_fieldsets(chosen):
            title, options = chosen[0]
            chosen = [(title, {**options, "fields": [*options["fields"], "section_type"]}), *chosen[1:]]
        return chosen

    def get_formset(self, request, obj=None, **kwargs):
        """The section formset of the step: the type hidden on steps that do not add sections, and the clips each
        section gives measured when the step shows the pools."""
        step = study_steps.page_step(request, obj)
        if step is not None and not step.adds_sections:
            kwargs["widgets"] = {**kwargs.get("widgets", {}), "section_type": HiddenInput}
        shows_pool = step is None or study_steps.SECTION_POOL in step.section_fieldsets
        if shows_pool and obj is not None and obj.pk is not None:
            self.clips_given = section_impact.clips_given(section_impact.study_sections(obj))
        return super().get_formset(request, obj, **kwargs)

    def _adds_here(self, request, obj) -> bool:
        step = study_steps.page_step(request, obj)
        return step is None or step.adds_sections

    def has_add_permission(self, request, obj=None):
        """Sections are added only on the step that adds sections (or the page without steps)."""
        return self._adds_here(request, obj) and super().has_add_permission(request, obj)

    def has_delete_permission(self, request, obj=None):
        """Sections are deleted only on the step that adds sections (or the page without steps)."""
        return self._adds_here(request, obj) and super().has_delete_permission(request, obj)


class StudyStepsMixin:
    """For StudyAdmin: the step's fieldsets and inlines, the step bar and the section order buttons in the page's
    context, the move view, and the impact warnings after a save of sections."""

    def get_fieldsets(self, request, obj=None):
        """The study fieldsets of the page's step (all without a step)."""
        fieldsets = super().get_fieldsets(request, obj)
        step = study_steps.page_step(request, obj)
        return fieldsets if step is None else study_steps.step_fieldsets(fieldsets, step.fieldsets)

    def get_inlines(self, request, obj):
        """The section inline only on steps that show section fieldsets (and the page without steps)."""
        step = study_steps.page_step(request, obj)
        return super().get_inlines(request, obj) if step is None or step.section_fieldsets else []

    def get_changelist(self, request, **kwargs):
        """The study list whose links open the first step."""
        return FirstStepChangeList

    def change_view(self, request, object_id, form_url="", extra_context=None):
        """The study page at the ``?step=`` step with the step bar and, on the sections step, the order buttons; an
        unknown step is an error message and a redirect to the whole page."""
        try:
            step = study_steps.request_step(request)
        except study_steps.UnknownStepError as exc:
            self.message_user(request, str(exc), messages.ERROR)
            return HttpResponseRedirect(request.path)
        context = {"study_steps": study_steps.nav(step, request.path), "current_step": step}
        study = self.get_object(request, unquote(object_id))
        if step is not None and step.adds_sections and study is not None:
            context["section_moves"] = self._section_moves(request, study)
        return super().change_view(request, object_id, form_url, {**(extra_context or {}), **context})

    def _section_moves(self, request, study) -> dict:
        """The sections step's order list: each section with its move URLs, and why moves are refused (if so)."""
        may = self.has_change_permission(request, study)
        rows = [{"section": s, "label": section_order.describe(s),
                 "up": reverse("admin:studyapp_study_move_section", args=[study.pk, s.pk, "up"]),
                 "down": reverse("admin:studyapp_study_move_section", args=[study.pk, s.pk, "down"])}
                for s in section_impact.study_sections(study)]
        return {"rows": rows, "may_move": may, "refusal": section_order.move_refusal(study) if may else ""}

    def get_urls(self):
        """The admin's URLs plus the section move view."""
        move = path("<path:object_id>/sections/<int:section_id>/move/<str:direction>/",
                    self.admin_site.admin_view(self.move_section_view), name="studyapp_study_move_section")
        return [move, *super().get_urls()]

    def move_section_view(self, request, object_id, section_id, direction):
        """POST only: move a section one place; back to the sections step with what happened (and what it did to
        the clips other sections give). 404 for a study the user may not see, 403 without change permission."""
        if request.method != "POST":
            return HttpResponseNotAllowed(["POST"])
        study = self.get_object(request, unquote(object_id))
        if study is None:
            raise Http404("no such study")
        if not self.has_change_permission(request, study):
            raise PermissionDenied
        section = get_object_or_404(Section, pk=section_id, study=study)
        before = section_impact.clips_given(section_impact.study_sections(study))
        try:
            other = section_order.move(section, direction)
        except section_order.MoveRefused as exc:
            self.message_user(request, str(exc), messages.ERROR)
        else:
            self.message_user(request, f"Moved {section_order.describe(section)} {direction}, past "
                                       f"{section_order.describe(other)}.", messages.SUCCESS)
            sections = section_impact.study_sections(study)
            for impact in section_impact.impacts(before, section_impact.clips_given(sections), sections,
                                                 {section.pk}):
                self.message_user(request, impact.message("Moving"), messages.WARNING)
        return HttpResponseRedirect(step_url(study.pk, "sections"))

    def save_formset(self, request, form, formset, change):
        """Save; for the sections, warn about each other section whose clips per participant the save changed."""
        if formset.model is not Section or not change:
            return super().save_formset(request, form, formset, change)
        saved = section_impact.study_sections(form.instance)
        before = section_impact.clips_given(saved)
        super().save_formset(request, form, formset, change)
        sections = section_impact.study_sections(form.instance)
        changed = section_impact.changed_sections(saved, sections)
        for impact in section_impact.impacts(before, section_impact.clips_given(sections), sections, changed):
            self.message_user(request, impact.message(), messages.WARNING)
