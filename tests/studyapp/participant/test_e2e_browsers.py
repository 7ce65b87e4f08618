"""The participant flow in the browsers participants use: Chromium, WebKit (WebKitGTK, Safari's engine) and
Firefox ESR each take the demo study (every section type, a practice item and an attention check) from the consent
page to the last page, reloading a clip page in the middle, and every answer is stored once. Each run says which
rendition the player played: with an MP4 and a WebM beside every clip, and with MP4 only (then the browser must
play H.264). The clips are SYNTHETIC test patterns. Fixtures (tests/conftest.py) skip with the reason when a
browser is not installed."""
from __future__ import annotations

import pytest
from browser_flow import take_study

from protocol.vocabulary import ATTENTION_CHECK, SECTION_QUESTIONS, SECTION_TYPES
from studyapp.models import Participant, Response, Study
from studyapp.participant.device_check import MP4_TYPE
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue, wide_clip

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]

BROWSERS = ("chromium", "webkit", "firefox")
RENDITIONS = {"webm+mp4": "webm", "mp4": "mp4"}
"""The files each clip has -> the rendition the player must play (the page lists the WebM first)."""


def demo_study(media_root, tmp_path, files: str) -> Study:
    mp4 = wide_clip(tmp_path / "clip.mp4", seconds=1.0).read_bytes()
    webm = wide_clip(tmp_path / "clip.webm", seconds=1.0, codec="libvpx-vp9").read_bytes() if "webm" in files else None
    make_catalogue(media_root, video_bytes=mp4, duration_s=1.0, webm_bytes=webm)
    study = create_study_from_preset("demo", f"browsers-{files.replace('+', '-')}", plan="test",
                                     status=Study.Status.OPEN)
    walks = study.sections.get(section_type="emotion_choice")
    walks.options = {"practice": True, "attention_checks": {"answer": "sad", "positions": [2]}}
    walks.full_clean()
    walks.save()
    return study


@pytest.mark.parametrize("files", list(RENDITIONS))
@pytest.mark.parametrize("browser", BROWSERS)
def test_participant_flow(browser, files, request, live_server, settings, tmp_path, record_property):
    driver = request.getfixturevalue(browser)
    h264 = driver.execute_script("return document.createElement('video').canPlayType(arguments[0])", MP4_TYPE)
    if files == "mp4" and not h264:
        pytest.skip(f"{browser} cannot play H.264 here (WebKitGTK needs GStreamer's gstreamer1.0-libav)")
    settings.MEDIA_ROOT = tmp_path / "media"
    study = demo_study(settings.MEDIA_ROOT, tmp_path, files)
    run = take_study(driver, live_server.url, study, f"{browser}-1", reload_at=4)

    record_property("rendition", ",".join(sorted(run.renditions)))
    print(f"{browser} with {files}: the player played {sorted(run.renditions)} "
          f"({len(run.pages)} clip pages, reloaded page {run.reloaded_at})")
    assert run.renditions == {RENDITIONS[files]}, run.renditions
    assert all(p.frame == (320, 180) for p in run.pages), [p.frame for p in run.pages]
    assert {p.section_type for p in run.pages} == set(SECTION_TYPES)
    p = Participant.objects.get(study=study, external_id=f"{browser}-1")
    assert p.status == Participant.Status.COMPLETED and p.feedback_done
    assert p.device_kind == "desktop" and p.viewport_width and p.viewport_height
    # every rated page stored each of its questions once; the check its instructed answer; the practice nothing
    for a in p.assignments.select_related("section"):
        stored = list(Response.objects.filter(participant=p, section=a.section, clip=a.clip, kind=a.kind)
                      .values_list("question", flat=True))
        if a.kind == "":
            assert sorted(stored) == sorted(SECTION_QUESTIONS[a.section.section_type]), (a.seq, stored)
        elif a.kind == ATTENTION_CHECK:
            assert stored == ["perceived=sad"]
        else:
            assert stored == []
        assert a.answered_at is not None and a.viewing is not None
    reloaded = p.assignments.get(seq=run.reloaded_at)
    assert reloaded.shows >= 2                      # displayed twice, answered once
    assert Response.objects.get(participant=p, kind=ATTENTION_CHECK).answer == "sad"
