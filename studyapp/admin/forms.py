"""The admin's study form (exclusion rules checked by the analysis library) and section form (the pool editor: pool
and options as fields or raw JSON, checked against the study protocol) with the preview form of its live clip
count, and the clip import form. The participant's forms are in studyapp.participant.forms, the researcher's
in studyapp.staff.forms."""
from __future__ import annotations

from django import forms
from django.db.models import Q

from analysis.exclusion import rule_errors
from protocol.pools import SUB_POOLS, pool_errors

from ..data import clip_import
from ..data.check_clips import check_clip_problems
from ..data.norming import open_errors
from ..data.norms_rule import NormsSourceError, check_reader, load_norms, norms_rules, norms_sources
from ..models import Clip, Section, Study
from ..questions import section_type_choices
from ..redirects import check_completion_url
from . import pool_editor, study_fields
from .partial_forms import PartialModelForm
from .pool_editor import PoolEditorFields
from .section_order import move_refusal


class SectionForm(PartialModelForm, PoolEditorFields):
    """A section in the admin: the pool and options as structured fields (studyapp.admin.pool_editor) with the raw JSON
    as an advanced field. The raw JSON wins only when none of its group's structured fields was edited (their
    initial values are read from the saved JSON); otherwise the fields win and the raw JSON adds only the keys
    they cannot show. Every bad pool filter, option or count is an error on the field it comes from
    (protocol.pools), so a study can never reach a participant with a pool or options the assignment cannot use.
    (A field with an error leaves cleaned_data, so Section.clean, which repeats the check, does not report it
    twice.)

    ``reader``: the user saving (the admin passes it). A norms rule (the pool's or a sub-pool's) whose source this
    save adds may name only a study of theirs (studyapp.data.norms_rule.check_reader); a source already saved stays as
    it is, so a collaborator can still save a section a superuser pointed at another study's norms.

    On a step of the study page the form holds only that step's fields (studyapp.admin.partial_forms); the pool and
    options are still checked against the section's type and count, the saved values standing in for the fields
    the step does not show."""

    CHECKED_TOGETHER = ("section_type", "clips_per_participant", "pool", "options")

    class Meta:
        """Every field of Section."""

        model = Section
        fields = "__all__"

    def __init__(self, *args, reader=None, **kwargs):
        super().__init__(*args, **kwargs)
        self.reader = reader
        self.saved_norms_sources = norms_sources(self.instance.pool)
        for name, value in pool_editor.initial_values(self.instance.pool, self.instance.options).items():
            self.initial.setdefault(name, value)
        plans = catalogue_plans()
        for name in ("pool_plan", *(f"pool_{sub}_plan" for sub in SUB_POOLS)):
            if name in self.fields:
                self.fields[name].widget.suggestions = plans
        self._earlier_sections_only()

    def _earlier_sections_only(self) -> None:
        """"Reuse section" offers only sections that come before this one in its own study (a saved section: by
        order, then id; a new one: every saved section of the study); Section.clean checks the same on save."""
        field = self.fields.get("reuse_section")
        if field is None or not self.instance.study_id:
            return
        earlier = field.queryset.filter(study_id=self.instance.study_id)
        if self.instance.pk:
            earlier = earlier.filter(Q(order__lt=self.instance.order) |
                                     Q(order=self.instance.order, pk__lt=self.instance.pk))
        field.queryset = earlier.order_by("order", "id")

    def clean(self):
        """Fill in the saved type, count, pool and options for fields this step does not show, settle the pool and
        options from the structured fields or the raw JSON (pool_editor.resolve_section_json), refuse an order change
        once participants take part, and check the norms rules the pool names."""
        data = super().clean()
        for name in self.CHECKED_TOGETHER:
            if not self.shows(name):
                data[name] = self.value_of(data, name)
        pool_editor.resolve_section_json(self, data, pool_editor.touched_groups(self.changed_data))
        self._check_order_change()
        if self.shows("pool"):
            self._check_norms_reader(data)
            self._check_norms_source(data)
        return data

    def _check_order_change(self) -> None:
        """A saved section's order is not typed anew once participants take part: the same rule as the move
        buttons (studyapp.admin.section_order), as an error on the order field."""
        if self.instance.pk and self.shows("order") and "order" in self.changed_data:
            refusal = move_refusal(self.instance.study)
            if refusal:
                self.add_error("order", refusal)

    def _post_clean(self):
        """After the model's own checks: an error on the options when the section's attention checks would find no
        clip the participant does not rate (studyapp.data.check_clips; the model layer does not read the catalogue)."""
        super()._post_clean()
        if not self.has_error("options") and not self.has_error("pool"):
            for problem in check_clip_problems(self.instance):
                self.add_error("options" if self.shows("options") else None, problem)

    def _check_norms_source(self, data: dict) -> None:
        """An error on the pool when a norms rule of its tree (its own or a sub-pool's) gives no norms (an unknown
        study, a study without norms yet, a bad clip_norms.csv: studyapp.data.norms_service names the file, line and
        column)."""
        pool = data.get("pool")
        if self.has_error("pool") or not norms_rules(pool) or pool_errors(pool, data.get("section_type")):
            return                # a bad pool is named by the section's own checks first (Section.clean)
        for where, rule in norms_rules(pool):
            try:
                load_norms(rule.get("from", ""))
            except NormsSourceError as exc:
                self.add_error("pool", str(exc).replace("pool.norms.", f"pool.{where}.", 1))

    def _check_norms_reader(self, data: dict) -> None:
        """An error on the pool (which then keeps its saved value) when the reader may not read a new source of a
        norms rule anywhere in the pool tree (its own rule or a sub-pool's)."""
        if self.reader is None or "pool" not in data:
            return
        try:
            check_reader(data["pool"], self.reader, already_saved=self.saved_norms_sources)
        except NormsSourceError as exc:
            self.add_error("pool", str(exc))


