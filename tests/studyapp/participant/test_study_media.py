"""Clip media: HTTP Range support, opaque URLs, no path escapes."""
from __future__ import annotations

import pytest
from django.urls import reverse

from studyapp.data.catalogue import upsert_clips
from studyapp.models import Clip
from studyapp.participant.media import parse_range
from studyapp.testing import write_media

pytestmark = pytest.mark.django_db

PAYLOAD = bytes(range(256)) * 40      # 10240 bytes


@pytest.fixture
def client(admin_client):
    """Clip media need a session that may see the clip (studyapp.participant.views.media_allowed): here a
    superuser's."""
    return admin_client


@pytest.fixture
def clip(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    rel = write_media(settings.MEDIA_ROOT, PAYLOAD)
    upsert_clips([{"clip_id": "gait_happy_secret", "modality": "gait", "origin": "generated", "video": rel,
                   "happy": 1, "sad": 0, "angry": 0, "neutral": 0}])
    return Clip.objects.get()


def url(c: Clip, ext: str = "mp4") -> str:
    return reverse("studyapp:media", kwargs={"key": c.media_key, "ext": ext})


def body(r) -> bytes:
    return b"".join(r.streaming_content) if r.streaming else r.content


def test_url_is_opaque(clip):
    u = url(clip)
    assert "happy" not in u and "gait" not in u and clip.video not in u


def test_full_file(client, clip):
    r = client.get(url(clip))
    assert r.status_code == 200 and r["Accept-Ranges"] == "bytes" and r["Content-Type"] == "video/mp4"
    assert body(r) == PAYLOAD and r["Content-Length"] == str(len(PAYLOAD))


@pytest.mark.parametrize("header,start,end", [("bytes=0-1", 0, 1), ("bytes=100-", 100, 10239),
                                              ("bytes=-500", 9740, 10239), ("bytes=10000-99999", 10000, 10239)])
def test_range(client, clip, header, start, end):
    r = client.get(url(clip), HTTP_RANGE=header)
    assert r.status_code == 206
    assert r["Content-Range"] == f"bytes {start}-{end}/{len(PAYLOAD)}"
    assert body(r) == PAYLOAD[start:end + 1]
    assert r["Content-Length"] == str(end - start + 1)


def test_unsatisfiable_range(client, clip):
    r = client.get(url(clip), HTTP_RANGE="bytes=20000-")
    assert r.status_code == 416 and r["Content-Range"] == f"bytes */{len(PAYLOAD)}"


def test_head_and_missing(client, clip):
    r = client.head(url(clip))
    assert r.status_code == 200 and r["Content-Length"] == str(len(PAYLOAD))
    assert client.get(url(clip, "webm")).status_code == 404          # no WebM for this clip
    assert client.get(reverse("studyapp:media", kwargs={"key": "0" * 32, "ext": "mp4"})).status_code == 404


def test_path_outside_media_root_refused(client, clip):
    Clip.objects.filter(pk=clip.pk).update(video="../../etc/passwd")
    assert client.get(url(clip)).status_code == 404


def test_parse_range_rejects_garbage():
    assert parse_range("", 100) is None
    assert parse_range("bytes=0-1,5-6", 100) is None      # multi-range: whole file
    with pytest.raises(ValueError):
        parse_range("bytes=50-10", 100)
