"""Researcher admin: studies with their ordered sections, the clip catalogue, participants and responses.

Study pages link to the staff views: preview (records nothing), progress, CSV exports and the analysis report.
Studies, participants and responses are scoped per study (StudyScopedAdmin): a researcher lists, opens, changes
and deletes only those of the studies they own or collaborate on (superusers: all); the catalogue is shared.
"""
from __future__ import annotations

import json

from django.contrib import admin, messages
from django.core.exceptions import PermissionDenied
from django.db import models
from django.forms import Textarea
from django.http import Http404, HttpResponseRedirect
from django.template.response import TemplateResponse
from django.urls import path, reverse
from django.utils.html import format_html, format_html_join

from protocol.pools import SUB_POOLS
from protocol.section_types import page_types

from ..data import clip_display, clip_import
from ..data.norming import design_rows, open_errors
from ..models import Assignment, Clip, Participant, Response, Section, Study
from ..permissions import can_access_study, can_manage_study_access, studies_for
from ..questions import section_type_choices
from ..staff import views as views_staff
from . import clip_qa as admin_clip_qa
from . import pool_editor, section_impact, study_fields, study_steps, views_pool
from . import stimuli as admin_stimuli
from .forms import ClipImportForm, SectionForm, StudyAdminForm
from .norms import norms_table
from .steps import SectionStepsMixin, StudyStepsMixin
from .views_pool import count_pool

COMPACT = {models.JSONField: {"widget": Textarea(attrs={"rows": 2, "cols": 90})},
           models.TextField: {"widget": Textarea(attrs={"rows": 3, "cols": 90})}}


RAW_STUDY_JSON_HELP = ("The fields above win as soon as one of them is edited; this JSON wins when they are left as "
                       "they were (paste a study's JSON here to import it).")
RAW_JSON_HELP = ("As JSON (protocol.pools). The fields above win as soon as one of them is "
                 "edited, and this JSON then only adds the keys they cannot show (e.g. <code>plan__startswith</code>, "
                 "<code>happy__gt</code>); it wins when the fields above are left as they were.")


NOT_ON_PAGES = [f"not-{t.name}" for t in page_types()]
"""Fieldset classes hiding a fieldset for the instruction and break pages (no clips: static/studyapp/admin_pool.js)."""


def section_fieldsets() -> list:
    """The section form: the section itself, its clips per participant, the clip pool's fields with the live count,
    the naturalness halves, the options of each section type (the page shows those of the chosen type), practice
    and attention checks, and the raw JSON of the pool and of the options (collapsed). The study page's steps
    (studyapp.admin.study_steps) show these by title: sections and options on one step, clips on another."""
    main = [("order", "section_type", "name"), "title", "instructions",
            ("randomize_order", "require_full_play", "loop", "counterbalance")]
    pool = ["matching_clips", ("pool_modality", "pool_origin"), "pool_plan", "pool_emotion_label", "pool_theme",
            ("pool_weight_sign", "pool_weight_min", "pool_weight_max"), ("pool_n_features_min", "pool_n_features_max"),
            ("pool_transition", "pool_rbf"), ("pool_include_flagged", "pool_keep_advisory", "pool_observer_advisory")]
    halves = [tuple(name for name in pool_editor.SUB_POOL_FIELDS if name.startswith(f"pool_{sub}_"))
              for sub in SUB_POOLS]
    option_sets = [(f"{' / '.join(section_type_label(t) for t in types)}{study_steps.SECTION_OPTIONS_SUFFIX}", {
        "fields": [tuple(names[i:i + 3]) for i in range(0, len(names), 3)],
        "classes": [f"only-{t}" for t in types]}) for types, names in pool_editor.OPTION_GROUPS]
    common = pool_editor.COMMON_OPTION_FIELDS
    return [
        (study_steps.SECTION_MAIN, {"fields": main}),
        (study_steps.SECTION_CLIPS, {"fields": [("clips_per_participant", "reuse_section")]}),
        (study_steps.SECTION_POOL, {"fields": pool, "classes": ["pool-editor", *NOT_ON_PAGES],
                                    "description": "Which catalogue clips this section draws from; blank or none "
                                                   "ticked: any."}),
        (f"{section_type_label(pool_editor.SUB_POOL_SECTION_TYPE)}{study_steps.SECTION_HALVES_SUFFIX}",
         {"fields": halves, "classes": [f"only-{pool_editor.SUB_POOL_SECTION_TYPE}"]}),
        *option_sets,
        (study_steps.SECTION_PRACTICE, {"fields": [tuple(common[i:i + 2]) for i in range(0, len(common), 2)],
                                        "classes": ["collapse", *NOT_ON_PAGES]}),
        (study_steps.SECTION_RAW_POOL, {"fields": ["pool"], "classes": ["collapse"], "description": RAW_JSON_HELP}),
        (study_steps.SECTION_RAW_OPTIONS, {"fields": ["options"], "classes": ["collapse"],
                                           "description": RAW_JSON_HELP}),
    ]


