"""Researcher admin: studies with their ordered sections, the clip catalogue, participants and responses.

Study pages link to the staff views: preview (records nothing), progress, CSV exports and the analysis report.
"""
from __future__ import annotations

from django.contrib import admin, messages
from django.db import models
from django.forms import Textarea
from django.urls import path, reverse
from django.utils.html import format_html

from . import views_staff
from .forms import SectionForm
from .models import Assignment, Clip, Participant, Response, Section, Study

COMPACT = {models.JSONField: {"widget": Textarea(attrs={"rows": 2, "cols": 90})},
           models.TextField: {"widget": Textarea(attrs={"rows": 3, "cols": 90})}}


class SectionInline(admin.StackedInline):
    model = Section
    form = SectionForm
    formfield_overrides = COMPACT
    fk_name = "study"
    extra = 0
    ordering = ["order", "id"]
    fields = [("order", "section_type", "title"), "instructions", "pool", ("clips_per_participant", "reuse_section"),
              ("randomize_order", "require_full_play", "loop"), "options"]


@admin.register(Study)
class StudyAdmin(admin.ModelAdmin):
    list_display = ["title", "slug", "status", "preset", "n_started", "n_completed", "links"]
    list_filter = ["status", "preset"]
    search_fields = ["title", "slug"]
    inlines = [SectionInline]
    formfield_overrides = COMPACT
    actions = ["open_studies", "close_studies"]
    readonly_fields = ["links", "preset", "created_at"]
    fieldsets = [
        (None, {"fields": ["title", "slug", "status", "preset", "links"]}),
        ("Participant pages", {"fields": ["introduction", "consent_text", "ask_demographics", "feedback_questions"]}),
        ("Recruitment", {"fields": ["max_participants", "abandon_after_minutes", "completion_code",
                                    "completion_redirect", "redirect_automatically", "created_at"]}),
    ]

    def get_urls(self):
        custom = [path("new-from-preset/", self.admin_site.admin_view(views_staff.create_from_preset),
                       name="studyapp_study_from_preset")]
        return custom + super().get_urls()

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
                    "duration_s", "plan"]
    list_filter = ["retired", "modality", "origin", "plan", "theme", "emotion_label"]
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
    fields = ["section", "position", "clip", "options", "shown_at", "answered_at"]
    readonly_fields = fields


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
