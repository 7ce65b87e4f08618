"""The study admin page in steps (studyapp.admin.study_steps, studyapp.admin.steps): every fieldset belongs to a step,
each step shows only its parts, saving a step keeps the other steps' fields, and the step bar and links."""
from __future__ import annotations

import pytest
from django.contrib.admin.sites import site
from django.contrib.admin.utils import flatten_fieldsets
from django.urls import reverse

from studyapp.admin import study_steps
from studyapp.admin.model_admins import StudyAdmin, section_fieldsets
from studyapp.models import Section, Study
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import admin_form_data, make_catalogue

FEEDBACK = [{"key": "distracted", "text": "Were you distracted?", "kind": "yesno"}]
RULES = {"min_rt_fraction": 0.3, "min_straight": 6}


# ---- the table ----------------------------------------------------------------------------------------------------

def test_every_study_fieldset_belongs_to_a_step():
    for title, _options in StudyAdmin.fieldsets:
        assert study_steps.steps_of(title), f"the study fieldset {title!r} is on no step (studyapp.admin.study_steps)"


def test_every_section_fieldset_belongs_to_a_step():
    for title, _options in section_fieldsets():
        assert study_steps.steps_of(title, section=True), f"the section fieldset {title!r} is on no step"


def test_every_study_field_is_on_exactly_one_step():
    seen: dict[str, str] = {}
    for step in study_steps.STEPS:
        for name in flatten_fieldsets(study_steps.step_fieldsets(StudyAdmin.fieldsets, step.fieldsets)):
            assert name not in seen, f"{name} is on the steps {seen[name]} and {step.key}"
            seen[name] = step.key
    assert set(seen) == set(flatten_fieldsets(StudyAdmin.fieldsets))


def test_a_step_that_adds_sections_shows_their_type():
    for step in study_steps.STEPS:
        names = flatten_fieldsets(study_steps.step_fieldsets(section_fieldsets(), step.section_fieldsets))
        if step.adds_sections:
            assert "section_type" in names


def test_unknown_step_is_a_clear_error():
    with pytest.raises(study_steps.UnknownStepError, match="no step 'nope' \\(steps: overview, sections"):
        study_steps.find_step("nope")
    assert study_steps.find_step("") is None


# ---- the pages ----------------------------------------------------------------------------------------------------