def section_type_label(section_type: str) -> str:
    """The readable label of a section type, as its choice shows it (the name itself for an unknown type)."""
    return dict(section_type_choices()).get(section_type, section_type)


def pool_notes(section: Section, given: dict[int, int] | None = None) -> tuple[str, list[str]]:
    """(summary, warnings) of a section's pool against the catalogue (never raises). ``given``: the clips each
    section gives a participant (studyapp.admin.section_impact.clips_given), to say when earlier sections leave this
    one fewer clips than it shows."""
    counted = count_pool(section.section_type or None, section.pool)
    warnings = counted.warnings(section.clips_per_participant, section.options)
    short = section_impact.short_of(section, given, counted.total)
    return counted.summary(), ([views_pool.REUSED] if section.reuse_section_id else []) + warnings + (
        [short] if short else [])


class StudyScopedAdmin(admin.ModelAdmin):
    """A model admin whose rows belong to a study (``study_field``: the lookup from the row to its study, "" for
    Study itself): the list holds only the rows of the user's studies, and a row of another study can be neither
    viewed, changed nor deleted (Django's admin then answers as if it did not exist)."""

    study_field = ""

    def _study_pk(self, obj):
        if not self.study_field:
            return obj.pk
        value = obj
        for part in self.study_field.split("__"):
            value = getattr(value, part)
        return value.pk

    def get_queryset(self, request):
        """The rows of the user's studies only (every row for a superuser): the admin list and every lookup by id."""
        queryset = super().get_queryset(request)
        if request.user.is_superuser:
            return queryset
        lookup = f"{self.study_field}__in" if self.study_field else "pk__in"
        return queryset.filter(**{lookup: studies_for(request.user).values("pk")})

    def _may(self, request, obj) -> bool:
        return obj is None or request.user.is_superuser or can_access_study(request.user, self._study_pk(obj))

    def has_view_permission(self, request, obj=None):
        """Django's view permission, and for a row access to its study."""
        return super().has_view_permission(request, obj) and self._may(request, obj)

    def has_change_permission(self, request, obj=None):
        """Django's change permission, and for a row access to its study."""
        return super().has_change_permission(request, obj) and self._may(request, obj)

    def has_delete_permission(self, request, obj=None):
        """Django's delete permission, and for a row access to its study."""
        return super().has_delete_permission(request, obj) and self._may(request, obj)

    def formfield_for_foreignkey(self, db_field, request, **kwargs):
        """A study drop-down offers only the user's studies."""
        if db_field.related_model is Study:
            kwargs["queryset"] = studies_for(request.user)
        return super().formfield_for_foreignkey(db_field, request, **kwargs)


