"""Readable clip titles (protocol.titles): derived from a clip's intent and record at catalogue time, kept for
imported files, filled in for clips catalogued before titles existed, and exported in clips.csv's ``title``."""
from __future__ import annotations

import importlib

import pytest
from django.apps import apps as django_apps

from protocol.titles import TITLE_MAX_LENGTH, clip_title, clip_titles, condition_label, emotion_mix
from studyapp.data.catalogue import upsert_clips
from studyapp.models import Clip


def walk(clip_id: str, vector, seed: int, generator: str = "gait_net", final=None, **meta) -> dict:
    rec = {"clip_id": clip_id, "modality": "gait", "origin": "generated", "plan": "p", "video": f"clips/{clip_id}.mp4",
           **dict(zip(("happy", "sad", "angry", "neutral"), vector, strict=True)),
           "metadata": {"generator": generator, "seed": seed, "entry_id": clip_id,
                        "inputs": {"trajectory": {"kind": "curved"}}, **meta}}
    if final is not None:
        rec.update(zip(("final_happy", "final_sad", "final_angry", "final_neutral"), final, strict=True))
    return rec


def test_a_mixture_is_named_by_its_components_largest_first_and_variants_are_numbered_by_seed():
    records = [walk("b", (0.8, 0, 0, 0.2), seed=9), walk("a", (0.8, 0, 0, 0.2), seed=3),
               walk("c", (0, 1, 0, 0), seed=1)]
    titles = clip_titles(records)
    assert titles == {"a": "gait net, happy 0.8 + neutral 0.2, path 1",
                      "b": "gait net, happy 0.8 + neutral 0.2, path 2",
                      "c": "gait net, sad"}             # alone in its condition: no variant


def test_transitions_fallbacks_gestures_themes_and_takes_are_named():
    tr = walk("t", (0.8, 0, 0, 0.2), 1, final=(0, 0.8, 0, 0.2))
    assert condition_label(tr) == "happy 0.8 + neutral 0.2 to sad 0.8 + neutral 0.2"
    fb = walk("f", (0, 0, 1, 0), 1, generator="procedural_walk", fallback_for="gait_net")
    assert clip_title(fb) == "procedural walk (in place of gait net), angry"
    gesture = {"clip_id": "g", "modality": "gesture", "origin": "generated", "emotion_label": "afraid",
               "metadata": {"generator": "gesture_net"}}
    assert clip_title(gesture) == "gesture net, afraid"
    vad = {"clip_id": "v", "modality": "gesture", "origin": "generated", "valence": 0.25, "arousal": 0.5,
           "dominance": 1.0, "metadata": {"generator": "procedural_gesture"}}
    assert clip_title(vad) == "procedural gesture, valence 0.25, arousal 0.5, dominance 1"
    rbf = {"clip_id": "r", "modality": "gait", "origin": "generated", "theme": "tired", "weight": -0.7,
           "metadata": {"generator": "rbf"}}
    assert clip_title(rbf) == "rbf, tired -0.7"
    take = {"clip_id": "s", "modality": "gait", "origin": "source",
            "metadata": {"generator": "captured", "inputs": {"clip": "turn_left0.txt"}}}
    assert clip_title(take) == "captured, take turn_left0"
    assert clip_title({"clip_id": "x", "modality": "gait", "origin": "source"}) == "gait, source, no emotion"
    assert emotion_mix([0, 0, 0, 0]) == "" and emotion_mix([None, 2, None, 2]) == "sad 0.5 + neutral 0.5"


def test_an_own_title_wins_and_long_titles_are_cut():
    imported = {"clip_id": "i", "modality": "other", "origin": "imported", "plan": "import:x",
                "metadata": {"title": "  Walk   across the room "}}
    assert clip_title(imported) == "Walk across the room"
    assert len(clip_title({"clip_id": "l", "title": "x" * 500})) == TITLE_MAX_LENGTH


@pytest.mark.django_db
def test_upsert_sets_titles_and_the_migration_fills_in_old_clips():
    upsert_clips([walk("a1", (1, 0, 0, 0), 1), walk("a2", (1, 0, 0, 0), 2),
                  {**walk("own", (0, 1, 0, 0), 3), "title": "my sad walk"}])
    assert dict(Clip.objects.values_list("clip_id", "title")) == {
        "a1": "gait net, happy, path 1", "a2": "gait net, happy, path 2", "own": "my sad walk"}
    Clip.objects.update(title="")                     # as catalogued before the field existed
    migration = importlib.import_module("studyapp.migrations.0014_workflow_clip_title")
    migration.fill_titles(django_apps, None)
    assert dict(Clip.objects.values_list("clip_id", "title"))["a2"] == "gait net, happy, path 2"


@pytest.fixture
def staff():
    from django.contrib.auth.models import User
    from django.test import Client

    client = Client()
    client.force_login(User.objects.create_user("lead", password="pw-lead-12345", is_staff=True, is_superuser=True))
    return client


@pytest.fixture
def catalogue(settings, tmp_path):
    from studyapp.testing import make_catalogue, write_media

    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    poster = write_media(settings.MEDIA_ROOT, b"\x89PNG poster", ".png")
    Clip.objects.filter(clip_id__startswith="gait_gen_").update(poster=poster)


@pytest.mark.django_db
def test_the_clip_list_is_paginated_with_thumbnails_the_security_policy_allows(staff, catalogue):
    import re

    from django.urls import reverse

    page = staff.get(reverse("admin:studyapp_clip_changelist") + "?o=2")    # ordered by title
    html = page.content.decode()
    assert page.status_code == 200 and "style-src 'self'" in page["Content-Security-Policy"]
    rows = page.context["cl"].result_list
    assert len(rows) == 25 < Clip.objects.count()                 # one page of 25
    assert "studyapp/admin_clips.css" in html                       # the thumbnails' size comes from a file
    thumbs = re.findall(r"<img [^>]*class=\"clip-thumb\"[^>]*>", html)
    assert thumbs and all('width="85"' in t and 'height="48"' in t and "style=" not in t for t in thumbs)
    assert "gait, generated, happy" in html                         # titles, not only ids


@pytest.mark.django_db
def test_progress_and_pool_editor_show_titles_and_posters(staff, catalogue):
    from django.urls import reverse

    from studyapp.models import Participant, Study
    from studyapp.participant.assignment import start_participant
    from studyapp.staff.presets import create_study_from_preset

    study = create_study_from_preset("gait_ismar2020", "titled", plan="test", status=Study.Status.OPEN)
    start_participant(Participant.objects.create(study=study, demographics_done=True))
    html = staff.get(reverse("studyapp:progress", args=[study.pk])).content.decode()
    assert 'class="clip-title">gait, generated, ' in html and 'class="clip-thumb"' in html
    answer = staff.get(reverse("admin:studyapp_pool_count"),
                       {"section_type": "emotion_choice", "clips_per_participant": "6", "pool": '{"plan": "test"}',
                        "options": "{}"}).json()
    assert answer["count"] and 0 < len(answer["sample"]) <= 8
    titles = {c["clip_id"]: c["title"] for c in answer["sample"]}
    assert titles == dict(Clip.objects.filter(clip_id__in=titles).values_list("clip_id", "title"))
    assert any(c["thumb_url"].startswith("/m/") for c in answer["sample"])
    edit = staff.get(reverse("admin:studyapp_study_change", args=[study.pk])).content.decode()
    assert 'class="clip-samples"' in edit and 'class="clip-title">' in edit
