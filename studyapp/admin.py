"""Researcher admin: studies with their ordered sections, the clip catalogue, participants and responses.

Study pages link to the staff views: preview (records nothing), progress, CSV exports and the analysis report.
"""
from __future__ import annotations

import json

from django.contrib import admin, messages
from django.db import models
from django.forms import Textarea
from django.urls import path, reverse
from django.utils.html import format_html, format_html_join

from study_pools import SUB_POOLS

from . import admin_clip_qa, pool_editor, views_pool, views_staff
from .forms import SectionForm, StudyAdminForm
from .models import Assignment, Clip, Participant, Response, Section, Study
from .questions import section_type_choices
from .views_pool import count_pool

COMPACT = {models.JSONField: {"widget": Textarea(attrs={"rows": 2, "cols": 90})},
           models.TextField: {"widget": Textarea(attrs={"rows": 3, "cols": 90})}}


RAW_JSON_HELP = ("The pool and options as JSON (study_pools). The fields above win as soon as one of them is "
                 "edited, and this JSON then only adds the keys they cannot show (e.g. <code>plan__startswith</code>, "
                 "<code>happy__gt</code>); it wins when the fields above are left as they were.")


def section_fieldsets() -> list:
    """The section form: main settings, the clip pool's fields with the live count, the naturalness halves, the
    options of each section type (the page shows those of the chosen type) and the raw JSON (collapsed)."""
    main = [("order", "section_type", "title"), "instructions", ("clips_per_participant", "reuse_section"),
            ("randomize_order", "require_full_play", "loop", "counterbalance")]
    pool = ["matching_clips", ("pool_modality", "pool_origin"), "pool_plan", "pool_emotion_label", "pool_theme",
            ("pool_weight_sign", "pool_weight_min", "pool_weight_max"), ("pool_n_features_min", "pool_n_features_max"),
            ("pool_transition", "pool_rbf"), "pool_include_flagged"]
    halves = [tuple(name for name in pool_editor.SUB_POOL_FIELDS if name.startswith(f"pool_{sub}_"))
              for sub in SUB_POOLS]
    option_sets = [(f"{section_type_label(stype)}: options", {
        "fields": [tuple(names[i:i + 3]) for i in range(0, len(names), 3)], "classes": [f"only-{stype}"]})
        for stype, names in pool_editor.OPTION_FIELDS.items() if names]
    common = pool_editor.COMMON_OPTION_FIELDS
    return [
        (None, {"fields": main}),
        ("Clip pool", {"fields": pool, "classes": ["pool-editor"],
                       "description": "Which catalogue clips this section draws from; blank or none ticked: any."}),
        (f"{section_type_label(pool_editor.SUB_POOL_SECTION_TYPE)}: generated and source halves",
         {"fields": halves, "classes": [f"only-{pool_editor.SUB_POOL_SECTION_TYPE}"]}),
        *option_sets,
        ("Practice and attention checks", {"fields": [tuple(common[i:i + 2]) for i in range(0, len(common), 2)]}),
        ("Advanced: raw JSON", {"fields": ["pool", "options"], "classes": ["collapse"], "description": RAW_JSON_HELP}),
    ]


def section_type_label(section_type: str) -> str:
    return dict(section_type_choices()).get(section_type, section_type)


def pool_notes(section: Section) -> tuple[str, list[str]]:
    """(summary, warnings) of a section's pool against the catalogue (never raises)."""
    counted = count_pool(section.section_type or None, section.pool)
    warnings = counted.warnings(section.clips_per_participant, section.options)
    return counted.summary(), ([views_pool.REUSED] if section.reuse_section_id else []) + warnings


class SectionInline(admin.StackedInline):
    model = Section
    form = SectionForm
    formfield_overrides = COMPACT
    fk_name = "study"
    extra = 0
    ordering = ["order", "id"]
    readonly_fields = ["matching_clips"]
    fieldsets = section_fieldsets()

    class Media:
        js = ["studyapp/admin_pool.js"]
        css = {"all": ["studyapp/admin_pool.css"]}

    @admin.display(description="matching clips")
    def matching_clips(self, section):
        summary, warnings = pool_notes(section)
        return format_html('<span class="pool-count" data-url="{}" aria-live="polite">{}</span>'
                           '<ul class="pool-warnings">{}</ul><code class="pool-json">pool (saved): {}</code>',
                           reverse("admin:studyapp_pool_count"), summary,
                           format_html_join("", '<li class="pool-warning">{}</li>', ((w,) for w in warnings)),
                           json.dumps(section.pool))