class SectionInline(SectionStepsMixin, admin.StackedInline):
    """The study page's sections, one stacked form each (section_fieldsets), with the pool editor and its live count of
    matching clips."""

    model = Section
    form = SectionForm
    formfield_overrides = COMPACT
    fk_name = "study"
    extra = 0
    ordering = ["order", "id"]
    readonly_fields = ["matching_clips"]
    fieldsets = section_fieldsets()

    class Media:
        """The pool editor's script and styles and the clip cells' stylesheet."""

        js = ["studyapp/admin_pool.js"]
        css = {"all": ["studyapp/admin_pool.css", clip_display.STYLESHEET]}

    def get_formset(self, request, obj=None, **kwargs):
        """The sections' formset, remembering on the request which study they belong to (for the reused-section
        choices)."""
        request.studyapp_section_study = obj          # the study whose sections a reused section may be
        return super().get_formset(request, obj, **kwargs)

    def formfield_for_foreignkey(self, db_field, request, **kwargs):
        """"Reuse section" offers only sections of the study being edited (none on a new study), never another lab's."""
        if db_field.name == "reuse_section":
            # only this study's sections (each form narrows to the earlier ones: SectionForm); never another lab's
            study = getattr(request, "studyapp_section_study", None)
            mine = Section.objects.filter(study__in=studies_for(request.user).values("pk"))
            kwargs["queryset"] = mine.filter(study=study) if study is not None else mine.none()
        return super().formfield_for_foreignkey(db_field, request, **kwargs)

    @admin.display(description="matching clips")
    def matching_clips(self, section):
        """The read-only "matching clips" cell: the pool's count (refreshed live from the pool-count URL), its warnings,
        a sample of matching clips, the saved pool JSON and the norms table of a norms rule."""
        summary, warnings = pool_notes(section, self.clips_given)
        sample = [] if section.reuse_section_id else views_pool.pool_sample(section.section_type or None,
                                                                             section.pool)
        return format_html('<span class="pool-count" data-url="{}" aria-live="polite">{}</span>'
                           '<ul class="pool-warnings">{}</ul><ul class="clip-samples" aria-label="some of the '
                           'matching clips">{}</ul><code class="pool-json">pool (saved): {}</code>'
                           '<div class="norms-slot">{}</div>',
                           reverse("admin:studyapp_pool_count"), summary,
                           format_html_join("", '<li class="pool-warning">{}</li>', ((w,) for w in warnings)),
                           format_html_join("", "<li>{}</li>", ((c.html(),) for c in sample)),
                           json.dumps(section.pool), norms_table(section.pool))


