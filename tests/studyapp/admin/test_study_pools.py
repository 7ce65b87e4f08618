"""Section pools and options: protocol.pools checks them against the protocol without Django or a database, and
the admin reports every bad pool filter or option as an error on its field (never a 500 at participant time)."""
from __future__ import annotations

import ast
import json
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from django.test import Client

from protocol.pools import SectionError, errors_by_field, validate_section
from protocol.vocabulary import SECTION_TYPES
from studyapp.models import Section, Study
from studyapp.staff.presets import PRESETS, create_study_from_preset
from studyapp.testing import admin_form_data, make_catalogue

ROOT = Path(__file__).resolve().parents[3]


def test_pools_module_imports_no_django():
    tree = ast.parse((ROOT / "protocol/pools.py").read_text())
    names = [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    names += [n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    assert names and not [n for n in names if n.startswith(("django", "studyapp")) or n.startswith(".")]


def _imports(module: str) -> set[str]:
    """Every module that studyapp/<module>.py imports anywhere (also inside functions), relative ones as
    '.name'."""
    tree = ast.parse((ROOT / "studyapp" / f"{module.replace('.', '/')}.py").read_text())
    names = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    return names | {"." * n.level + (n.module or "") for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}


def test_models_do_not_import_the_catalogue():
    """catalogue -> models -> protocol.pools -> protocol.vocabulary: no cycle."""
    assert not {".catalogue", "studyapp.data.catalogue"} & _imports("models")
    assert "..models" in _imports("data.catalogue") and "protocol.pools" in _imports("models")


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_every_preset_section_is_valid(preset):
    for sec in PRESETS[preset]["sections"]:
        assert sec["section_type"] in SECTION_TYPES
        assert validate_section(sec["section_type"], sec.get("pool", {}), sec.get("options", {}),
                                sec.get("clips_per_participant", 6)) == [], sec


GOOD = [
    ("emotion_choice", {"modality": "gait", "origin": "generated", "transition": False, "rbf": False}, {}),
    ("theme_rating", {"rbf": True, "weight__gt": 0, "theme__in": ["sad", "tired"], "n_features__gte": 2}, {}),
    ("gesture_emotion", {"modality": "gesture", "emotion_label": ["proud", "sad"]},
     {"n_options": 3, "categories": ["proud", "sad", "afraid"]}),
    ("naturalness", {"modality": "gait", "generated": {"plan": "demo"}, "source": {"sections__contains":
                                                                                    "naturalness"}},
     {"anchors": {"1": "bad", "5": "good"}, "question": "Natural?", "n_generated": 3, "n_source": 3}),
    ("neutral_validation", {"theme": "neutral", "clip_id__startswith": "rbf_", "duration_s__isnull": False}, {}),
]


@pytest.mark.parametrize("stype,pool,options", GOOD)
def test_good_sections(stype, pool, options):
    assert validate_section(stype, pool, options, 6) == []


BAD = [  # (section_type, pool, options, clips, field, words the message must contain)
    ("emotion_choice", {"modality": "walk"}, {}, 6, "pool", ["'modality'", "'walk'"]),
    ("emotion_choice", {"origin": 3}, {}, 6, "pool", ["'origin'", "text"]),
    ("emotion_choice", {"video": "x"}, {}, 6, "pool", ["'video'", "not a catalogue field"]),
    ("emotion_choice", {"weight__near": 1}, {}, 6, "pool", ["'weight__near'", "lookup"]),
    ("emotion_choice", {"weight__gt": "big"}, {}, 6, "pool", ["'weight__gt'", "number"]),
    ("emotion_choice", {"n_features": 1.5}, {}, 6, "pool", ["'n_features'", "integer"]),
    ("emotion_choice", {"transition": "yes"}, {}, 6, "pool", ["'transition'", "true or false"]),
    ("emotion_choice", {"theme__in": ["sad", "sleepy"]}, {}, 6, "pool", ["'theme__in'", "'sleepy'"]),
    ("emotion_choice", {"theme__in": []}, {}, 6, "pool", ["'theme__in'", "non-empty list"]),
    ("emotion_choice", {"weight__gt": [1, 2]}, {}, 6, "pool", ["'weight__gt'", "not a list"]),
    ("emotion_choice", {"theme__isnull": True}, {}, 6, "pool", ["'theme__isnull'", "lookup"]),
    ("emotion_choice", {"sections__contains": "dancing"}, {}, 6, "pool", ["'sections__contains'", "'dancing'"]),
    ("emotion_choice", ["gait"], {}, 6, "pool", ["JSON object"]),
    ("emotion_choice", {"generated": {"origin": "generated"}}, {}, 6, "pool", ["'generated'", "naturalness"]),
    ("gesture_emotion", {"modality": "gait"}, {}, 6, "pool", ["'modality'", "gesture"]),
    ("naturalness", {"source": {"origin": "copied"}}, {}, 6, "pool", ["sub-pool 'source'", "'copied'"]),
    ("naturalness", {"generated": "demo"}, {}, 6, "pool", ["sub-pool 'generated'", "JSON object"]),
    ("affect_likert", {}, {"colour": "red"}, 6, "options", ["'colour'", "no options"]),
    ("emotion_choice", {}, "four", 6, "options", ["JSON object"]),
    ("naturalness", {}, {"n_options": 4}, 6, "options", ["'n_options'", "n_generated"]),
    ("naturalness", {}, {"anchors": {"6": "great"}}, 6, "options", ["'anchors'", "'6'"]),
    ("naturalness", {}, {"anchors": ["bad", "good"]}, 6, "options", ["'anchors'"]),
    ("naturalness", {}, {"question": ""}, 6, "options", ["'question'"]),
    ("naturalness", {}, {"n_generated": -1, "n_source": 7}, 6, "options", ["'n_generated'", "integer"]),
    ("naturalness", {}, {"n_generated": 2, "n_source": 2}, 6, "options", ["'n_generated' + 'n_source'", "6"]),
    ("naturalness", {}, {"n_source": 2}, 0, "options", ["both"]),
    ("gesture_emotion", {}, {"n_options": "four"}, 6, "options", ["'n_options'", "integer"]),
    ("gesture_emotion", {}, {"n_options": 12}, 6, "options", ["'n_options'", "2 to 11"]),
    ("gesture_emotion", {}, {"categories": ["proud", "happy", "sad", "afraid"]}, 6, "options",
     ["'categories'", "'happy'"]),
    ("gesture_emotion", {}, {"categories": ["proud", "sad"]}, 6, "options", ["'categories'", "at least 4"]),
    ("emotion_choice", {}, {}, -1, "clips_per_participant", ["0 or more"]),
    ("dance_rating", {}, {}, 6, "section_type", ["'dance_rating'"]),
]


@pytest.mark.parametrize("stype,pool,options,clips,field,words", BAD)
def test_bad_sections_name_the_field(stype, pool, options, clips, field, words):
    errors = errors_by_field(validate_section(stype, pool, options, clips))
    assert field in errors, errors
    message = " | ".join(errors[field])
    for word in words:
        assert word in message, (word, message)


def test_errors_carry_their_field_and_json_keys():
    errors = validate_section(
        "naturalness",
        {"weight__gte": "x", "generated": {"theme": "sleepy"}, "rbf": 1},
        {"n_generated": 2, "n_source": 2, "anchors": {"9": "odd"},
         "attention_checks": {"answer": "7", "count": 0}, "max_replays": -1, "colour": 1}, 6)
    assert all(isinstance(e, SectionError) for e in errors)
    keys = {(e.field, e.keys) for e in errors}
    assert {("pool", ("weight__gte",)), ("pool", ("generated.theme",)), ("pool", ("rbf",)),
            ("options", ("n_generated", "n_source")), ("options", ("anchors.9",)),
            ("options", ("attention_checks.answer",)), ("options", ("attention_checks.count",)),
            ("options", ("max_replays",)), ("options", ("colour",))} == keys
    # every message still names its key, so a reader of the plain text knows what to fix
    by_keys = {e.keys: e.message for e in errors}
    assert "'weight__gte'" in by_keys[("weight__gte",)] and "sub-pool 'generated'" in by_keys[("generated.theme",)]
    assert validate_section("dance", {}, {}) == [SectionError("section_type", validate_section("dance", {}, {})[0]
                                                              .message)]
    assert errors_by_field(validate_section("emotion_choice", {"origin": 3}, {}, -1)) == {
        "pool": ["'origin' takes text, got 3"], "clips_per_participant": ["must be an integer 0 or more, got -1"]}


def test_section_clean_needs_no_database():
    """Section.clean checks a filter's syntax without a query (this test has no database access)."""
    from django.core.exceptions import ValidationError

    bad = Section(section_type="emotion_choice", pool={"weight__gt": "big"}, options={"colour": 1})
    with pytest.raises(ValidationError) as exc:
        bad.clean()
    assert set(exc.value.message_dict) == {"pool", "options"}
    Section(section_type="theme_rating", pool={"rbf": True, "weight__gt": 0}, options={}).clean()


# ---- the admin: the real forms, posted through the test client ------------------------------------------------

@pytest.fixture
def staff(db):
    user = User.objects.create_user("researcher", password="pw-researcher-1", is_staff=True, is_superuser=True)
    c = Client()
    c.force_login(user)
    return c


@pytest.fixture
def study(db, settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    return create_study_from_preset("gestures_ieeevr2021", "gest")


def inline_errors(response) -> list[dict]:
    assert response.status_code == 200, "the admin accepted a bad section"
    return response.context["inline_admin_formsets"][0].formset.errors


CHANGES = [  # (section index, field, posted value, words of the error on that field)
    (0, "pool", json.dumps({"modality": "walk"}), ["'modality'", "'walk'"]),
    (0, "pool", json.dumps({"weight__gt": "big"}), ["'weight__gt'", "number"]),
    (0, "pool", json.dumps({"video": "x.mp4"}), ["'video'"]),
    (0, "pool", json.dumps(["gesture"]), ["JSON object"]),
    (0, "options", json.dumps({"n_options": "four"}), ["'n_options'"]),
    (0, "options", json.dumps({"colour": "red"}), ["'colour'"]),
    (1, "options", json.dumps({"anchors": {"1": "bad"}, "n_generated": 3, "n_source": 3, "size": 2}), ["'size'"]),
    (1, "options", json.dumps({"n_generated": 1, "n_source": 1}), ["'n_generated' + 'n_source'"]),
    (1, "pool", json.dumps({"generated": {"origin": "made"}}), ["sub-pool 'generated'", "'made'"]),
]


@pytest.mark.parametrize("index,field,value,words", CHANGES)
def test_admin_change_form_reports_bad_sections(staff, study, index, field, value, words):
    url = f"/admin/studyapp/study/{study.pk}/change/"
    before = list(study.sections.order_by("order").values_list("pool", "options"))
    data = admin_form_data(staff.get(url))
    data[f"sections-{index}-{field}"] = value
    data["title"] = "Changed title"
    errors = inline_errors(staff.post(url, data))
    message = " | ".join(errors[index].get(field, []))
    for word in words:
        assert word in message, (word, errors)
    assert set(errors[index]) == {field}
    assert len(set(errors[index][field])) == len(errors[index][field])     # each problem reported once
    study.refresh_from_db()
    assert study.title != "Changed title"                    # nothing saved
    assert list(study.sections.order_by("order").values_list("pool", "options")) == before


def add_data(staff, **section) -> dict:
    data = admin_form_data(staff.get("/admin/studyapp/study/add/"))
    data.update({"title": "New study", "slug": "new-study", "status": "draft", "sections-TOTAL_FORMS": "1",
                 "sections-INITIAL_FORMS": "0"})
    fields = {"order": "1", "section_type": "theme_rating", "title": "", "instructions": "", "pool": "{}",
              "clips_per_participant": "6", "reuse_section": "", "options": "{}", "randomize_order": "on"}
    fields.update(section)
    data.update({f"sections-0-{k}": v for k, v in fields.items()})
    return data


def test_admin_add_form_with_bad_section_creates_nothing(staff, study):
    n = Study.objects.count(), Section.objects.count()
    data = add_data(staff, pool=json.dumps({"rbf": True, "theme": "sleepy"}), options=json.dumps({"n_options": 4}))
    errors = inline_errors(staff.post("/admin/studyapp/study/add/", data))
    assert "'sleepy'" in " ".join(errors[0]["pool"]) and "'n_options'" in " ".join(errors[0]["options"])
    bad_type = add_data(staff, section_type="dance_rating")
    assert "section_type" in inline_errors(staff.post("/admin/studyapp/study/add/", bad_type))[0]
    bad_json = add_data(staff, pool="{modality: gait")
    assert "pool" in inline_errors(staff.post("/admin/studyapp/study/add/", bad_json))[0]
    assert (Study.objects.count(), Section.objects.count()) == n


def test_admin_saves_good_sections(staff, study):
    pool = {"rbf": True, "weight__gt": 0, "theme__in": ["sad", "tired"]}
    r = staff.post("/admin/studyapp/study/add/", add_data(staff, pool=json.dumps(pool)))
    assert r.status_code == 302
    section = Study.objects.get(slug="new-study").sections.get()
    assert section.pool == pool and section.section_type == "theme_rating"
    url = f"/admin/studyapp/study/{study.pk}/change/"
    data = admin_form_data(staff.get(url))
    data["sections-1-options"] = json.dumps({"question": "How natural?", "n_generated": 4, "n_source": 2})
    assert staff.post(url, data).status_code == 302
    assert study.sections.get(order=2).options == {"question": "How natural?", "n_generated": 4, "n_source": 2}
