"""Participant forms (consent, demographics, feedback), the researcher's create-from-preset form and the admin's
section form (pool and options checked against the study protocol)."""
from __future__ import annotations

from django import forms

from .models import Section, Study
from .pools import validate_section
from .presets import preset_choices

GENDERS = [("female", "Female"), ("male", "Male"), ("non-binary", "Non-binary / another gender"),
           ("undisclosed", "Prefer not to say")]
AGE_GROUPS = [("18-24", "18-24"), ("25-34", "25-34"), ("35-44", "35-44"), ("45-54", "45-54"), ("55+", "55 or over"),
              ("undisclosed", "Prefer not to say")]


PARAM_MAX_LENGTH = 100
PARAM_TOO_LONG = ("The study link is not valid: its {name} is longer than 100 characters. Please open the study "
                  "again from the recruitment site (Prolific); if this keeps happening, contact the researchers.")
CHOICE_ERRORS = {"invalid_choice": "Please choose one of the answers shown.",   # never repeats the value sent
                 "required": "Please answer this question."}


def _link_param() -> forms.CharField:
    return forms.CharField(required=False, max_length=PARAM_MAX_LENGTH, widget=forms.HiddenInput)


class ConsentForm(forms.Form):
    """Consent plus the Prolific link parameters (hidden). A too-long parameter is an error the page shows (the
    message never repeats the value)."""

    consent = forms.BooleanField(required=True, label="I have read the information above and agree to take part.",
                                 error_messages={"required": "Please tick the box to agree before starting."})
    PROLIFIC_PID = _link_param()
    STUDY_ID = _link_param()
    SESSION_ID = _link_param()

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        for name in ("PROLIFIC_PID", "STUDY_ID", "SESSION_ID"):
            self.fields[name].error_messages["max_length"] = PARAM_TOO_LONG.format(name=name)


class DemographicsForm(forms.Form):
    gender = forms.ChoiceField(choices=GENDERS, widget=forms.RadioSelect, label="Gender", error_messages=CHOICE_ERRORS)
    age_group = forms.ChoiceField(choices=AGE_GROUPS, widget=forms.RadioSelect, label="Age group",
                                  error_messages=CHOICE_ERRORS)


class FeedbackForm(forms.Form):
    """Built from Study.feedback_questions: yes/no radios or an optional text box."""

    def __init__(self, questions: list[dict], *args, **kwargs):
        super().__init__(*args, **kwargs)
        for q in questions:
            key = str(q["key"])
            if q.get("kind", "yesno") == "text":
                self.fields[key] = forms.CharField(label=q["text"], required=False, max_length=2000,
                                                   widget=forms.Textarea(attrs={"rows": 3}))
            else:
                self.fields[key] = forms.ChoiceField(label=q["text"], choices=[("yes", "Yes"), ("no", "No")],
                                                     widget=forms.RadioSelect, error_messages=CHOICE_ERRORS)


class PresetStudyForm(forms.Form):
    preset = forms.ChoiceField(choices=preset_choices)
    slug = forms.SlugField(max_length=80, help_text="Used in the participant URL /s/<slug>/")
    title = forms.CharField(max_length=200, required=False, help_text="Leave blank for the preset's title")

    def clean_slug(self):
        slug = self.cleaned_data["slug"]
        if Study.objects.filter(slug=slug).exists():
            raise forms.ValidationError(f"A study with slug '{slug}' already exists.")
        return slug


class SectionForm(forms.ModelForm):
    """A section in the admin: every bad pool filter, option or count is an error on its field (studyapp.pools),
    so a study can never reach a participant with a pool or options the assignment cannot use. (A field with an
    error leaves cleaned_data, so Section.clean, which repeats the check, does not report it twice.)"""

    class Meta:
        model = Section
        fields = "__all__"

    def clean(self):
        data = super().clean()
        if self.has_error("section_type"):
            return data
        section_type = data.get("section_type")
        fields = {"pool": data.get("pool"), "options": data.get("options"),
                  "clips_per_participant": data.get("clips_per_participant")}
        for name, messages in validate_section(section_type, **fields).items():
            if not self.has_error(name) and name in self.fields:
                for message in messages:
                    self.add_error(name, message)
        return data