@admin.register(Study)
class StudyAdmin(StudyStepsMixin, StudyScopedAdmin):
    """The study admin: the list with participant counts and links to the staff pages, the study page in steps with its
    sections inline, the open and close actions, and the owners and collaborators who may see the study."""

    list_display = ["title", "slug", "status", "preset", "n_started", "n_completed", "links"]
    list_filter = ["status", "preset"]
    search_fields = ["title", "slug"]
    inlines = [SectionInline]
    formfield_overrides = COMPACT
    actions = ["open_studies", "close_studies"]
    readonly_fields = ["links", "preset", "created_at", "norming_design"]
    form = StudyAdminForm

    class Media:
        """The stylesheet of the study page's steps."""

        css = {"all": ["studyapp/admin_steps.css"]}

    fieldsets = [
        (None, {"fields": ["title", "slug", "status", "listed_publicly", "preset", "links"]}),
        ("Participant data", {"fields": ["export_external_ids"],
                              "description": "Exports and reports pseudonymise external ids unless this is ticked; "
                                             "withdrawn participants are left out of them."}),
        ("Participant pages", {"fields": ["language", "introduction", "consent_text", "ask_demographics",
                                          "counterbalance_sections"]}),
        ("Screens and devices", {"fields": [("min_viewport_width", "min_viewport_height"),
                                            ("admit_phones", "admit_tablets")],
                                 "description": "Checked on the consent page before the study starts; a participant "
                                                "turned away gets a page that says why, and nothing is recorded."}),
        ("Feedback questions (the last page)", {
            "fields": [study_fields.feedback_names(i) for i in range(study_fields.FEEDBACK_ROWS)],
            "description": "Up to six questions; a row without key and text is left out. The raw JSON below "
                           "wins only while these rows are left as they were."}),
        ("Recruitment", {"fields": ["max_participants", "norming_design", "abandon_after_minutes", "completion_code",
                                    "completion_redirect", "redirect_automatically", "created_at"]}),
        ("Pilot", {"fields": ["pilot", "report_includes_pilot"],
                   "description": "Run a pilot before opening: its participants stay apart (see the progress page "
                                  "to delete their data). Opening the study ends pilot mode."}),
        ("Analysis", {"fields": [tuple(study_fields.RULE_FIELDS[i:i + 2])
                                 for i in range(0, len(study_fields.RULE_FIELDS), 2)],
                      "description": "Exclusion rules the analysis report applies (checked by analysis.exclusion); "
                                     "the raw exports stay unchanged. Blank: the defaults."}),
        ("Advanced: feedback questions as JSON", {"fields": ["feedback_questions"], "classes": ["collapse"],
                                                  "description": RAW_STUDY_JSON_HELP}),
        ("Advanced: exclusion rules as JSON", {"fields": ["exclusion_rules"], "classes": ["collapse"],
                                               "description": RAW_STUDY_JSON_HELP}),
        ("Access", {"fields": ["owners", "collaborators"],
                    "description": "Who may see, preview, export and analyse this study (superusers see every "
                                   "study). Only owners and superusers change this; whoever creates a study owns "
                                   "it."}),
    ]

    def get_readonly_fields(self, request, obj=None):
        """Owners and collaborators are read-only for anyone who may not manage the study's access (only superusers on a
        new study)."""
        fields = list(super().get_readonly_fields(request, obj))
        may_manage = request.user.is_superuser if obj is None else can_manage_study_access(request.user, obj)
        if not may_manage:
            fields += ["owners", "collaborators"]
        return fields

    def formfield_for_manytomany(self, db_field, request, **kwargs):
        """Owners and collaborators are chosen among active staff accounts, by username."""
        if db_field.name in ("owners", "collaborators"):
            kwargs["queryset"] = db_field.related_model.objects.filter(is_staff=True, is_active=True).order_by(
                "username")
        return super().formfield_for_manytomany(db_field, request, **kwargs)

    def save_related(self, request, form, formsets, change):
        """Save the sections and access lists; whoever creates a study becomes an owner."""
        super().save_related(request, form, formsets, change)
        if not change:
            form.instance.owners.add(request.user)

    def get_urls(self):
        """The admin's URLs plus "new from preset" and the pool editor's live count (pool-count/)."""
        custom = [path("new-from-preset/", self.admin_site.admin_view(views_staff.create_from_preset),
                       name="studyapp_study_from_preset"),
                  # staff check inside: answers 403 JSON (not a login redirect) to anyone else
                  path("pool-count/", views_pool.pool_count, name="studyapp_pool_count")]
        return custom + super().get_urls()

    def get_formset_kwargs(self, request, obj, inline, prefix):
        """The section forms know who saves (SectionForm's reader: a norms rule may name only their studies)."""
        kwargs = super().get_formset_kwargs(request, obj, inline, prefix)
        if isinstance(inline, SectionInline):
            kwargs["form_kwargs"] = {**kwargs.get("form_kwargs", {}), "reader": request.user}
        return kwargs

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
        """The list's "started" column: participants who started or completed."""
        return obj.participants.filter(status__in=["started", "completed"]).count()

    @admin.display(description="completed")
    def n_completed(self, obj):
        """The list's "completed" column."""
        return obj.participants.filter(status="completed").count()

    @admin.display(description="study pages")
    def links(self, obj):
        """The "study pages" cell: participant link, preview, progress, clone, the three CSV exports and report.zip ("-"
        before the study is saved)."""
        if not obj.pk:
            return "-"
        return format_html(
            '<a href="{}">participant link</a> | <a href="{}">preview</a> | <a href="{}">progress, Prolific, '
            'pilot, sharing</a> | <a href="{}">clone</a> | '
            '<a href="{}">responses.csv</a> | <a href="{}">clips.csv</a> | <a href="{}">participants.csv</a> | '
            '<a href="{}">report.zip</a>',
            reverse("studyapp:study_entry", args=[obj.slug]), reverse("studyapp:preview_start", args=[obj.pk]),
            reverse("studyapp:progress", args=[obj.pk]), reverse("studyapp:clone_study", args=[obj.pk]),
            reverse("studyapp:export_csv", args=[obj.pk, "responses"]),
            reverse("studyapp:export_csv", args=[obj.pk, "clips"]),
            reverse("studyapp:export_csv", args=[obj.pk, "participants"]),
            reverse("studyapp:report_zip", args=[obj.pk]))

    @admin.action(description="Open the selected studies to participants")
    def open_studies(self, request, queryset):
        """The list action "Open": opens each selected study whose checks pass (studyapp.data.norming.open_errors; the
        others are named with their errors), ends its pilot mode and warns where pilot data remain."""
        refused = {}
        for study in queryset:
            errors = open_errors(study)
            if errors:
                refused[study.pk] = errors
                self.message_user(request, f"Not opened: {study.slug}: {'; '.join(errors)}", messages.ERROR)
        opened = queryset.exclude(pk__in=refused)
        for study in opened.filter(participants__pilot=True).distinct():
            self.message_user(request, format_html(
                "{} still holds pilot data: <a href=\"{}\">delete it on the progress page</a> (it stays marked "
                "and out of the report meanwhile).", study.slug,
                reverse("studyapp:progress", args=[study.pk]) + "#pilot"), messages.WARNING)
        n = opened.update(status=Study.Status.OPEN, pilot=False)     # opening ends pilot mode
        self.message_user(request, f"Opened {n} stud{'y' if n == 1 else 'ies'}.",
                          messages.SUCCESS if n else messages.WARNING)

    @admin.display(description="norming design")
    def norming_design(self, obj):
        """The read-only "norming design" table: per norming section C, M, K, the participants needed and planned and
        whether every clip gets K ratings, with a link to the norming monitor ("-" without norming sections)."""
        rows = design_rows(obj) if obj.pk else []
        if not rows:
            return "-"
        body = format_html_join("", "<tr><td>{}. {}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>"
                                    "<td>{}</td></tr>",
                                ((r.section.order, r.section.section_type, r.n_clips, r.m, r.k, r.n_needed,
                                  r.n_planned or "no limit set", "; ".join(r.errors) or
                                  f"ok: every clip gets at least {r.min_with_planned} ratings") for r in rows))
        return format_html('<table class="norming-design"><thead><tr><th>section</th><th>clips C</th>'
                           '<th>per participant M</th><th>ratings per clip K</th><th>participants needed N</th>'
                           '<th>planned N (participant limit)</th><th>design</th></tr></thead><tbody>{}</tbody>'
                           '</table><p><a href="{}">ratings per clip so far</a></p>', body,
                           reverse("studyapp:norming_monitor", args=[obj.pk]))

    @admin.action(description="Close the selected studies (no new participants)")
    def close_studies(self, request, queryset):
        """The list action "Close": no new participants for the selected studies."""
        n = queryset.update(status=Study.Status.CLOSED)
        self.message_user(request, f"Closed {n} stud{'y' if n == 1 else 'ies'}.", messages.SUCCESS)


