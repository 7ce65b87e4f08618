"""The admin's pool editor: form fields <-> pool/options JSON (studyapp.admin.pool_editor), the staff-only live count
(studyapp.admin.views_pool), saving sections through the admin with fields or raw JSON, the study form's new fields,
and (browser, slow) the count updating in headless Chromium as a field changes."""
from __future__ import annotations

import json
import re

import pytest
from django.contrib.auth.models import Permission, User
from django.test import Client
from django.urls import reverse

from protocol.vocabulary import CLIP_THEMES, GESTURE_EMOTIONS, MODALITIES, ORIGINS
from studyapp.admin import pool_editor as pe
from studyapp.admin.forms import SectionForm, SectionPreviewForm
from studyapp.admin.views_pool import HALVES
from studyapp.data.catalogue import pool_queryset
from studyapp.models import Clip, Section, Study
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import admin_form_data, make_catalogue

COUNT_URL = "admin:studyapp_pool_count"

# ---- fields <-> JSON, no database -------------------------------------------------------------------------------

FIELD_VALUES = [
    {"pool_modality": [MODALITIES[0]], "pool_origin": [ORIGINS[0]], "pool_transition": "no",
     "pool_weight_sign": "positive"},
    {"pool_theme": list(CLIP_THEMES[:2]), "pool_weight_min": -1.5, "pool_weight_max": 0.25, "pool_rbf": "yes",
     "pool_n_features_min": 2, "pool_n_features_max": 10, "pool_include_flagged": True},
    {"pool_plan": "demo, test", "pool_emotion_label": list(GESTURE_EMOTIONS[3:6]), "pool_n_features_min": 4,
     "pool_n_features_max": 4, "pool_weight_sign": "zero"},
    {"pool_modality": [MODALITIES[1]], "pool_generated_plan": "gen-plan", "pool_source_emotion_label":
     [GESTURE_EMOTIONS[0]], "pool_source_transition": "yes"},
]


@pytest.mark.parametrize("values", FIELD_VALUES)
def test_fields_to_json_to_fields_is_the_identity(values):
    pool = pe.fields_to_pool(values, {}, pe.SUB_POOL_SECTION_TYPE)
    back, leftover = pe.pool_to_fields(pool)
    assert back == values and leftover == {}


CANONICAL_POOLS = [
    {"modality": "gait", "origin": "generated", "transition": False, "weight__gt": 0},
    {"rbf": True, "weight__lt": 0, "weight__gte": -1.0, "theme": ["sad", "tired"], "n_features": 10},
    {"modality": "gesture", "emotion_label": ["afraid", "proud"], "plan": ["a", "b"], "include_flagged": True},
    {"modality": "gait", "generated": {"plan": "demo", "transition": False}, "source": {"emotion_label": "sad"}},
]


@pytest.mark.parametrize("pool", CANONICAL_POOLS)
def test_json_to_fields_to_json_is_the_identity(pool):
    values, leftover = pe.pool_to_fields(pool)
    assert leftover == {}
    assert pe.fields_to_pool(values, leftover, pe.SUB_POOL_SECTION_TYPE) == pool


def test_keys_the_fields_cannot_show_are_kept_and_spellings_become_canonical():
    pool = {"theme__in": ["tired", "sad"], "n_features__gte": 3, "n_features__lte": 3, "happy__gt": 0.5,
            "clip_id__startswith": "rbf_", "weight__gt": 0.5, "source": {"sections__contains": "naturalness",
                                                                         "plan": "demo"}}
    values, leftover = pe.pool_to_fields(pool)
    assert values["pool_theme"] == ["sad", "tired"] and values["pool_source_plan"] == "demo"
    assert leftover == {"happy__gt": 0.5, "clip_id__startswith": "rbf_", "weight__gt": 0.5,
                        "source": {"sections__contains": "naturalness"}}
    assert pe.fields_to_pool(values, leftover, pe.SUB_POOL_SECTION_TYPE) == {
        "theme": ["sad", "tired"], "n_features": 3, "happy__gt": 0.5, "clip_id__startswith": "rbf_",
        "weight__gt": 0.5, "source": {"sections__contains": "naturalness", "plan": "demo"}}
    # sub-pool fields count only for the section type that has sub-pools
    assert "source" not in pe.fields_to_pool({"pool_source_plan": "x"}, {}, "theme_rating")


