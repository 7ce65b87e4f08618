"""The study page in the admin: "reuse section" offers only earlier sections of the same study."""
from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.urls import reverse

from studyapp.staff.presets import create_study_from_preset

pytestmark = pytest.mark.django_db


def test_reuse_section_lists_only_earlier_sections_of_the_same_study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    client = Client()
    client.force_login(User.objects.create_user("lead", password="pw-lead-12345", is_staff=True,
                                                is_superuser=True))
    study = create_study_from_preset("gait_ismar2020", "builder", plan="test")
    other = create_study_from_preset("gait_ismar2020", "elsewhere", plan="test")
    page = client.get(reverse("admin:studyapp_study_change", args=[study.pk]))
    formset = next(f.formset for f in page.context["inline_admin_formsets"] if f.formset.model.__name__ == "Section")
    sections = list(study.sections.order_by("order", "id"))
    for form in formset.forms:
        offered = list(form.fields["reuse_section"].queryset)
        assert offered == [s for s in sections if s.order < form.instance.order], form.instance.order
    assert formset.forms[0].fields["reuse_section"].queryset.count() == 0
    assert not set(formset.empty_form.fields["reuse_section"].queryset) & set(other.sections.all())
    assert set(formset.empty_form.fields["reuse_section"].queryset) == set(sections)


FEEDBACK = [{"key": "distracted_camera", "text": "Were you distracted by the camera?", "kind": "yesno"},
            {"key": "comments", "text": "Any other comments?", "kind": "text"}]
RULES = {"min_rt_fraction": 0.3, "max_straightline": 0.9, "min_straight": 6, "min_attention_pass": 1.0}


@pytest.fixture
def staff_and_study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    client = Client()
    client.force_login(User.objects.create_user("lead", password="pw-lead-12345", is_staff=True,
                                                is_superuser=True))
    study = create_study_from_preset("gait_ismar2020", "options", plan="test")
    study.feedback_questions, study.exclusion_rules = FEEDBACK, RULES
    study.save()
    return client, study


def _post(client, study, change):
    from studyapp.testing import admin_form_data

    url = reverse("admin:studyapp_study_change", args=[study.pk])
    data = admin_form_data(client.get(url))
    data.update(change(data) or {})
    r = client.post(url, data)
    assert r.status_code == 302, r.context["adminform"].form.errors if r.context else r
    study.refresh_from_db()
    return data


def test_feedback_questions_and_exclusion_rules_round_trip_through_their_fields(staff_and_study):
    client, study = staff_and_study
    data = _post(client, study, lambda d: None)                     # saved unchanged: the JSON stays as it was
    assert (data["feedback_0_key"], data["feedback_1_kind"], data["rule_min_straight"]) == (
        "distracted_camera", "text", "6")
    assert study.feedback_questions == FEEDBACK and study.exclusion_rules == RULES
    # the fields win once one is edited; what they hold becomes the JSON, every option kept
    _post(client, study, lambda d: {"feedback_0_text": "Were you distracted by the camera?", "feedback_2_key": "",
                                    "rule_min_rt_fraction": "0.3"} | {"feedback_0_kind": "yesno"})
    assert study.feedback_questions == FEEDBACK and study.exclusion_rules == RULES
    _post(client, study, lambda d: {"feedback_2_key": "tired", "feedback_2_text": "Were you tired?",
                                    "rule_max_straightline": "", "rule_min_straight": "8"})
    assert study.feedback_questions == [*FEEDBACK, {"key": "tired", "text": "Were you tired?", "kind": "yesno"}]
    assert study.exclusion_rules == {"min_rt_fraction": 0.3, "min_straight": 8, "min_attention_pass": 1.0}


def test_bad_fields_are_refused_next_to_the_field(staff_and_study):
    from studyapp.testing import admin_form_data

    client, study = staff_and_study
    url = reverse("admin:studyapp_study_change", args=[study.pk])
    data = admin_form_data(client.get(url))
    data.update({"feedback_2_key": "Bad Key", "feedback_2_text": "x", "rule_max_fast_share": "7"})
    form = client.post(url, data).context["adminform"].form
    assert "feedback_2_key" in form.errors and "rule_max_fast_share" in form.errors
    study.refresh_from_db()
    assert study.feedback_questions == FEEDBACK and study.exclusion_rules == RULES