def catalogue_plans() -> list[str]:
    """The plans of the clips in the catalogue (suggestions for the pool's plan boxes)."""
    return sorted(p for p in Clip.objects.exclude(plan="").values_list("plan", flat=True).distinct())


class SectionPreviewForm(PoolEditorFields):
    """What the admin page sends while a section is edited (studyapp.admin.views_pool): the section's type, count, raw
    JSON and structured fields, and whether the structured fields of each group were edited on the page."""

    section_type = forms.ChoiceField(choices=section_type_choices)
    clips_per_participant = forms.IntegerField(required=False, min_value=0)
    pool = forms.JSONField(required=False)
    options = forms.JSONField(required=False)
    touched_pool = forms.BooleanField(required=False)
    touched_options = forms.BooleanField(required=False)

    def clean(self):
        """The pool and options the page's fields mean, settled as on save, each problem on its field."""
        data = super().clean()
        touched = {"pool": bool(data.get("touched_pool")), "options": bool(data.get("touched_options"))}
        pool_editor.resolve_section_json(self, data, touched)
        return data


class StudyAdminForm(PartialModelForm):
    """A study in the admin; the exclusion rules are checked by the analysis library (analysis.exclusion), the
    completion URL must be http(s) (studyapp.redirects)."""

    class Meta:
        """Every field of Study."""

        model = Study
        fields = "__all__"

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        study_fields.set_initial(self)

    def clean_completion_redirect(self):
        """The completion URL, stripped; refused unless it is http(s) (blank allowed)."""
        value = (self.cleaned_data.get("completion_redirect") or "").strip()
        check_completion_url(value)
        return value

    def clean(self):
        """A norming study opens only when its planned N (the participant limit) gives every clip K ratings."""
        data = super().clean()
        if study_fields.touched(self, study_fields.FEEDBACK_FIELDS):
            data["feedback_questions"] = study_fields.feedback_from_fields(self, data)
        if study_fields.touched(self, study_fields.RULE_FIELDS):
            rules = study_fields.rules_from_fields(data)
            errors = rule_errors(rules)
            if errors:
                self.add_error(None, errors)
            data["exclusion_rules"] = rules
        if self.instance.pk and data.get("status") == Study.Status.OPEN:
            errors = open_errors(self.instance, n_planned=data.get("max_participants") or 0)
            if errors:
                self.add_error("status", errors)
        return data

    def clean_exclusion_rules(self):
        """The raw exclusion rules JSON (blank: {}), refused with the analysis library's messages when a rule is unknown
        or out of range."""
        rules = self.cleaned_data.get("exclusion_rules")
        rules = {} if rules is None else rules
        errors = rule_errors(rules)
        if errors:
            raise forms.ValidationError(errors)
        return rules


StudyAdminForm.base_fields.update(study_fields.declared_fields())
StudyAdminForm.declared_fields.update(study_fields.declared_fields())


class MultipleFileInput(forms.ClearableFileInput):
    """A file input that lets the browser select several files."""

    allow_multiple_selected = True


class MultipleFileField(forms.FileField):
    """Several uploaded files in one field (a list, possibly empty)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("widget", MultipleFileInput())
        super().__init__(*args, **kwargs)

    def clean(self, data, initial=None):
        """The uploaded files as a list, each checked like one file; empty slots are dropped."""
        if isinstance(data, (list, tuple)):
            return [super(MultipleFileField, self).clean(d, initial) for d in data if d]
        return [super().clean(data, initial)] if data else []


class ClipImportForm(forms.Form):
    """The admin's clip import: a manifest CSV and its files, or a zip holding both (docs/study.md, "Bring your own
    stimuli")."""

    manifest = forms.FileField(required=False, help_text="The manifest CSV; it names each file by its file name.")
    files = MultipleFileField(required=False, help_text="The videos (.mp4 .mov .webm ...) and motion files (.bvh).")
    archive = forms.FileField(required=False, label="or a zip",
                              help_text="A zip of the manifest (manifest.csv, or the only .csv) and its files; the "
                                        "manifest's paths are relative to the zip's top.")
    collection = forms.SlugField(
        required=False, max_length=clip_import.COLLECTION_MAX_LENGTH,
        help_text="The collection these clips belong to, yours alone (catalogue plan import:upload/<your user "
                  "name>/<collection>); blank: from the uploaded file's name. Upload a changed version of the "
                  "same stimuli into the same collection: a changed file retires the older clip of that "
                  "collection and path, never another collection's.")
    keep_audio = forms.BooleanField(required=False, help_text="Keep the videos' sound (default: stripped).")
    dry_run = forms.BooleanField(required=False, help_text="Only check every row; import nothing.")

    def clean(self):
        """Requires a manifest (a .csv) or a zip; a blank collection is named after the uploaded file."""
        data = super().clean()
        if not data.get("manifest") and not data.get("archive"):
            raise forms.ValidationError("Upload a manifest with its files, or a zip of them.")
        if data.get("manifest") and not data["manifest"].name.lower().endswith(".csv"):
            self.add_error("manifest", "The manifest must be a .csv file.")
        if not data.get("collection") and "collection" not in self.errors:
            upload = data.get("archive") or data.get("manifest")
            data["collection"] = clip_import.default_collection(upload.name)
        return data