OPTIONS = [
    ("naturalness", {"anchors": {"1": "bad", "5": "good"}, "question": "Natural?", "n_generated": 3, "n_source": 3}),
    ("gesture_emotion", {"n_options": 3, "categories": ["afraid", "proud", "sad"]}),
    ("gesture_emotion", {}),
    ("theme_rating", {"attention_checks": {"answer": "3", "count": 2, "positions": [3, 7]}, "practice": True}),
    ("emotion_choice", {"attention_checks": {"answer": "sad", "positions": "random", "question": "perceived"},
                        "practice_clip": "gait_src_00"}),
]


@pytest.mark.parametrize("stype,options", OPTIONS)
def test_options_round_trip(stype, options):
    values, leftover = pe.options_to_fields(options)
    assert leftover == {}
    assert pe.fields_to_options(values, leftover, stype) == options
    assert pe.options_to_fields(pe.fields_to_options(values, {}, stype))[0] == values


def test_preview_form_without_database_reports_bad_fields_by_name():
    form = SectionPreviewForm({"section_type": "theme_rating", "pool_weight_min": "heavy", "pool_theme": "sleepy",
                               "pool_n_features_min": "5", "pool_n_features_max": "2", "touched_pool": "on"})
    assert not form.is_valid()
    assert "number" in form.errors["pool_weight_min"][0]
    assert "sleepy" in form.errors["pool_theme"][0]
    assert "below" in form.errors["pool_n_features_max"][0]
    assert "pool" not in form.cleaned_data                     # no pool is built from bad fields


def test_error_of_the_built_pool_lands_on_the_structured_field():
    form = SectionPreviewForm({"section_type": "gesture_emotion", "pool_modality": "gait", "touched_pool": "on",
                               "opt_n_options": "3", "opt_categories": ["afraid", "sad"], "touched_options": "on"})
    assert not form.is_valid()
    assert "'modality'" in form.errors["pool_modality"][0]
    assert "'n_options'" in form.errors["opt_n_options"][0]
    assert set(form.errors) == {"pool_modality", "opt_n_options"}


def test_attention_check_fields_name_their_part():
    form = SectionPreviewForm({"section_type": "theme_rating", "opt_attention_answer": "maybe",
                               "opt_attention_positions": "2", "touched_options": "on"})
    assert not form.is_valid()
    assert set(form.errors) == {"opt_attention_answer"} and "'answer'" in form.errors["opt_attention_answer"][0]
    bad_places = SectionPreviewForm({"section_type": "theme_rating", "opt_attention_answer": "3",
                                     "opt_attention_positions": "3, x", "touched_options": "on"})
    assert not bad_places.is_valid() and "whole numbers" in bad_places.errors["opt_attention_positions"][0]
    good = SectionPreviewForm({"section_type": "theme_rating", "opt_attention_answer": "7", "opt_practice": "on",
                               "opt_n_options": "3", "touched_options": "on"})      # another type's field: ignored
    assert good.is_valid(), good.errors
    assert good.cleaned_data["options"] == {"attention_checks": {"answer": "7"}, "practice": True}


# ---- the count endpoint -----------------------------------------------------------------------------------------

