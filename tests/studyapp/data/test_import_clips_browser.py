"""In headless Chromium: imported clips (an H.264 MP4 remuxed, a VP9 WebM transcoded, a BVH take rendered) play in
a study's gait and naturalness sections and their answers are saved with the imported clip ids.

IMPORT_SCREENSHOTS=<folder> saves the pages of the rendered BVH clip and of the transcoded video while they play
(docs/img/import_clip_playing.png, import_video_playing.png);
IMPORT_MANIFEST=<csv> imports that manifest instead of the synthetic one (its bad rows are reported, not fatal).
"""
from __future__ import annotations

import contextlib
import io
import os
from pathlib import Path

import pytest
from django.core.management import CommandError, call_command
from django.urls import reverse

from studyapp.models import Clip, Participant, Response, Section, Study
from studyapp.testing import consent_and_demographics, wait_for
from tests.studyapp.data.test_import_clips import GOOD, lab, write_manifest  # noqa: F401 - the lab fixture

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]


def _import(manifest: Path, size: str) -> None:
    with contextlib.suppress(CommandError):
        call_command("import_clips", str(manifest), "--render-size", size, stdout=io.StringIO())


def test_imported_clips_play_in_a_study(chromium, live_server, settings, tmp_path, lab):  # noqa: F811
    from selenium.webdriver.common.by import By

    settings.MEDIA_ROOT = tmp_path / "media"
    settings.DATA_DIR = tmp_path / "data"
    shots = os.environ.get("IMPORT_SCREENSHOTS")
    manifest = Path(os.environ["IMPORT_MANIFEST"]) if os.environ.get("IMPORT_MANIFEST") else write_manifest(
        lab, [{**row, "body": "mannequin"} if row.get("body") else row for row in GOOD])
    _import(manifest, "960x540" if shots else "320x180")
    imported = {c.media_key: c for c in Clip.objects.filter(origin="imported")}
    assert len(imported) >= 3 and {c.modality for c in imported.values()} >= {"gait", "other"}
    study = Study.objects.create(slug="own-stimuli", title="Own stimuli", status=Study.Status.OPEN,
                                 ask_demographics=True)
    Section.objects.create(study=study, order=1, section_type="emotion_choice", clips_per_participant=0,
                           pool={"origin": "imported", "modality": "gait"}, options={"controls": "replay-only"})
    Section.objects.create(study=study, order=2, section_type="naturalness", clips_per_participant=0,
                           pool={"origin": "imported", "modality": ["gesture", "other"]})
    driver = chromium
    driver.get(live_server.url + reverse("studyapp:study_entry", args=[study.slug]) + "?PROLIFIC_PID=own-1")
    consent_and_demographics(driver)
    participant = Participant.objects.get(external_id="own-1")
    total = participant.assignments.filter(clip__isnull=False).count()
    assert total == len(imported)
    shown = set()
    for n in range(1, total + 1):
        wait_for(driver, lambda d, n=n: f"/clip/{n}/" in d.current_url, what=f"clip {n}")
        src = driver.find_element(By.ID, "clip").get_attribute("src") or driver.find_element(
            By.CSS_SELECTOR, "#clip source").get_attribute("src")
        clip = next(c for key, c in imported.items() if key in src)
        shown.add(clip.clip_id)
        wait_for(driver, lambda d: d.execute_script(
            "var v = document.getElementById('clip'); return v.readyState >= 2 && v.currentTime > 0.4 && "
            "v.videoWidth > 0;"), timeout=30, what=f"clip {clip.clip_id} playing")
        if shots and clip.metadata.get("kind") == "motion":
            driver.save_screenshot(str(Path(shots) / "import_clip_playing.png"))
        if shots and clip.metadata.get("action") == "transcode":
            driver.save_screenshot(str(Path(shots) / "import_video_playing.png"))
        wait_for(driver, lambda d: d.find_element(By.ID, "next").is_enabled(), timeout=40, what="clip played")
        fieldset = driver.find_element(By.CSS_SELECTOR, "#answer-form fieldset.question")
        fieldset.find_elements(By.CSS_SELECTOR, "input")[0].find_element(By.XPATH, "..").click()
        driver.find_element(By.ID, "next").click()
        wait_for(driver, lambda d, n=n: f"/clip/{n}/" not in d.current_url, what=f"leave clip {n}")
    assert shown == {c.clip_id for c in imported.values()}
    answered = set(Response.objects.filter(participant=participant).values_list("clip__clip_id", flat=True))
    assert answered == shown