@admin.register(Clip)
class ClipAdmin(admin.ModelAdmin):
    """The shared clip catalogue: posters, titles, quality flags and observer readings, the stimuli page (render a plan)
    and the clip import, and a contact sheet of selected clips."""

    list_display = ["thumbnail", "title_or_id", "modality", "origin", "emotion_label", "theme", "weight",
                    "n_features", "duration_s", "plan", admin_clip_qa.quality_flag, admin_clip_qa.observer_reading]
    list_display_links = ["title_or_id"]
    list_filter = ["retired", admin_clip_qa.QualityFlagFilter, "modality", "origin", "plan", "theme", "emotion_label"]
    search_fields = ["clip_id", "title", "plan", "licence", "citation"]
    readonly_fields = ["preview", "media_key", "created_at", "updated_at"]
    actions = ["download_contact_sheet"]
    change_list_template = "admin/studyapp/clip/change_list.html"
    list_per_page = 25

    class Media:
        """The clip cells' stylesheet."""

        css = {"all": [clip_display.STYLESHEET]}

    def get_urls(self):
        """The admin's URLs plus the stimuli page, its render jobs with their plan and contact sheet, the import and its
        status page."""
        def wrap(view):
            return self.admin_site.admin_view(lambda request, *args, **kwargs: view(request, self, *args, **kwargs))

        custom = [path("stimuli/", wrap(admin_stimuli.stimuli_view), name="studyapp_clip_stimuli"),
                  path("stimuli/<str:job>/", wrap(admin_stimuli.render_view), name="studyapp_clip_render"),
                  path("stimuli/<str:job>/plan.yaml", wrap(admin_stimuli.render_file_view),
                       {"kind": "plan"}, name="studyapp_clip_render_plan"),
                  path("stimuli/<str:job>/contact-sheet.png", wrap(admin_stimuli.render_file_view),
                       {"kind": "sheet"}, name="studyapp_clip_render_sheet"),
                  path("import/", self.admin_site.admin_view(self.import_view), name="studyapp_clip_import"),
                  path("import/<str:job>/", self.admin_site.admin_view(self.import_status_view),
                       name="studyapp_clip_import_status")]
        return custom + super().get_urls()

    def import_view(self, request):
        """Upload a manifest and its files (or a zip); the import runs as ``manage.py import_clips`` outside the
        request and the status page shows its report."""
        if not self.has_add_permission(request):
            raise PermissionDenied
        form = ClipImportForm(request.POST or None, request.FILES or None)
        if request.method == "POST" and form.is_valid():
            data = form.cleaned_data
            try:
                name = clip_import.collection_name(request.user.get_username(), data["collection"])
                job, manifest = clip_import.save_upload(data["manifest"], data["files"], data["archive"])
            except clip_import.UploadError as exc:
                form.add_error(None, str(exc))
            else:
                clip_import.start_import(manifest, job, name, data["keep_audio"], data["dry_run"])
                return HttpResponseRedirect(reverse("admin:studyapp_clip_import_status", args=[job]))
        context = {**self.admin_site.each_context(request), "opts": self.model._meta, "form": form,
                   "title": "Import clips"}
        return TemplateResponse(request, "admin/studyapp/clip/import.html", context)

    def import_status_view(self, request, job):
        """The status page of clip import ``job`` (needs the clip add permission): its state and the per-row report; 404
        for an unknown job."""
        if not self.has_add_permission(request):
            raise PermissionDenied
        try:
            state = clip_import.import_state(job)
        except clip_import.UploadError:
            raise Http404("no such import") from None
        context = {**self.admin_site.each_context(request), "opts": self.model._meta, "state": state,
                   "title": f"Clip import {job}", "ok": sum(r.get("status") == "ok" for r in state.rows)}
        return TemplateResponse(request, "admin/studyapp/clip/import_status.html", context)

    @admin.display(description="poster")
    def thumbnail(self, clip):
        """The list's "poster" cell."""
        return clip_display.clip_cell(clip).thumb()

    @admin.display(description="clip", ordering="title")
    def title_or_id(self, clip):
        """The list's "clip" cell: the title (or the clip id) above the clip id."""
        return format_html('{}<br><code class="clip-id">{}</code>', clip.title or clip.clip_id, clip.clip_id)

    @admin.display(description="poster and video")
    def preview(self, clip):
        """The change page's player: the clip's MP4 with its poster, looping as the clip does."""
        poster = reverse("studyapp:media", args=[clip.media_key, "png"]) if clip.poster else ""
        return format_html('<video src="{}" poster="{}" controls preload="metadata" {} style="max-width:480px">'
                           "</video>", reverse("studyapp:media", args=[clip.media_key, "mp4"]), poster,
                           "loop" if clip.loop else "")

    @admin.action(description="Download a contact sheet (PNG) of the selected clips")
    def download_contact_sheet(self, request, queryset):
        """The list action: a PNG contact sheet of the selected clips' posters."""
        return views_staff.contact_sheet_response(request, queryset)


