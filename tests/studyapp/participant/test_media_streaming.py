"""Media and downloads under ASGI: clip and poster bodies are async iterators over the file (no "must consume
synchronous iterators" warning, nothing read whole before the first byte), a range reads only its range, and the
CSV exports and the report zip stream the same way; under WSGI the bodies stay plain iterators."""
from __future__ import annotations

import asyncio
import os
import warnings

import pytest
from asgiref.sync import async_to_sync
from django.contrib.auth.models import User
from django.test import AsyncClient, Client
from django.urls import reverse

from studyapp.data.catalogue import upsert_clips
from studyapp.models import Clip, Participant, Study
from studyapp.participant import streaming
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import write_media

pytestmark = pytest.mark.django_db

SIZE = 3 * 1024 * 1024 + 17
PAYLOAD = os.urandom(SIZE)          # synthetic bytes standing in for a video


@pytest.fixture
def clip(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    rel = write_media(settings.MEDIA_ROOT, PAYLOAD)
    poster = write_media(settings.MEDIA_ROOT, PAYLOAD[:5000], ".png")
    upsert_clips([{"clip_id": "synthetic_big", "modality": "gait", "origin": "generated", "video": rel,
                   "poster": poster, "happy": 1, "sad": 0, "angry": 0, "neutral": 0}])
    return Clip.objects.get()


@pytest.fixture
def root():
    return User.objects.create_superuser("root", "r@example.org", "pw-root-12345")


def media_url(clip, ext="mp4") -> str:
    return reverse("studyapp:media", kwargs={"key": clip.media_key, "ext": ext})


def asgi_get(user, url: str, **headers):
    """GET through Django's ASGI handler; the body collected from its async iterator, warnings as errors."""
    async def run():
        client = AsyncClient()
        await client.aforce_login(user)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            response = await client.get(url, headers=headers)
            assert response.streaming and response.is_async, "not an async body under ASGI"
            body = b"".join([part async for part in response])
        return response, body
    return async_to_sync(run)()


def test_clips_and_posters_are_async_under_asgi_and_ranges_are_exact(clip, root):
    r, body = asgi_get(root, media_url(clip))
    assert r.status_code == 200 and body == PAYLOAD and r["Content-Length"] == str(SIZE)
    r, body = asgi_get(root, media_url(clip), range="bytes=1000000-1999999")
    assert r.status_code == 206 and body == PAYLOAD[1000000:2000000]
    assert r["Content-Range"] == f"bytes 1000000-1999999/{SIZE}"
    r, body = asgi_get(root, media_url(clip), range="bytes=-100")
    assert r.status_code == 206 and body == PAYLOAD[-100:]
    r, body = asgi_get(root, media_url(clip, "png"))
    assert r.status_code == 200 and body == PAYLOAD[:5000]


def test_under_wsgi_the_body_stays_a_plain_iterator(clip, root):
    c = Client()
    c.force_login(root)
    r = c.get(media_url(clip), headers={"range": "bytes=10-19"})
    assert r.status_code == 206 and not r.is_async and b"".join(r.streaming_content) == PAYLOAD[10:20]


class CountingFile:
    """A file that counts the bytes read from it."""

    def __init__(self, path, mode, reads: list):
        self.fh = open(path, mode)  # noqa: SIM115 - closed by close()
        self.reads = reads

    def seek(self, pos):
        return self.fh.seek(pos)

    def read(self, n):
        data = self.fh.read(n)
        self.reads.append(len(data))
        return data

    def close(self):
        self.fh.close()


def test_a_range_reads_only_its_range_and_the_first_block_comes_before_the_rest(clip, monkeypatch, tmp_path):
    reads: list[int] = []
    monkeypatch.setattr(streaming, "open", lambda path, mode: CountingFile(path, mode, reads), raising=False)
    path = tmp_path / "media" / clip.video

    async def first_then_rest(start, length):
        it = streaming.aiter_file(path, start, length)
        first = await it.__anext__()
        read_before_first = sum(reads)
        rest = [part async for part in it]
        return first, read_before_first, b"".join([first, *rest])

    first, before, whole = asyncio.run(first_then_rest(0, SIZE))
    assert before == len(first) == streaming.ASYNC_BLOCK          # one block read, not the file
    assert whole == PAYLOAD
    reads.clear()
    _, _, part = asyncio.run(first_then_rest(2_000_000, 300_000))
    assert part == PAYLOAD[2_000_000:2_300_000] and sum(reads) == 300_000     # only the range


def test_exports_and_the_report_stream_under_asgi(settings, tmp_path, root):
    from django.core.management import call_command

    from studyapp.testing import make_catalogue
    from tests.studyapp.staff.test_study_admin import finish

    settings.MEDIA_ROOT = tmp_path / "media"
    settings.REPORTS_DIR = tmp_path / "reports"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("gait_ismar2020", "asgi", plan="test", status=Study.Status.OPEN)
    finish(Participant.objects.create(study=study, external_id="PID-1"))
    plain = Client()
    plain.force_login(root)
    for kind in ("responses", "participants", "viewing"):
        url = reverse("studyapp:export_csv", args=[study.pk, kind])
        r, body = asgi_get(root, url)
        assert r.status_code == 200 and body == b"".join(plain.get(url).streaming_content), kind
    call_command("build_report", str(study.pk), stdout=open(os.devnull, "w"))  # noqa: SIM115
    r, body = asgi_get(root, reverse("studyapp:report_zip", args=[study.pk]))
    assert r.status_code == 200 and body[:2] == b"PK" and len(body) == int(r["Content-Length"])
