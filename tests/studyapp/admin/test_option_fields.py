"""Section options as form fields (studyapp.admin.pool_editor): every option a registered section type declares
(protocol.section_types) and every option of all sections has form fields with help text, and every JSON option
round-trips through the form for every registered section type (JSON -> fields -> the form's cleaned options is
the same JSON), so JSON stays importable and exportable. The study's feedback questions and exclusion rules are
form fields too (studyapp.admin.study_fields)."""
from __future__ import annotations

import json

import pytest
from django.urls import reverse

from protocol.pools import COMMON_OPTIONS, validate_section
from protocol.section_types import registered
from protocol.vocabulary import GESTURE_EMOTIONS, answer_values
from studyapp.admin import pool_editor as pe
from studyapp.admin.forms import SectionPreviewForm
from studyapp.admin.model_admins import section_fieldsets
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import admin_form_data, make_catalogue

EXAMPLES: dict[str, list[dict]] = {
    "anchors": [{"anchors": {"1": "not natural at all", "5": "very natural"}}],
    "question": [{"question": "How natural does this movement look?"}],
    "n_generated": [{"n_generated": 4, "n_source": 2}],
    "n_source": [{"n_generated": 3, "n_source": 3}],
    "n_options": [{"n_options": 3}],
    "categories": [{"categories": list(GESTURE_EMOTIONS[:4])}, {"categories": list(GESTURE_EMOTIONS[2:4]),
                                                               "n_options": 2}],
    "norming": [{"norming": {}}, {"norming": {"ratings_per_clip": 12}}],
    "practice": [{"practice": True}],
    "practice_clip": [{"practice_clip": "gait_gen_00"}],
    "controls": [{"controls": "full"}, {"controls": "none"}],
    "max_replays": [{"max_replays": 0}, {"max_replays": 3}],
    "attention_checks": [{"attention_checks": {"answer": "<first answer>", "count": 2, "positions": [2, 4]}},
                         {"attention_checks": {"answer": "<first answer>", "positions": "random"}}],
}
"""Option key -> JSON options that use it (with the partner keys it needs), canonical spelling."""


def type_keys(section_type) -> list[str]:
    return [*COMMON_OPTIONS, *section_type.option_keys]


def examples_of(section_type) -> list[dict]:
    """The EXAMPLES of every option the type takes, the attention answer made one of its first question's."""
    first_answer = (list(GESTURE_EMOTIONS[:4]) if section_type.drawn_choices
                    else answer_values(section_type.questions[0].kind))[0]
    out = []
    for key in type_keys(section_type):
        for options in EXAMPLES[key]:
            text = json.dumps(options).replace("<first answer>", first_answer)
            out.append(json.loads(text))
    return out


def count_for(options: dict) -> int:
    return options.get("n_generated", 0) + options.get("n_source", 0) or 6


def posted(values: dict) -> dict[str, str]:
    """Field values as a browser posts them (check boxes "on" or absent, several choices comma-separated)."""
    out = {}
    for name, value in values.items():
        if value is True:
            out[name] = "on"
        elif isinstance(value, list):
            out[name] = ",".join(map(str, value))
        elif value is not None and value is not False and value != "":
            out[name] = str(value)
    return out


CASES = [pytest.param(t.name, options, id=f"{t.name}-{'-'.join(options)}-{i}")
         for t in registered() for i, options in enumerate(examples_of(t))]


def test_every_declared_option_has_form_fields_with_help():
    common = {spec.key for spec in pe.COMMON_OPTION_SPECS}
    assert set(COMMON_OPTIONS) <= common
    for section_type in registered():
        for key in section_type.option_keys:
            assert key in pe.OPTION_KEY_SPECS, f"{section_type.name}: option {key!r} has no form fields"
            spec = pe.OPTION_KEY_SPECS[key]
            assert spec in pe.OPTION_SPECS[section_type.name]
            fields = spec.form_fields()
            assert any(f.help_text for f in fields.values()), f"{key}: no help text"
        assert key in EXAMPLES or not section_type.option_keys


def test_every_declared_option_has_an_example():
    for section_type in registered():
        used = {key for options in examples_of(section_type) for key in options}
        assert set(type_keys(section_type)) <= used, section_type.name