class AssignmentInline(admin.TabularInline):
    """A participant's clip pages, read-only, in the order they are shown."""

    model = Assignment
    extra = 0
    can_delete = False
    fields = ["seq", "section", "position", "kind", "clip", "options", "instructed", "shown_at", "answered_at"]
    readonly_fields = fields
    ordering = ["seq"]      # the order the participant sees the pages (practice items and checks included)


@admin.register(Participant)
class ParticipantAdmin(StudyScopedAdmin):
    """Participants of the user's studies, their record mostly read-only; deleting or withdrawing one says whether
    stored analysis reports with their data were deleted."""

    study_field = "study"
    list_display = ["public_id", "study", "status", "external_id", "gender", "age_group", "started_at",
                    "completed_at"]
    list_filter = [("study", admin.RelatedOnlyFieldListFilter), "status"]
    search_fields = ["public_id", "external_id"]
    readonly_fields = ["token", "public_id", "seed", "consented_at", "started_at", "completed_at", "user_agent",
                       "external_id", "external_study_id", "external_session_id", "feedback", "gender", "age_group",
                       "demographics_done", "feedback_done", "last_active_at", "section_order", "device_kind",
                       "viewport_width", "viewport_height"]
    inlines = [AssignmentInline]

    def has_add_permission(self, request):
        """Never: participants come from the consent page."""
        return False              # participants come from the consent page only

    def _say_reports_forgotten(self, request, participants) -> None:
        n = sum(getattr(p, "_reports_forgotten", 0) for p in participants)
        studies = sorted({p.study.title for p in participants})
        if n:
            messages.warning(request, f"Deleted {n} stored analysis report(s) of {', '.join(studies)} that held "
                                      "this participant's data; build the report again on the study's progress page.")
        else:
            messages.info(request, "No stored analysis report held this participant's data; exports are made from "
                                   "the database on each download and no longer include them.")

    def save_model(self, request, obj, form, change):
        """Save; a change to withdrawn says which stored analysis reports held the participant's data."""
        super().save_model(request, obj, form, change)
        if "status" in form.changed_data and obj.status == Participant.Status.WITHDRAWN:
            self._say_reports_forgotten(request, [obj])

    def delete_model(self, request, obj):
        """Delete the participant (answers and assignments with them) and say which stored reports went too."""
        super().delete_model(request, obj)
        self._say_reports_forgotten(request, [obj])

    def delete_queryset(self, request, queryset):
        """The list's delete action: each participant deleted on its own, so each one's study forgets its reports."""
        gone = list(queryset.select_related("study"))
        for participant in gone:               # one by one: each deletion forgets its study's reports
            participant.delete()
        self._say_reports_forgotten(request, gone)


