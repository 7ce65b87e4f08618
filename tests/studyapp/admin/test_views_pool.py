"""What the pool editor's live count answers (studyapp.admin.views_pool): counts by origin, sub-pools narrowing their
half, warnings for pools too small, errors instead of exceptions. Who may ask is
tests/studyapp/staff/test_staff_permissions.py's subject; the editor's fields are
tests/studyapp/admin/test_pool_editor.py's."""
from __future__ import annotations

import json

import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.urls import reverse

from studyapp.admin.views_pool import REUSED, PoolCount, count_pool
from studyapp.models import Clip
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def catalogue(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)


def test_counts_follow_the_catalogue(catalogue):
    gait = Clip.objects.filter(modality="gait")
    assert count_pool("emotion_choice", {"modality": "gait"}).total == gait.count()
    nat = count_pool("naturalness", {"modality": "gesture"})
    assert nat.by_origin == {o: Clip.objects.filter(modality="gesture", origin=o).count()
                             for o in ("generated", "source")}
    # a sub-pool narrows only its half
    narrowed = count_pool("naturalness", {"modality": "gesture", "generated": {"emotion_label": "proud"}})
    assert narrowed.by_origin["generated"] == Clip.objects.filter(modality="gesture", origin="generated",
                                                                  emotion_label="proud").count()
    assert narrowed.by_origin["source"] == nat.by_origin["source"] and narrowed.total == nat.total


def test_bad_pools_come_back_as_errors(catalogue):
    bad = count_pool("emotion_choice", {"weight__gt": "big"})
    assert bad.total is None and any("'weight__gt'" in e for e in bad.errors)
    assert bad.summary().startswith("the pool cannot be counted") and bad.warnings(6, {}) == []


def test_warnings_say_when_a_pool_is_too_small():
    assert PoolCount(0).warnings(6, {}) == ["no clip matches: this section would show nothing"]
    assert PoolCount(4).warnings(6, {}) == ["fewer than the 6 clips each participant sees"]
    halves = PoolCount(10, {"generated": 2, "source": 8})
    assert halves.warnings(6, {"n_generated": 3, "n_source": 3}) == [
        "fewer generated clips (2) than the 3 each participant sees"]
    assert PoolCount(1).summary() == "1 clip in the catalogue matches"
    assert halves.summary() == "10 clips in the catalogue match (generated 2, source 8)"


def test_the_endpoint_answers_json_for_good_and_bad_forms(catalogue):
    client = Client()
    client.force_login(User.objects.create_user("ed", password="pw-ed-12345678", is_staff=True, is_superuser=True))
    url = reverse("admin:studyapp_pool_count")
    ok = client.get(url, {"section_type": "emotion_choice", "pool": json.dumps({"modality": "gait"}),
                          "clips_per_participant": 1000, "reuse_section": "1"}).json()
    assert ok["count"] == Clip.objects.filter(modality="gait").count() and ok["errors"] == []
    assert ok["warnings"][0] == REUSED and "fewer than the 1000 clips" in ok["warnings"][1]
    bad = client.get(url, {"section_type": "emotion_choice", "pool": json.dumps({"colour": "red"})}).json()
    error = bad["errors"][0]
    assert bad["count"] is None and error["field"] == "pool" and "'colour'" in error["messages"][0]
    assert client.post(url).status_code == 405
