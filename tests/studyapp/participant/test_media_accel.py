"""Clip media behind nginx: with settings.MEDIA_ACCEL_REDIRECT the app checks the opaque key and answers with an
empty X-Accel-Redirect response; without it the app streams the bytes itself
(tests/studyapp/participant/test_study_media.py)."""
from __future__ import annotations

import pytest
from django.urls import reverse

from studyapp.data.catalogue import upsert_clips
from studyapp.models import Clip
from studyapp.testing import write_media

pytestmark = pytest.mark.django_db

PAYLOAD = bytes(range(256)) * 8


@pytest.fixture
def client(admin_client):
    """Clip media need a session that may see the clip (studyapp.participant.views.media_allowed): here a
    superuser's."""
    return admin_client


@pytest.fixture
def clip(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    rel = write_media(settings.MEDIA_ROOT, PAYLOAD)
    poster = write_media(settings.MEDIA_ROOT, b"\x89PNG synthetic poster", suffix=".png")
    upsert_clips([{"clip_id": "gait_synthetic_accel", "modality": "gait", "origin": "generated", "video": rel,
                   "poster": poster, "happy": 1, "sad": 0, "angry": 0, "neutral": 0}])
    return Clip.objects.get()


def url(c: Clip, ext: str = "mp4") -> str:
    return reverse("studyapp:media", kwargs={"key": c.media_key, "ext": ext})


def test_accel_redirect_names_the_file_below_the_internal_location(client, clip, settings):
    settings.MEDIA_ACCEL_REDIRECT = "/protected-media/"
    r = client.get(url(clip), HTTP_RANGE="bytes=0-9")
    assert r.status_code == 200 and r.content == b""
    assert r["X-Accel-Redirect"] == "/protected-media/" + clip.video
    assert r["Content-Type"] == "video/mp4"
    assert "Content-Range" not in r           # nginx answers the range, not the app
    poster = client.get(url(clip, "png"))
    assert poster["X-Accel-Redirect"] == "/protected-media/" + clip.poster and poster["Content-Type"] == "image/png"


def test_accel_redirect_keeps_the_app_checks(client, clip, settings):
    settings.MEDIA_ACCEL_REDIRECT = "/protected-media/"
    missing = client.get(reverse("studyapp:media", kwargs={"key": "0" * 32, "ext": "mp4"}))
    assert missing.status_code == 404 and "X-Accel-Redirect" not in missing
    assert client.get(url(clip, "webm")).status_code == 404                 # no WebM for this clip
    from django.test import Client

    refused = Client().get(url(clip))                    # no session that may see it: nginx is never asked
    assert refused.status_code == 403 and "X-Accel-Redirect" not in refused
    Clip.objects.filter(pk=clip.pk).update(video="../../etc/passwd")
    escaped = client.get(url(clip))
    assert escaped.status_code == 404 and "X-Accel-Redirect" not in escaped


def test_accel_path_is_percent_encoded(client, clip, settings):
    settings.MEDIA_ACCEL_REDIRECT = "/protected-media/"
    odd = settings.MEDIA_ROOT / "clips" / "a b#c.mp4"
    odd.write_bytes(PAYLOAD)
    Clip.objects.filter(pk=clip.pk).update(video="clips/a b#c.mp4")
    assert client.get(url(clip))["X-Accel-Redirect"] == "/protected-media/clips/a%20b%23c.mp4"


def test_without_the_setting_the_app_streams(client, clip, settings):
    settings.MEDIA_ACCEL_REDIRECT = ""
    r = client.get(url(clip), HTTP_RANGE="bytes=0-9")
    assert r.status_code == 206 and "X-Accel-Redirect" not in r
    assert b"".join(r.streaming_content) == PAYLOAD[:10]


def test_setting_must_be_a_path_prefix(monkeypatch):
    import importlib

    from django.core.exceptions import ImproperlyConfigured

    import studyapp.settings as study_settings

    monkeypatch.setenv("MEDIA_ACCEL_REDIRECT", "protected-media")
    try:
        with pytest.raises(ImproperlyConfigured, match="MEDIA_ACCEL_REDIRECT"):
            importlib.reload(study_settings)
    finally:
        monkeypatch.delenv("MEDIA_ACCEL_REDIRECT")
        importlib.reload(study_settings)


def test_healthz_answers_without_touching_the_database(client, django_assert_num_queries):
    with django_assert_num_queries(0):
        r = client.get("/healthz")
    assert r.status_code == 200 and r.content == b"ok" and r["Content-Type"].startswith("text/plain")


def test_favicon_is_the_static_icon(client):
    r = client.get("/favicon.ico")
    assert r.status_code == 301 and r["Location"].endswith("studyapp/favicon.svg")
    assert client.get(r["Location"]).status_code == 200
