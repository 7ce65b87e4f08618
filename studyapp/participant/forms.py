"""The participant's forms: consent (with the Prolific link parameters), demographics and feedback."""
from __future__ import annotations

from django import forms
from django.utils.translation import gettext
from django.utils.translation import gettext_lazy as _

from ..i18n import display
from ..inputs import refuse_control_characters, refuse_control_characters_in_text

GENDERS = [("female", _("Female")), ("male", _("Male")), ("non-binary", _("Non-binary / another gender")),
           ("undisclosed", _("Prefer not to say"))]
AGE_GROUPS = [("18-24", "18-24"), ("25-34", "25-34"), ("35-44", "35-44"), ("45-54", "45-54"),
              ("55+", _("55 or over")), ("undisclosed", _("Prefer not to say"))]


PARAM_MAX_LENGTH = 100
PARAM_TOO_LONG = _("The study link is not valid: its {name} is longer than 100 characters. Please open the study "
                    "again from the recruitment site (Prolific); if this keeps happening, contact the researchers.")
CHOICE_ERRORS = {"invalid_choice": _("Please choose one of the answers shown."),   # never repeats the value sent
                 "required": _("Please answer this question.")}


def _link_param() -> forms.CharField:
    return forms.CharField(required=False, max_length=PARAM_MAX_LENGTH, widget=forms.HiddenInput,
                           validators=[refuse_control_characters])


class ConsentForm(forms.Form):
    """Consent plus the Prolific link parameters (hidden). A too-long parameter is an error the page shows (the
    message never repeats the value)."""

    consent = forms.BooleanField(required=True, label=_("I have read the information above and agree to take part."),
                                 error_messages={"required": _("Please tick the box to agree before starting.")})
    PROLIFIC_PID = _link_param()
    STUDY_ID = _link_param()
    SESSION_ID = _link_param()

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        for name in ("PROLIFIC_PID", "STUDY_ID", "SESSION_ID"):
            self.fields[name].error_messages["max_length"] = PARAM_TOO_LONG.format(name=name)


class DemographicsForm(forms.Form):
    gender = forms.ChoiceField(choices=GENDERS, widget=forms.RadioSelect, label=_("Gender"),
                               error_messages=CHOICE_ERRORS)
    age_group = forms.ChoiceField(choices=AGE_GROUPS, widget=forms.RadioSelect, label=_("Age group"),
                                  error_messages=CHOICE_ERRORS)


class FeedbackForm(forms.Form):
    """Built from Study.feedback_questions: yes/no radios or an optional text box. The question texts are the
    researcher's; a preset's default question is shown in the active language (studyapp.i18n.display)."""

    def __init__(self, questions: list[dict], *args, **kwargs):
        super().__init__(*args, **kwargs)
        for q in questions:
            key = str(q["key"])
            if q.get("kind", "yesno") == "text":
                self.fields[key] = forms.CharField(label=display(q["text"]), required=False, max_length=2000,
                                                   widget=forms.Textarea(attrs={"rows": 3}),
                                                   validators=[refuse_control_characters_in_text])
            else:
                self.fields[key] = forms.ChoiceField(label=display(q["text"]),
                                                     choices=[("yes", gettext("Yes")), ("no", gettext("No"))],
                                                     widget=forms.RadioSelect, error_messages=CHOICE_ERRORS)