PARTICIPANT_DELETE_VIEWS = ("studyapp_participant_delete", "studyapp_participant_changelist")
"""Admin views that delete participants (one, or the list's delete action) and with them their answers."""


@admin.register(Response)
class ResponseAdmin(StudyScopedAdmin):
    """Answers of the user's studies, read-only; deleted only with their participant."""

    study_field = "section__study"
    list_display = ["participant", "section", "clip", "question", "answer", "response_ms", "created_at"]
    list_filter = [("section__study", admin.RelatedOnlyFieldListFilter), "section__section_type", "question"]
    search_fields = ["participant__public_id", "clip__clip_id"]

    def has_add_permission(self, request):
        """Never: answers come from participants."""
        return False              # answers come from participants only

    def has_change_permission(self, request, obj=None):
        """Never: an answer is kept as given."""
        return False

    def has_delete_permission(self, request, obj=None):
        """Only as part of deleting their participant (the participant pages' delete views ask about the answers
        that go with them); never one answer on its own."""
        match = getattr(request, "resolver_match", None)
        whole = match is not None and match.url_name in PARTICIPANT_DELETE_VIEWS
        return whole and super().has_delete_permission(request, obj)

    def formfield_for_foreignkey(self, db_field, request, **kwargs):
        """Participant and section drop-downs offer only those of the user's studies."""
        if db_field.name == "participant":
            kwargs["queryset"] = Participant.objects.filter(study__in=studies_for(request.user).values("pk"))
        elif db_field.name == "section":
            kwargs["queryset"] = Section.objects.filter(study__in=studies_for(request.user).values("pk"))
        return super().formfield_for_foreignkey(db_field, request, **kwargs)