@admin.register(Study)
class StudyAdmin(admin.ModelAdmin):
    list_display = ["title", "slug", "status", "preset", "n_started", "n_completed", "links"]
    list_filter = ["status", "preset"]
    search_fields = ["title", "slug"]
    inlines = [SectionInline]
    formfield_overrides = COMPACT
    actions = ["open_studies", "close_studies"]
    readonly_fields = ["links", "preset", "created_at"]
    form = StudyAdminForm
    fieldsets = [
        (None, {"fields": ["title", "slug", "status", "preset", "links"]}),
        ("Participant pages", {"fields": ["language", "introduction", "consent_text", "ask_demographics",
                                          "feedback_questions", "counterbalance_sections"]}),
        ("Recruitment", {"fields": ["max_participants", "abandon_after_minutes", "completion_code",
                                    "completion_redirect", "redirect_automatically", "created_at"]}),
        ("Analysis", {"fields": ["exclusion_rules"],
                      "description": "Exclusion rules the analysis report applies (checked by analysis.exclusion); "
                                     "the raw exports stay unchanged. Empty: the defaults."}),
    ]

    def get_urls(self):
        custom = [path("new-from-preset/", self.admin_site.admin_view(views_staff.create_from_preset),
                       name="studyapp_study_from_preset"),
                  # staff check inside: answers 403 JSON (not a login redirect) to anyone else
                  path("pool-count/", views_pool.pool_count, name="studyapp_pool_count")]
        return custom + super().get_urls()

    def save_formset(self, request, form, formset, change):
        """Save, then say how many clips each saved section's pool matches (a warning where it is too small)."""
        super().save_formset(request, form, formset, change)
        if formset.model is not Section:
            return
        for section in Section.objects.filter(study=form.instance).order_by("order", "id"):
            summary, warnings = pool_notes(section)
            level = messages.WARNING if warnings else messages.INFO
            self.message_user(request, f"Section {section.order} ({section.section_type}): {summary}"
                              + (f" - {'; '.join(warnings)}" if warnings else ""), level)

    @admin.display(description="started")
    def n_started(self, obj):
        return obj.participants.filter(status__in=["started", "completed"]).count()

    @admin.display(description="completed")
    def n_completed(self, obj):
        return obj.participants.filter(status="completed").count()

    @admin.display(description="study pages")
    def links(self, obj):
        if not obj.pk:
            return "-"
        return format_html(
            '<a href="{}">participant link</a> | <a href="{}">preview</a> | <a href="{}">progress</a> | '
            '<a href="{}">responses.csv</a> | <a href="{}">clips.csv</a> | <a href="{}">participants.csv</a> | '
            '<a href="{}">report.zip</a>',
            reverse("studyapp:study_entry", args=[obj.slug]), reverse("studyapp:preview_start", args=[obj.pk]),
            reverse("studyapp:progress", args=[obj.pk]),
            reverse("studyapp:export_csv", args=[obj.pk, "responses"]),
            reverse("studyapp:export_csv", args=[obj.pk, "clips"]),
            reverse("studyapp:export_csv", args=[obj.pk, "participants"]),
            reverse("studyapp:report_zip", args=[obj.pk]))

    @admin.action(description="Open the selected studies to participants")
    def open_studies(self, request, queryset):
        n = queryset.update(status=Study.Status.OPEN)
        self.message_user(request, f"Opened {n} stud{'y' if n == 1 else 'ies'}.", messages.SUCCESS)

    @admin.action(description="Close the selected studies (no new participants)")
    def close_studies(self, request, queryset):
        n = queryset.update(status=Study.Status.CLOSED)
        self.message_user(request, f"Closed {n} stud{'y' if n == 1 else 'ies'}.", messages.SUCCESS)


@admin.register(Clip)
class ClipAdmin(admin.ModelAdmin):
    list_display = ["thumbnail", "clip_id", "modality", "origin", "emotion_label", "theme", "weight", "n_features",
                    "duration_s", "plan", admin_clip_qa.quality_flag, admin_clip_qa.observer_reading]
    list_filter = ["retired", admin_clip_qa.QualityFlagFilter, "modality", "origin", "plan", "theme", "emotion_label"]
    search_fields = ["clip_id", "plan"]
    readonly_fields = ["preview", "media_key", "created_at", "updated_at"]
    actions = ["download_contact_sheet"]

    @admin.display(description="poster")
    def thumbnail(self, clip):
        if not clip.poster:
            return "-"
        return format_html('<img src="{}" alt="" style="height:48px">', reverse("studyapp:media", args=[
            clip.media_key, "png"]))

    @admin.display(description="poster and video")
    def preview(self, clip):
        poster = reverse("studyapp:media", args=[clip.media_key, "png"]) if clip.poster else ""
        return format_html('<video src="{}" poster="{}" controls preload="metadata" {} style="max-width:480px">'
                           "</video>", reverse("studyapp:media", args=[clip.media_key, "mp4"]), poster,
                           "loop" if clip.loop else "")

    @admin.action(description="Download a contact sheet (PNG) of the selected clips")
    def download_contact_sheet(self, request, queryset):
        return views_staff.contact_sheet_response(request, queryset)


class AssignmentInline(admin.TabularInline):
    model = Assignment
    extra = 0
    can_delete = False
    fields = ["seq", "section", "position", "kind", "clip", "options", "instructed", "shown_at", "answered_at"]
    readonly_fields = fields
    ordering = ["seq"]      # the order the participant sees the pages (practice items and checks included)


@admin.register(Participant)
class ParticipantAdmin(admin.ModelAdmin):
    list_display = ["public_id", "study", "status", "external_id", "gender", "age_group", "started_at",
                    "completed_at"]
    list_filter = ["study", "status"]
    search_fields = ["public_id", "external_id"]
    readonly_fields = ["token", "public_id", "seed", "consented_at", "started_at", "completed_at", "user_agent",
                       "external_id", "external_study_id", "external_session_id", "feedback"]
    inlines = [AssignmentInline]


@admin.register(Response)
class ResponseAdmin(admin.ModelAdmin):
    list_display = ["participant", "section", "clip", "question", "answer", "response_ms", "created_at"]
    list_filter = ["section__study", "section__section_type", "question"]
    search_fields = ["participant__public_id", "clip__clip_id"]

    def has_change_permission(self, request, obj=None):
        return False
