"""In headless Chromium: the consent page states the computed duration, a practice item is marked "Practice" and
its answer is not stored, an attention check shows its instruction above the question and its answer is stored
as an attention check. STUDY_SCREENSHOTS=<folder> saves docs/img/study_practice.png, study_attention_check.png
and study_consent_duration.png there."""
from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
from django.urls import reverse

from protocol.vocabulary import ATTENTION_CHECK
from studyapp.models import Assignment, Participant, Response, Study
from studyapp.participant.duration import expected_minutes
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import consent_and_demographics, make_catalogue, tiny_mp4, wait_for

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]


def shot(driver, folder: str | None, name: str) -> None:
    if not folder:
        return
    driver.set_window_size(1000, 900)
    height = driver.execute_script("return document.documentElement.scrollHeight")
    driver.set_window_size(1000, min(int(height) + 140, 3000))
    time.sleep(0.3)
    driver.save_screenshot(str(Path(folder) / name))
    driver.set_window_size(1280, 900)


def click_value(driver, value: str) -> None:
    from selenium.webdriver.common.by import By

    driver.find_element(By.CSS_SELECTOR, f"#answer-form input[value='{value}']").find_element(By.XPATH, "..").click()


def answer_when_played(driver, n: int, value: str, folder: str | None = None, name: str = "") -> None:
    """Wait until clip n has played (the answers are enabled then), choose ``value``, optionally take a
    screenshot, and submit."""
    from selenium.webdriver.common.by import By

    wait_for(driver, lambda d: d.find_element(By.ID, "next").is_enabled(), timeout=15, what=f"clip {n} played")
    click_value(driver, value)
    if name:
        shot(driver, folder, name)
    driver.find_element(By.ID, "next").click()
    wait_for(driver, lambda d: f"/clip/{n + 1}/" in d.current_url, what=f"clip {n + 1}")


def test_practice_and_attention_check_in_chromium(chromium, live_server, settings, tmp_path):
    from selenium.webdriver.common.by import By

    settings.MEDIA_ROOT = tmp_path / "media"
    video = tiny_mp4(tmp_path / "clip.mp4", seconds=1.0, size=160)
    make_catalogue(settings.MEDIA_ROOT, video_bytes=video.read_bytes(), duration_s=1.0)
    study = create_study_from_preset("gait_ismar2020", "extras", plan="test", status=Study.Status.OPEN)
    section = study.sections.get(order=1)
    section.options = {"practice": True, "attention_checks": {"answer": "sad", "positions": [2]}}
    section.full_clean()
    section.save()
    shots = os.environ.get("STUDY_SCREENSHOTS")
    driver = chromium
    driver.get(live_server.url + reverse("studyapp:study_entry", args=[study.slug]) + "?PROLIFIC_PID=x-1")
    duration = driver.find_element(By.CSS_SELECTOR, "p.duration").text
    assert f"about {expected_minutes(study)} minute" in duration
    shot(driver, shots, "study_consent_duration.png")
    consent_and_demographics(driver)
    # 1: the practice item, marked as such
    badge = driver.find_element(By.CSS_SELECTOR, ".practice-badge")
    assert badge.is_displayed() and "Practice" in badge.text
    answer_when_played(driver, 1, "happy", shots, "study_practice.png")
    # 2: a trial; 3: the attention check (second rated item of the section)
    answer_when_played(driver, 2, "neutral")
    instruction = driver.find_element(By.ID, "page-note")
    assert instruction.is_displayed() and "with Sad only" in instruction.text
    assert instruction.location["y"] < driver.find_element(By.CSS_SELECTOR, "fieldset.question").location["y"]
    assert len(driver.find_elements(By.CSS_SELECTOR, "fieldset.question")) == 1
    answer_when_played(driver, 3, "sad", shots, "study_attention_check.png")
    p = Participant.objects.get(external_id="x-1")
    practice = p.assignments.get(kind=Assignment.Kind.PRACTICE)
    assert practice.answered_at is not None
    assert not Response.objects.filter(participant=p, clip_id=practice.clip_id, section=section, kind="").exists()
    check = Response.objects.get(participant=p, kind=ATTENTION_CHECK)
    assert (check.question, check.answer) == ("perceived=sad", "sad")
    assert Response.objects.filter(participant=p, kind="").count() == 1
