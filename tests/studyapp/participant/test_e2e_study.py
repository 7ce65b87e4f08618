"""End to end in real headless Chromium: take the whole demo study (every section type), reload mid-section, use
the back button, finish, and check the exported responses.csv holds every answer exactly once.

Set STUDY_SCREENSHOTS=<folder> to save a screenshot of the first clip page of each section type there
(docs/img/study_<section_type>.png are made this way); STUDY_SCREENSHOT_VIDEO=<mp4> (and STUDY_SCREENSHOT_SECONDS)
(and STUDY_SCREENSHOT_GESTURE_VIDEO for gesture clips) use rendered clips instead of the 1-second test pattern.
"""
from __future__ import annotations

import csv
import io
import os
import time
import urllib.request
from contextlib import contextmanager
from pathlib import Path

import pytest
from django.urls import reverse

from protocol.vocabulary import SECTION_TYPES
from studyapp.data.export import stream_csv
from studyapp.models import Participant, Response, Study
from studyapp.questions import questions_for
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import consent_and_demographics, make_catalogue, tiny_mp4, wait_for

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]


def path_of(driver) -> str:
    return "/" + driver.current_url.split("/", 3)[3]


def full_shot(driver, path: Path, width: int = 1000):
    """Screenshot of the whole page: the window is made as tall as the document first."""
    driver.set_window_size(width, 900)
    for _ in range(5):
        inner, height = driver.execute_script(
            "return [window.innerHeight, document.documentElement.scrollHeight]")
        if inner >= height:
            break
        driver.set_window_size(width, min(driver.get_window_size()["height"] + int(height) - int(inner) + 24, 4000))
    driver.execute_script("window.scrollTo(0, 0); document.activeElement && document.activeElement.blur()")
    time.sleep(0.3)
    driver.save_screenshot(str(path))
    driver.set_window_size(1280, 900)


def researcher_shots(driver, base: str, study: Study, folder: Path) -> None:
    """Screenshots of the researcher pages: the study in the admin and its progress page."""
    from django.contrib.auth.models import User
    from selenium.webdriver.common.by import By

    User.objects.create_superuser("researcher", "r@example.org", "screenshot-pw-1")
    driver.get(base + "/admin/login/")
    driver.find_element(By.ID, "id_username").send_keys("researcher")
    driver.find_element(By.ID, "id_password").send_keys("screenshot-pw-1")
    driver.find_element(By.CSS_SELECTOR, "input[type=submit]").click()
    wait_for(driver, lambda d: "/admin/login/" not in d.current_url, what="admin login")
    driver.get(base + reverse("studyapp:progress", args=[study.pk]))
    full_shot(driver, folder / "study_admin_progress.png", width=1200)
    driver.get(base + reverse("admin:studyapp_study_change", args=[study.pk]))
    full_shot(driver, folder / "study_admin_study.png", width=1200)


@contextmanager
def requests_seen():
    """The (method, path) of every request the live server starts meanwhile (static files and media excluded)."""
    from django.core.signals import request_started

    seen: list[tuple[str, str]] = []

    def record(sender, environ=None, **kwargs):
        path = (environ or {}).get("PATH_INFO", "")
        if not path.startswith(("/static/", "/m/")):
            seen.append(((environ or {}).get("REQUEST_METHOD", ""), path))

    request_started.connect(record, weak=False)
    try:
        yield seen
    finally:
        request_started.disconnect(record)


def pick_answers(driver, choice: int = 0):
    """Choose option number `choice` (clamped) of every question; for multi-select also the last option."""
    from selenium.webdriver.common.by import By

    for fs in driver.find_elements(By.CSS_SELECTOR, "#answer-form fieldset.question"):
        inputs = fs.find_elements(By.CSS_SELECTOR, "input")
        target = inputs[min(choice, len(inputs) - 1)]
        if not target.is_selected():
            target.find_element(By.XPATH, "..").click()        # click the label, as a person would
        if target.get_attribute("type") == "checkbox" and not inputs[-1].is_selected():
            inputs[-1].find_element(By.XPATH, "..").click()