@pytest.fixture
def study(db, settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("gait_ismar2020", "steps", plan="test")
    study.feedback_questions, study.exclusion_rules = FEEDBACK, RULES
    study.save()
    return study


def url(study, step: str = "") -> str:
    base = reverse("admin:studyapp_study_change", args=[study.pk])
    return f"{base}?step={step}" if step else base


def shown_fields(page) -> set[str]:
    names = set(page.context["adminform"].form.fields)
    for inline in page.context["inline_admin_formsets"]:
        for form in inline.formset.forms:
            names |= {f"section:{n}" for n in form.fields}
    return names


@pytest.mark.parametrize("step", study_steps.STEPS, ids=lambda s: s.key)
def test_each_step_shows_only_its_fields(admin_client, study, step):
    page = admin_client.get(url(study, step.key))
    assert page.status_code == 200
    names = shown_fields(page)
    wanted = set(flatten_fieldsets(study_steps.step_fieldsets(StudyAdmin.fieldsets, step.fieldsets)))
    wanted -= set(StudyAdmin.readonly_fields)
    study_names = {n for n in names if not n.startswith("section:")}
    assert study_names - {"owners", "collaborators"} == wanted - {"owners", "collaborators"}
    has_sections = any(n.startswith("section:") for n in names)
    assert has_sections == bool(step.section_fieldsets)
    html = page.content.decode()
    assert 'aria-current="page">' + step.title in html
    assert "admin_steps.css" in html


def test_sections_and_clips_steps_split_the_section_form(admin_client, study):
    sections = shown_fields(admin_client.get(url(study, "sections")))
    clips = shown_fields(admin_client.get(url(study, "clips")))
    assert {"section:title", "section:options", "section:opt_practice"} <= sections
    assert not {"section:pool", "section:pool_modality", "section:clips_per_participant"} & sections
    assert {"section:pool", "section:pool_modality", "section:clips_per_participant", "section:section_type"} <= clips
    assert not {"section:title", "section:options", "section:opt_practice"} & clips
    page = admin_client.get(url(study, "clips")).content.decode()
    assert 'type="hidden" name="sections-0-section_type"' in page


def test_whole_page_without_a_step_and_the_add_page_stay_one_form(admin_client, study):
    names = shown_fields(admin_client.get(url(study)))
    assert {"title", "max_participants", "rule_min_straight", "section:pool", "section:options"} <= names
    add = admin_client.get(reverse("admin:studyapp_study_add") + "?step=clips")
    assert add.status_code == 200 and "slug" in add.context["adminform"].form.fields


def test_unknown_step_redirects_to_the_whole_page_with_a_message(admin_client, study):
    r = admin_client.get(url(study, "nope"), follow=True)
    assert r.redirect_chain[-1][0] == url(study)
    assert any("no step 'nope'" in str(m) for m in r.context["messages"])


def post_step(client, study, step: str, edit: dict):
    page = client.get(url(study, step))
    data = admin_form_data(page)
    data.update(edit)
    data["_continue"] = "Save and continue editing"
    return client.post(url(study, step), data)


def test_saving_a_step_keeps_the_other_steps(admin_client, study):
    sections_before = list(study.sections.order_by("order").values_list("pool", "options", "title"))
    r = post_step(admin_client, study, "overview", {"title": "A new title"})
    assert r.status_code == 302, r.context["adminform"].form.errors
    assert r["Location"].endswith("?step=overview")
    study.refresh_from_db()
    assert study.title == "A new title"
    assert study.feedback_questions == FEEDBACK and study.exclusion_rules == RULES
    assert list(study.sections.order_by("order").values_list("pool", "options", "title")) == sections_before

    r = post_step(admin_client, study, "exclusions", {"rule_min_straight": "8"})
    assert r.status_code == 302, r.context["adminform"].form.errors
    study.refresh_from_db()
    assert study.exclusion_rules == {**RULES, "min_straight": 8}
    assert study.feedback_questions == FEEDBACK and study.title == "A new title"


def test_saving_the_clips_step_keeps_texts_and_options(admin_client, study):
    first = study.sections.order_by("order").first()
    first.title, first.options = "Walks", {"practice": True}
    first.save()
    r = post_step(admin_client, study, "clips", {"sections-0-clips_per_participant": "3"})
    assert r.status_code == 302, [f.errors for i in r.context["inline_admin_formsets"] for f in i.formset.forms]
    first.refresh_from_db()
    assert first.clips_per_participant == 3 and first.title == "Walks" and first.options == {"practice": True}


def test_saving_the_sections_step_keeps_pools(admin_client, study):
    pools = list(study.sections.order_by("order").values_list("pool", "clips_per_participant"))
    r = post_step(admin_client, study, "sections", {"sections-0-title": "First walks"})
    assert r.status_code == 302, [f.errors for i in r.context["inline_admin_formsets"] for f in i.formset.forms]
    assert study.sections.order_by("order").first().title == "First walks"
    assert list(study.sections.order_by("order").values_list("pool", "clips_per_participant")) == pools


def test_only_the_sections_step_adds_sections(admin_client, study):
    for step, adds in (("sections", True), ("clips", False)):
        inline = admin_client.get(url(study, step)).context["inline_admin_formsets"][0]
        assert inline.has_add_permission is adds and inline.formset.can_delete is adds


def test_an_error_of_a_field_another_step_shows_names_the_field(admin_client, study):
    """A count that no longer fits the saved naturalness options is reported on the clips step, naming them."""
    section = Section.objects.create(study=study, order=99, section_type="naturalness", clips_per_participant=4,
                                     pool={"modality": "gait"}, options={"n_generated": 2, "n_source": 2})
    page = admin_client.get(url(study, "clips"))
    data = admin_form_data(page)
    index = next(i for i, f in enumerate(page.context["inline_admin_formsets"][0].formset.forms)
                 if f.instance.pk == section.pk)
    data[f"sections-{index}-clips_per_participant"] = "6"
    r = admin_client.post(url(study, "clips"), data)
    assert r.status_code == 200
    form = r.context["inline_admin_formsets"][0].formset.forms[index]
    assert any("options" in e for e in form.non_field_errors()), form.errors
    section.refresh_from_db()
    assert section.clips_per_participant == 4


def test_study_list_opens_the_first_step(admin_client, study):
    page = admin_client.get(reverse("admin:studyapp_study_changelist"))
    assert f'{url(study)}?step={study_steps.STEPS[0].key}' in page.content.decode()
    assert isinstance(site._registry[Study], StudyAdmin)