@pytest.fixture
def catalogue(db, settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    return make_catalogue(settings.MEDIA_ROOT)


@pytest.fixture
def staff(db):
    user = User.objects.create_user("researcher", password="pw-researcher-1", is_staff=True)
    user.user_permissions.add(Permission.objects.get(codename="view_clip"))     # the count needs it
    c = Client()
    c.force_login(user)
    return c


def count(client, **params):
    r = client.get(reverse(COUNT_URL), params)
    assert r.status_code == 200, r.content
    return r.json()


def test_count_endpoint_is_staff_only(catalogue):
    url = reverse(COUNT_URL)
    assert Client().get(url, {"section_type": "theme_rating"}).status_code == 403
    plain = Client()
    plain.force_login(User.objects.create_user("someone", password="pw-someone-1"))
    r = plain.get(url, {"section_type": "theme_rating"})
    assert r.status_code == 403 and "staff" in r.json()["error"]
    staff = Client()
    user = User.objects.create_user("r", password="pw-r-1", is_staff=True)
    staff.force_login(user)
    r = staff.get(url, {"section_type": "theme_rating"})
    assert r.status_code == 403 and "studyapp.view_clip" in r.json()["error"]
    user.user_permissions.add(Permission.objects.get(codename="view_clip"))
    assert staff.post(url, {"section_type": "theme_rating"}).status_code == 405


def test_count_endpoint_counts_the_catalogue(catalogue, staff):
    pool = {"modality": "gait", "origin": "generated", "transition": False}
    answer = count(staff, section_type="emotion_choice", pool_modality="gait", pool_origin="generated",
                   pool_transition="no", touched_pool="on")
    assert answer["errors"] == [] and answer["pool"] == pool and answer["used"]["pool"] == "fields"
    assert answer["count"] == pool_queryset(pool).count() > 0
    negative = count(staff, section_type="theme_inversion", pool_weight_sign="negative", touched_pool="on")
    assert negative["count"] == Clip.objects.filter(weight__lt=0).count() == 6
    every = count(staff, section_type="theme_rating", pool="")          # empty pool: every clip it can show
    assert every["count"] == Clip.objects.filter(modality="gait").count() and every["pool"] == {}
    Clip.objects.filter(clip_id="rbf_sad_inv").update(retired=True)
    assert count(staff, section_type="theme_inversion", pool=json.dumps({"weight__lt": 0}))["count"] == 5


def test_count_endpoint_splits_naturalness_halves(catalogue, staff):
    answer = count(staff, section_type="naturalness", pool_modality="gesture", pool_source_emotion_label="sad",
                   touched_pool="on", clips_per_participant="6", opt_n_generated="3", opt_n_source="3",
                   touched_options="on")
    gestures = Clip.objects.filter(modality="gesture")
    assert answer["by_origin"] == {"generated": gestures.filter(origin="generated").count(),
                                   "source": gestures.filter(origin="source", emotion_label="sad").count()}
    assert any("fewer source clips" in w for w in answer["warnings"])
    assert answer["pool"] == {"modality": "gesture", "source": {"emotion_label": "sad"}}


def test_flagged_clips_count_only_when_the_pool_includes_them(catalogue, staff):
    Clip.objects.filter(clip_id__in=["rbf_sad_inv", "gest_src_03"]).update(qa_flag="foot_skate")
    without = count(staff, section_type="theme_inversion", pool_weight_sign="negative", touched_pool="on")
    with_flagged = count(staff, section_type="theme_inversion", pool_weight_sign="negative",
                         pool_include_flagged="on", touched_pool="on")
    assert (without["count"], with_flagged["count"]) == (5, 6)
    assert with_flagged["pool"] == {"weight__lt": 0, "include_flagged": True}
    natural = count(staff, section_type="naturalness", pool_modality="gesture", pool_include_flagged="on",
                    pool_source_plan="test", touched_pool="on", reuse_section="1")
    assert natural["by_origin"]["source"] == Clip.objects.filter(modality="gesture", origin="source").count()
    assert "reuses the clips" in natural["warnings"][0]


BAD_INPUTS = [  # (params, field the error is on, words of the message)
    ({"pool_weight_min": "heavy"}, "pool_weight_min", "number"),
    ({"pool_emotion_label": "happyish"}, "pool_emotion_label", "happyish"),
    ({"pool_n_features_min": "-3"}, "pool_n_features_min", "greater than or equal"),
    ({"pool": "{modality: gait"}, "pool", "JSON"),
    ({"pool": json.dumps({"weight__gt": "big"})}, "pool", "'weight__gt'"),
    ({"pool": '{"weight__gt": NaN}'}, "pool", "'weight__gt'"),
    ({"pool": json.dumps({"n_features": 10**30})}, "pool", "n_features"),
    ({"section_type": "dance"}, "section_type", "dance"),
    ({"clips_per_participant": "many"}, "clips_per_participant", "number"),
]


@pytest.mark.parametrize("params,field,words", BAD_INPUTS)
def test_count_endpoint_names_the_field_of_every_bad_input(catalogue, staff, params, field, words):
    touched = {"touched_pool": "on"} if any(k.startswith("pool_") for k in params) else {}   # raw JSON otherwise
    answer = count(staff, **{"section_type": "theme_rating", **touched, **params})
    messages = " | ".join(m for e in answer["errors"] if e["field"] == field for m in e["messages"])
    assert words in messages, answer
    assert all(e["label"] for e in answer["errors"])
    assert (answer["count"] is None) == (field != "clips_per_participant")    # a pool that is fine is counted


def test_edited_fields_override_the_raw_keys_they_own(catalogue, staff):
    raw = json.dumps({"n_features": 10**30, "weight__gt": 0, "happy__gt": 0.5})
    answer = count(staff, section_type="theme_rating", pool=raw, pool_theme="sad", touched_pool="on")
    # n_features and weight__gt are the fields' keys (left blank: no filter); happy__gt only the raw JSON can say
    assert answer["pool"] == {"theme": "sad", "happy__gt": 0.5} and answer["errors"] == []
    assert answer["count"] == 0                         # the themed clips have no gait emotion vector
    # a raw key the fields cannot show stays the raw field's, errors included
    bad = count(staff, section_type="theme_rating", pool=json.dumps({"weight__gt": "big"}), pool_weight_sign="zero",
                touched_pool="on")
    assert [e["field"] for e in bad["errors"]] == ["pool"] and "'weight__gt'" in bad["errors"][0]["messages"][0]


def test_count_endpoint_uses_raw_json_when_fields_untouched(catalogue, staff):
    raw = {"theme": "sad"}
    answer = count(staff, section_type="theme_rating", pool=json.dumps(raw), pool_theme="happy")
    assert answer["pool"] == raw and answer["used"]["pool"] == "raw"
    assert answer["count"] == Clip.objects.filter(theme="sad").count()


# ---- saving through the admin ------------------------------------------------------------------------------------

@pytest.fixture
def admin_client(db):
    user = User.objects.create_user("admin", password="pw-admin-1", is_staff=True, is_superuser=True)
    c = Client()
    c.force_login(user)
    return c


@pytest.fixture
def study(catalogue):
    return create_study_from_preset("gestures_ieeevr2021", "gest", plan="test")


def change(client, study, edit: dict):
    url = reverse("admin:studyapp_study_change", args=[study.pk])
    data = admin_form_data(client.get(url))
    data.update(edit)
    return client.post(url, data)


def test_change_page_shows_the_editor_with_server_side_counts(admin_client, study):
    page = admin_client.get(reverse("admin:studyapp_study_change", args=[study.pk]))
    html = page.content.decode()
    gesture = study.sections.get(order=1)
    assert f"{pool_queryset(gesture.pool).count()} clips in the catalogue match" in html
    assert 'class="pool-count"' in html and reverse(COUNT_URL) in html and "admin_pool.js" in html
    assert re.search(r'name="sections-0-pool_modality" value="gesture" id="[^"]+" checked', html)
    assert "Advanced: raw JSON" in html and 'name="sections-0-pool"' in html
    assert 'name="language"' in html and 'name="counterbalance_sections"' in html
    assert 'name="exclusion_rules"' in html


def test_unchanged_page_saves_the_same_json(admin_client, study):
    before = list(study.sections.order_by("order").values_list("pool", "options"))
    assert change(admin_client, study, {}).status_code == 302
    assert list(study.sections.order_by("order").values_list("pool", "options")) == before


def test_structured_fields_win_once_edited_and_keep_raw_only_keys(admin_client, study):
    r = change(admin_client, study, {
        "sections-0-pool_emotion_label": ["sad", "proud"], "sections-0-opt_n_options": "3",
        # the raw JSON edited too: its 'modality' loses to the untouched field, its extra key is kept
        "sections-0-pool": json.dumps({"modality": "gait", "plan": "test", "clip_id__startswith": "gest_"})})
    assert r.status_code == 302, r.context["inline_admin_formsets"][0].formset.errors
    section = study.sections.get(order=1)
    assert section.pool == {"modality": "gesture", "origin": "generated", "plan": "test", "keep_advisory": True,
                            "emotion_label": ["proud", "sad"], "clip_id__startswith": "gest_"}
    assert section.options == {"n_options": 3}
    messages = [m.message for m in r.wsgi_request._messages]
    assert any(f"Section 1 (gesture_emotion): {pool_queryset(section.pool).count()} clips" in m for m in messages)


def test_raw_json_wins_when_fields_are_untouched(admin_client, study):
    raw = {"modality": "gesture", "origin": "source", "plan": "test"}
    assert change(admin_client, study, {"sections-0-pool": json.dumps(raw)}).status_code == 302
    assert study.sections.get(order=1).pool == raw


BAD_FIELDS = [  # (posted fields of section 0 (gesture_emotion) or 1 (naturalness), field with the error, words)
    ({"sections-0-pool_weight_min": "heavy"}, 0, "pool_weight_min", "number"),
    ({"sections-0-pool_emotion_label": "happyish"}, 0, "pool_emotion_label", "happyish"),
    ({"sections-0-pool_modality": "gait"}, 0, "pool_modality", "gesture"),
    ({"sections-0-opt_n_options": "20"}, 0, "opt_n_options", "less than or equal"),
    ({"sections-1-pool_weight_min": "2", "sections-1-pool_weight_max": "1"}, 1, "pool_weight_max", "below"),
    ({"sections-1-opt_n_generated": "5"}, 1, "opt_n_generated", "'n_generated' + 'n_source'"),
]


@pytest.mark.parametrize("edit,index,field,words", BAD_FIELDS)
def test_bad_fields_are_errors_on_their_field_and_save_nothing(admin_client, study, edit, index, field, words):
    before = list(study.sections.order_by("order").values_list("pool", "options"))
    r = change(admin_client, study, {**edit, "title": "Changed"})
    assert r.status_code == 200, "the admin accepted a bad section"
    errors = r.context["inline_admin_formsets"][0].formset.errors[index]
    assert set(errors) == {field} and words in " ".join(errors[field]), errors
    study.refresh_from_db()
    assert study.title != "Changed"
    assert list(study.sections.order_by("order").values_list("pool", "options")) == before


def test_blank_raw_json_is_an_empty_pool_not_a_500(admin_client, study):
    section = study.sections.get(order=1)
    r = change(admin_client, study, {"sections-0-pool": "", "sections-0-options": "",   # as a browser posts them:
                                     "initial-sections-0-pool": json.dumps(section.pool),
                                     "initial-sections-0-options": json.dumps(section.options)})
    assert r.status_code == 302
    assert study.sections.get(order=1).pool == {} and study.sections.get(order=1).options == {}


def test_section_form_reads_its_initial_fields_from_the_saved_json(study):
    section = study.sections.get(order=2)
    form = SectionForm(instance=section)
    assert form.initial["pool_modality"] == ["gesture"] and form.initial["pool_plan"] == "test"
    assert form.initial["opt_n_generated"] == section.options["n_generated"]
    assert "test" in form.fields["pool_plan"].widget.suggestions


# ---- the study form -------------------------------------------------------------------------------------------

def test_exclusion_rules_checked_by_the_analysis_library(admin_client, study):
    r = change(admin_client, study, {"exclusion_rules": json.dumps({"min_rt_fraction": "fast"})})
    assert r.status_code == 200 and "'min_rt_fraction'" in " ".join(r.context["adminform"].form.errors[
        "exclusion_rules"])
    ok = change(admin_client, study, {"exclusion_rules": json.dumps({"min_rt_fraction": 0.3}), "language": "de",
                                      "counterbalance_sections": "on"})
    assert ok.status_code == 302
    study.refresh_from_db()
    assert study.exclusion_rules == {"min_rt_fraction": 0.3} and study.language == "de"
    assert study.counterbalance_sections


def test_exclusion_rules_are_checked_by_the_analysis_library(admin_client, study, monkeypatch):
    from studyapp.admin import forms

    monkeypatch.setattr(forms, "rule_errors", lambda rules: [f"fake: {key!r} refused" for key in rules])
    r = change(admin_client, study, {"exclusion_rules": json.dumps({"anything": 1})})
    assert "fake: 'anything' refused" in r.context["adminform"].form.errors["exclusion_rules"]
    assert Study.objects.get(pk=study.pk).exclusion_rules == {}


# ---- in a real browser ------------------------------------------------------------------------------------------

@pytest.mark.browser
@pytest.mark.slow
@pytest.mark.django_db(transaction=True)
def test_count_updates_as_a_field_changes_in_chromium(chromium, live_server, settings, tmp_path):
    """Log in, open a study, tick an emotion in the gesture section's pool: the count drops to that emotion's
    clips without a save; a weight range upside down shows its field's error; an added naturalness section shows
    its fieldsets and gets a count of both halves. Set POOL_EDITOR_SCREENSHOT=<png> to save
    the section editor (docs/img/admin_pool_editor.png is made this way)."""
    import os

    from selenium.webdriver.common.by import By

    from studyapp.testing import wait_for

    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("gestures_ieeevr2021", "gest", plan="test")
    User.objects.create_superuser("researcher", "r@example.org", "pool-editor-pw-1")
    driver = chromium
    driver.get(live_server.url + "/admin/login/")
    driver.find_element(By.ID, "id_username").send_keys("researcher")
    driver.find_element(By.ID, "id_password").send_keys("pool-editor-pw-1")
    driver.find_element(By.CSS_SELECTOR, "input[type=submit]").click()
    wait_for(driver, lambda d: "/admin/login/" not in d.current_url, what="admin login")
    driver.get(live_server.url + reverse("admin:studyapp_study_change", args=[study.pk]))
    row = driver.find_element(By.ID, "sections-0")
    count_el = row.find_element(By.CSS_SELECTOR, ".pool-count")
    total = Clip.objects.filter(modality="gesture", origin="generated", plan="test").count()
    assert count_el.text.startswith(f"{total} clips")
    natural = driver.find_element(By.ID, "sections-1")
    assert natural.find_element(By.CSS_SELECTOR, "fieldset.only-naturalness").is_displayed()
    assert not row.find_element(By.CSS_SELECTOR, "fieldset.only-naturalness").is_displayed()

    row.find_element(By.CSS_SELECTOR, "input[name='sections-0-pool_emotion_label'][value='sad']").click()
    sad = Clip.objects.filter(modality="gesture", origin="generated", plan="test", emotion_label="sad").count()
    wait_for(driver, lambda d: count_el.text.startswith(f"{sad} clip"), what=f"the count to become {sad}")
    shown = row.find_element(By.CSS_SELECTOR, ".pool-json").text
    assert json.loads(shown.split(": ", 1)[1])["emotion_label"] == "sad" and "from the fields" in shown
    if os.environ.get("POOL_EDITOR_SCREENSHOT"):
        screenshot(driver, os.environ["POOL_EDITOR_SCREENSHOT"])

    row.find_element(By.NAME, "sections-0-pool_weight_min").send_keys("0.5")
    row.find_element(By.NAME, "sections-0-pool_weight_max").send_keys("0.25")
    wait_for(driver, lambda d: "Weight to: 0.25 is below weight from (0.5)" in row.find_element(
        By.CSS_SELECTOR, ".pool-warnings").text, what="the weight range error")
    assert "fix the errors" in count_el.text

    # a section added on the page: its type's fieldsets appear and it gets a live count too
    from selenium.webdriver.support.ui import Select

    driver.find_element(By.CSS_SELECTOR, "#sections-group .add-row a").click()
    added = wait_for(driver, lambda d: d.find_element(By.ID, "sections-2"), what="the added section")
    Select(added.find_element(By.NAME, "sections-2-section_type")).select_by_value("naturalness")
    assert added.find_element(By.CSS_SELECTOR, "fieldset.only-naturalness").is_displayed()
    added.find_element(By.NAME, "sections-2-pool_plan").send_keys("test")
    halves = {o: Clip.objects.filter(plan="test", origin=o).count() for o in HALVES}
    added_count = added.find_element(By.CSS_SELECTOR, ".pool-count")
    wait_for(driver, lambda d: f"({', '.join(f'{o} {n}' for o, n in halves.items())})" in added_count.text,
             what="the added section's count")
    assert Section.objects.get(pk=study.sections.get(order=1).pk).pool.get("emotion_label") is None   # not saved


def screenshot(driver, path: str) -> None:
    """The first section's form, the rest of the page (study fields, other sections, buttons) hidden."""
    from pathlib import Path

    from selenium.webdriver.common.by import By

    from tests.studyapp.participant.test_e2e_study import full_shot

    toggle = driver.find_elements(By.ID, "toggle-nav-sidebar")
    if toggle and toggle[0].is_displayed():
        toggle[0].click()                                  # the page's full width for the form
    driver.execute_script("document.querySelectorAll('#sections-1, .submit-row, #footer, fieldset.module.aligned"
                          ":not(#sections-0 fieldset)').forEach(function (el) { el.style.display = 'none'; });")
    driver.execute_script("document.querySelectorAll('#sections-0 details').forEach(function (d) { d.open = true; "
                          "});")
    full_shot(driver, Path(path), width=1280)


def test_a_section_draws_only_the_modality_it_shows(catalogue):
    """A gait section whose pool names no modality never draws gestures (nor imported `other` videos); its count
    says the same; naturalness sections take either modality."""
    from studyapp.admin.views_pool import count_pool
    from studyapp.data.catalogue import section_queryset

    assert Clip.objects.filter(modality="gesture").exists() and Clip.objects.filter(modality="gait").exists()
    gait = section_queryset("emotion_choice", {})
    assert set(gait.values_list("modality", flat=True)) == {"gait"}
    assert count_pool("emotion_choice", {}).total == gait.count() < pool_queryset({}).count()
    assert set(section_queryset("gesture_emotion", {}).values_list("modality", flat=True)) == {"gesture"}
    assert section_queryset("naturalness", {}).count() == pool_queryset({}).count()