def test_whole_demo_study_in_chromium(chromium, live_server, settings, tmp_path):
    from selenium.webdriver.common.by import By

    settings.MEDIA_ROOT = tmp_path / "media"
    shots = os.environ.get("STUDY_SCREENSHOTS")
    if shots and os.environ.get("STUDY_SCREENSHOT_VIDEO"):
        video = Path(os.environ["STUDY_SCREENSHOT_VIDEO"])
        seconds = float(os.environ.get("STUDY_SCREENSHOT_SECONDS", "3"))
    else:
        video, seconds = tiny_mp4(tmp_path / "clip.mp4", seconds=1.0, size=160), 1.0
    gesture = os.environ.get("STUDY_SCREENSHOT_GESTURE_VIDEO") if shots else None
    make_catalogue(settings.MEDIA_ROOT, video_bytes=video.read_bytes(), duration_s=seconds,
                   gesture_video_bytes=Path(gesture).read_bytes() if gesture else None)
    study = create_study_from_preset("demo", "demo", plan="test", status=Study.Status.OPEN,
                                     completion_redirect="https://example.org/complete?cc={code}")
    driver = chromium
    entry_url = live_server.url + reverse("studyapp:study_entry", args=[study.slug]) + "?PROLIFIC_PID=e2e-1"
    with urllib.request.urlopen(entry_url) as page:        # the pages carry the Content-Security-Policy
        assert "script-src 'self'" in page.headers["Content-Security-Policy"]
    driver.get(entry_url)
    if shots:
        full_shot(driver, Path(shots) / "study_consent.png")
    consent_and_demographics(driver)
    participant = Participant.objects.get(external_id="e2e-1")
    total = participant.assignments.count()
    seen_types, reloaded, went_back = set(), False, False
    for n in range(1, total + 1):
        wait_for(driver, lambda d, n=n: f"/clip/{n}/" in d.current_url, what=f"clip {n}")
        a = participant.assignments.select_related("section", "clip").order_by("section__order", "position")[n - 1]
        stype = a.section.section_type
        # answers are enabled once the clip has played (looping clips: after one full loop)
        wait_for(driver, lambda d: d.find_element(By.ID, "next").is_enabled(), timeout=10 + 3 * seconds,
                 what="clip played")
        progress = driver.find_element(By.CSS_SELECTOR, ".progress").get_attribute("aria-valuenow")
        assert int(progress) == round(100 * (n - 1) / total)
        if n == 1:
            # under the Content-Security-Policy (no inline script or style) study.js still runs: it shows Replay
            assert driver.find_element(By.ID, "replay").is_displayed()
            assert int(driver.find_element(By.CSS_SELECTOR, "progress.progress").get_attribute("value")) == 0
        if stype not in seen_types:
            seen_types.add(stype)
            if shots:
                pick_answers(driver, 2)
                full_shot(driver, Path(shots) / f"study_{stype}.png")
                if stype == "affect_likert":
                    full_shot(driver, Path(shots) / "study_phone_affect_likert.png", width=390)
        pick_answers(driver, n % 3)
        if n == 2 and not reloaded:
            # reload mid-section before answering: same clip again, nothing saved, nothing lost. Clip 2 came as the
            # answer to clip 1's POST; study.js gave the page its own URL, so the reload is a plain GET of it.
            reloaded = True
            with requests_seen() as seen:
                driver.refresh()
                wait_for(driver, lambda d: "/clip/2/" in d.current_url and d.find_element(By.ID, "answer-form"),
                         what="reloaded clip 2")
            # (the player's own reports of the replay are POSTs to .../playback)
            assert seen and all(method == "GET" or path.endswith("/playback") for method, path in seen), seen
            assert any(path.endswith("/clip/2/") for _method, path in seen), seen
            wait_for(driver, lambda d: d.find_element(By.ID, "next").is_enabled(), timeout=10 + 3 * seconds,
                     what="replayed")
            assert "/clip/2/" in driver.current_url
            assert Response.objects.filter(participant=participant).count() == len(
                questions_for(participant.assignments.order_by("section__order", "position")[0].section.section_type))
            pick_answers(driver, n % 3)
        driver.find_element(By.ID, "next").click()
        wait_for(driver, lambda d, n=n: f"/clip/{n}/" not in d.current_url, what=f"leave clip {n}")
        if n == 3 and not went_back:
            went_back = True
            driver.back()                 # the back button shows where the participant is, not an old clip
            wait_for(driver, lambda d: "/clip/4/" in d.current_url or "/clip/3/" not in d.current_url,
                     what="back button redirect")
            driver.get(live_server.url + reverse("studyapp:resume", args=[participant.token]))
    assert seen_types == set(SECTION_TYPES)
    wait_for(driver, lambda d: "/feedback/" in d.current_url, what="feedback page")
    for fs in driver.find_elements(By.CSS_SELECTOR, "fieldset.question"):
        radios = fs.find_elements(By.CSS_SELECTOR, "input[type=radio]")
        if radios:
            radios[-1].find_element(By.XPATH, "..").click()
        else:
            fs.find_element(By.TAG_NAME, "textarea").send_keys("Clear clips, thanks.")
    driver.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait_for(driver, lambda d: "/done/" in d.current_url, what="completion page")
    if shots:
        full_shot(driver, Path(shots) / "study_done.png")
    assert driver.find_element(By.ID, "completion-code").text == study.completion_code
    assert f"cc={study.completion_code}" in driver.find_element(By.ID, "completion-link").get_attribute("href")

    if shots:
        researcher_shots(driver, live_server.url, study, Path(shots))

    participant.refresh_from_db()
    assert participant.status == "completed" and participant.feedback["comments"] == "Clear clips, thanks."
    rows = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "responses")))))
    expected = {}
    for a in participant.assignments.select_related("section", "clip"):
        for q in questions_for(a.section.section_type, a.section.options, a.clip.theme, a.options):
            expected[(participant.public_id, a.section.section_type, a.clip.clip_id, q.key)] = q
    got = [(r["participant_id"], r["section_type"], r["clip_id"], r["question"]) for r in rows]
    assert len(got) == len(set(got)), "an answer was stored twice"
    assert set(got) == set(expected), "an answer is missing or unexpected"
    reloaded_clip = participant.assignments.get(seq=2).clip.clip_id
    for r in rows:
        q = expected[(r["participant_id"], r["section_type"], r["clip_id"], r["question"])]
        allowed = {c[0] for c in q.choices}
        assert set(r["answer"].split(";")) <= allowed
        if r["clip_id"] == reloaded_clip:
            # watched to its end before the reload: the reloaded page may enable the answers at once
            assert int(r["response_ms"]) >= 0
        else:
            assert int(r["response_ms"]) >= 500       # measured in the browser; clips are 1 s long
