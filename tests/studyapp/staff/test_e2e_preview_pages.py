"""End to end in headless Chromium: the shared preview link shows a break page at its place among the sections,
says how long participants wait there and leaves Continue enabled (static/studyapp/page.js counts nothing down in
a preview); Continue goes on to the next section's clip.

Set STUDY_SCREENSHOTS=<folder> to save the preview's break page at 1366x768 there.
"""
from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
from django.urls import reverse

from studyapp.models import Participant, Section, Study
from studyapp.staff.sharing import preview_token
from studyapp.testing import make_catalogue, tiny_mp4, wait_for

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]

GAIT = {"modality": "gait", "origin": "generated", "transition": False}


def test_a_break_page_in_the_shared_preview_in_chromium(chromium, live_server, settings, tmp_path):
    from selenium.webdriver.common.by import By

    settings.MEDIA_ROOT = tmp_path / "media"
    video = tiny_mp4(tmp_path / "clip.mp4", seconds=1.0, size=160)
    make_catalogue(settings.MEDIA_ROOT, video_bytes=video.read_bytes(), duration_s=1.0)
    study = Study.objects.create(slug="paged", title="Perception of walking styles", status=Study.Status.DRAFT)
    Section.objects.create(study=study, order=1, section_type="break_page", options={"wait_seconds": 60},
                           instructions="You have finished the first part. Take a short rest before the next "
                                        "part: look away from the screen, stretch, relax.")
    Section.objects.create(study=study, order=2, section_type="emotion_choice", clips_per_participant=1,
                           pool=GAIT, require_full_play=False)
    driver = chromium
    driver.get(live_server.url + reverse("studyapp:shared_preview", args=[preview_token(study, 1)]))
    driver.find_element(By.ID, "start-preview").click()
    wait_for(driver, lambda d: d.find_elements(By.ID, "preview-wait"), what="the preview's break page")
    note = driver.find_element(By.ID, "preview-wait").text
    assert "participants wait 60 seconds" in note and "continue at once" in note, note
    assert not driver.find_elements(By.ID, "page-wait")
    if os.environ.get("STUDY_SCREENSHOTS"):
        driver.set_window_size(1366, 768)
        chrome = driver.execute_script("return [window.outerWidth - window.innerWidth, "
                                       "window.outerHeight - window.innerHeight]")
        driver.set_window_size(1366 + chrome[0], 768 + chrome[1])        # a 1366x768 viewport
        time.sleep(0.3)
        driver.save_screenshot(str(Path(os.environ["STUDY_SCREENSHOTS"]) / "preview_break_page.png"))
    assert driver.find_element(By.ID, "continue").is_enabled()
    driver.find_element(By.ID, "continue").click()
    wait_for(driver, lambda d: d.find_elements(By.ID, "next"), what="the clip after the break")
    assert "/2/" in driver.current_url and not Participant.objects.exists()