def test_every_option_field_is_in_a_fieldset_once():
    names = [name for _title, options in section_fieldsets() for line in options["fields"]
             for name in (line if isinstance(line, tuple) else (line,))]
    for name in pe.ALL_OPTION_FIELDS:
        assert names.count(name) == 1, name


@pytest.mark.parametrize("section_type,options", CASES)
def test_json_options_round_trip_through_the_form(section_type, options):
    k = count_for(options)
    assert validate_section(section_type, {}, options, k) == [], options      # a valid example to begin with
    values, leftover = pe.options_to_fields(options)
    assert leftover == {}, f"{sorted(leftover)} of {options} has no field"
    form = SectionPreviewForm({"section_type": section_type, "clips_per_participant": str(k), "pool": "{}",
                               "options": "", "touched_options": "on", **posted(values)})
    assert form.is_valid(), form.errors
    assert form.cleaned_data["options"] == options


@pytest.mark.parametrize("section_type", [t.name for t in registered()])
def test_fields_of_another_type_do_not_leak_into_the_options(section_type):
    form = SectionPreviewForm({"section_type": section_type, "clips_per_participant": "6", "pool": "{}",
                               "options": "", "touched_options": "on", "opt_n_options": "3",
                               "opt_norming": "on", "opt_question": "Why?"})
    assert form.is_valid(), form.errors
    declared = set(type_keys(next(t for t in registered() if t.name == section_type)))
    assert set(form.cleaned_data["options"]) <= declared


@pytest.mark.parametrize("text,field", [("0", "opt_norming_ratings_per_clip"), ("x", "opt_norming_ratings_per_clip")])
def test_a_bad_norming_count_is_an_error_on_its_field(text, field):
    form = SectionPreviewForm({"section_type": "emotion_choice", "clips_per_participant": "6", "pool": "{}",
                               "options": "", "touched_options": "on", "opt_norming": "on",
                               "opt_norming_ratings_per_clip": text})
    assert not form.is_valid() and field in form.errors


def test_norming_json_the_fields_cannot_show_stays_raw():
    values, leftover = pe.options_to_fields({"norming": {"ratings_per_clip": 5, "extra": 1}})
    assert values == {} and leftover == {"norming": {"ratings_per_clip": 5, "extra": 1}}


# ---- through the admin ----------------------------------------------------------------------------------------

@pytest.fixture
def study(db, settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    return create_study_from_preset("gait_ismar2020", "options", plan="test")


def test_norming_is_edited_on_the_sections_step(admin_client, study):
    url = reverse("admin:studyapp_study_change", args=[study.pk]) + "?step=sections"
    page = admin_client.get(url)
    html = page.content.decode()
    assert 'name="sections-0-opt_norming_ratings_per_clip"' in html and "Ratings per clip (K)" in html
    data = admin_form_data(page)
    data.update({"sections-0-opt_norming": "on", "sections-0-opt_norming_ratings_per_clip": "15"})
    r = admin_client.post(url, data)
    assert r.status_code == 302, [f.errors for i in r.context["inline_admin_formsets"] for f in i.formset.forms]
    first = study.sections.order_by("order").first()
    assert first.options == {"norming": {"ratings_per_clip": 15}}
    again = admin_client.get(url).context["inline_admin_formsets"][0].formset.forms[0]
    assert again.initial["opt_norming"] is True and again.initial["opt_norming_ratings_per_clip"] == 15


def test_feedback_and_exclusion_rules_are_form_fields_with_help(admin_client, study):
    recruitment = admin_client.get(reverse("admin:studyapp_study_change", args=[study.pk]) + "?step=recruitment")
    form = recruitment.context["adminform"].form
    assert {"feedback_0_key", "feedback_0_text", "feedback_0_kind"} <= set(form.fields)
    exclusions = admin_client.get(reverse("admin:studyapp_study_change", args=[study.pk]) + "?step=exclusions")
    rules = [f for name, f in exclusions.context["adminform"].form.fields.items() if name.startswith("rule_")]
    assert rules and all(f.help_text for f in rules)
