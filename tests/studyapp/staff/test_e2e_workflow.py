"""In headless Chromium, the researcher's journey from an empty catalogue to a study ready for Prolific, with no
command line: log in, create a study from the seed 000 preset, render a (small) stimulus set from the admin and
point the study's pools at it, share a preview link and open it in a browser without a session, run two pilot
participants, delete the pilot data, clone the study and open the clone.

The render jobs run here as threads of the test server instead of detached processes: the test database lives in
this process's memory, out of reach of another process (tests/studyapp/data/test_stimulus_sets.py runs the real detached
process, kills it and resumes it). STUDY_SCREENSHOTS=<folder> saves the pages at 1366x768 as workflow_*.png."""
from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from django.core.management import call_command
from django.db import connections
from django.urls import reverse

from studyapp.data import background, render_jobs
from studyapp.models import Clip, Participant, Study
from studyapp.testing import wait_for
from tests.studyapp.participant.test_e2e_norming import simulated_participant

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]

CONDITIONS = "happy\nsad\nangry\nneutral\nhappy 0.6 + neutral 0.4\nsad to happy\nangry to neutral"


def shot(driver, folder: str | None, name: str, element_id: str = "") -> None:
    """The page as a 1366x768 screen shows it: its top, or scrolled to the element ``element_id``."""
    if folder:
        from selenium.webdriver.common.by import By

        driver.set_window_size(1366, 768)
        if element_id:
            driver.execute_script("arguments[0].scrollIntoView();", driver.find_element(By.ID, element_id))
        time.sleep(0.3)
        driver.save_screenshot(str(Path(folder) / name))


def threaded_jobs(monkeypatch) -> dict:
    """Background commands as threads of this process (see the module docstring); returns folder -> thread."""
    threads: dict[str, threading.Thread] = {}

    def launch(cmd, folder, log_name, pid_name):
        args = cmd[cmd.index("generate_clips") + 1:]
        # SQLite's in-memory test database is reachable only through the test server's own connection; a
        # PostgreSQL one is a real database, and its pooled connections must not cross threads
        shared = connections["default"] if connections["default"].vendor == "sqlite" else None
        if shared is not None:
            shared.inc_thread_sharing()

        def run():
            if shared is not None:
                connections["default"] = shared
            with open(Path(folder) / log_name, "a") as log:
                try:
                    call_command("generate_clips", *args, stdout=log, stderr=log)
                except Exception as exc:  # noqa: BLE001 - the job's log says what failed, as the real one does
                    log.write(f"{exc}\n")
                finally:
                    if shared is not None:
                        shared.dec_thread_sharing()
                    else:
                        connections["default"].close()

        threads[str(folder)] = thread = threading.Thread(target=run, daemon=True)
        thread.start()
        return 0

    monkeypatch.setattr(background, "launch", launch)
    monkeypatch.setattr(background, "is_running",
                        lambda folder, pid_name: str(folder) in threads and threads[str(folder)].is_alive())
    return threads


def log_in(driver, url: str) -> None:
    from selenium.webdriver.common.by import By

    driver.get(url + "/admin/login/")
    driver.find_element(By.NAME, "username").send_keys("lead")
    driver.find_element(By.NAME, "password").send_keys("pw-for-tests")
    driver.find_element(By.CSS_SELECTOR, "input[type=submit]").click()
    wait_for(driver, lambda d: "/admin/login/" not in d.current_url, what="admin login")


def fill(driver, name: str, value: str) -> None:
    from selenium.webdriver.common.by import By

    field = driver.find_element(By.NAME, name)
    field.clear()
    field.send_keys(value)


def test_from_a_preset_to_a_piloted_shared_and_cloned_study(chromium, live_server, settings, tmp_path, monkeypatch):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    settings.MEDIA_ROOT = tmp_path / "media"
    settings.DATA_DIR = tmp_path / "data"
    settings.REPORTS_DIR = tmp_path / "reports"
    threads = threaded_jobs(monkeypatch)
    shots = os.environ.get("STUDY_SCREENSHOTS")
    User.objects.create_superuser("lead", "lead@example.org", "pw-for-tests")
    driver, url = chromium, live_server.url
    started = time.perf_counter()

    # 1. log in, create a study from the seed 000 preset: the page offers to render its plan
    log_in(driver, url)
    driver.get(url + reverse("studyapp:create_from_preset"))
    Select(driver.find_element(By.NAME, "preset")).select_by_value("gait_ismar2020")
    fill(driver, "slug", "gaits")
    driver.find_element(By.CSS_SELECTOR, "form [type=submit]").click()
    offer = wait_for(driver, lambda d: d.find_element(By.ID, "render-preset-plan"), what="the offer to render")
    study = Study.objects.get(slug="gaits")
    shot(driver, shots, "workflow_1_study_created.png")

    # 2. the stimulus page: a small set of our own (the preset's plan is 34 full-size clips), checked, rendered
    offer.click()
    wait_for(driver, lambda d: d.find_element(By.ID, "builtin-seed000"), what="the stimulus page")
    fill(driver, "name", "gaits-mini")
    Select(driver.find_element(By.NAME, "generator")).select_by_value("procedural_walk")
    fill(driver, "conditions", CONDITIONS)
    fill(driver, "variants", "2")
    for name, value in (("width", "160"), ("height", "120"), ("fps", "10"), ("duration_s", "1")):
        fill(driver, name, value)
    driver.find_element(By.CSS_SELECTOR, "button[value=check]").click()
    estimate = wait_for(driver, lambda d: d.find_element(By.ID, "stimulus-estimate"), what="the check")
    assert "Expected render time" in estimate.text
    assert "procedural walk, sad to happy, path 2" in driver.find_element(By.ID, "stimulus-clips").text
    shot(driver, shots, "workflow_2_stimulus_set.png", "stimulus-check")
    render_started = time.perf_counter()
    driver.find_element(By.CSS_SELECTOR, "button[value=render]").click()
    status_url = wait_for(driver, lambda d: d.find_element(By.ID, "render-status") and d.current_url,
                          what="the render's page").split("#")[0]

    for thread in list(threads.values()):
        thread.join(timeout=240)          # the render shares the test server's one database connection
        assert not thread.is_alive(), "the render did not finish"

    def finished(d) -> bool:
        if d.find_element(By.ID, "render-status").get_attribute("data-status") == "done":
            return True
        time.sleep(1.0)
        d.get(status_url)         # as the page's own refresh does every 3 s
        return False

    try:
        wait_for(driver, finished, timeout=60, what="the render's page to say it is done")
    except AssertionError as exc:
        state = render_jobs.render_state(status_url.rstrip("/").rsplit("/", 1)[-1])
        raise AssertionError(f"{exc}; the render is {state.status}, its log ends:\n{state.log[-1500:]}") from None
    render_s = time.perf_counter() - render_started
    assert Clip.objects.filter(plan="gaits-mini").count() == 14
    assert driver.find_element(By.ID, "render-sheet").is_displayed()
    shot(driver, shots, "workflow_3_render_done.png")

    # 3. the study draws its clips from the new set, in pilot mode
    driver.get(url + reverse("admin:studyapp_study_change", args=[study.pk]))
    for field in driver.find_elements(By.CSS_SELECTOR, "input[name$='-pool_plan']"):
        if field.is_displayed() and field.get_attribute("name").count("-") == 2:
            field.clear()
            field.send_keys("gaits-mini")
    driver.find_element(By.NAME, "pilot").click()
    driver.find_element(By.NAME, "_continue").click()
    wait_for(driver, lambda d: d.find_elements(By.CSS_SELECTOR, ".messagelist"), what="the save")
    study.refresh_from_db()
    assert study.pilot and study.sections.filter(pool__plan="gaits-mini").count() >= 3

    # 4. progress page: Prolific URL, a shared preview link
    driver.get(url + reverse("studyapp:progress", args=[study.pk]))
    assert "{{%PROLIFIC_PID%}}" in driver.find_element(By.ID, "prolific-url").get_attribute("value")
    fill(driver, "days", "7")
    driver.find_element(By.CSS_SELECTOR, "#share-form [type=submit]").click()
    link = wait_for(driver, lambda d: d.find_element(By.ID, "shared-preview-url"), what="the preview link")
    preview = link.get_attribute("value")
    shot(driver, shots, "workflow_4_share.png")
    driver.get(url + reverse("studyapp:progress", args=[study.pk]))
    shot(driver, shots, "workflow_4_progress.png")

    # 5. the link in a browser without a session: the study as participants see it, nothing stored
    driver.delete_all_cookies()
    driver.get(preview)
    driver.find_element(By.ID, "start-preview").click()
    wait_for(driver, lambda d: d.find_element(By.ID, "clip"), what="the first clip of the preview")
    shot(driver, shots, "workflow_5_shared_preview.png")
    assert not Participant.objects.exists()

    # 6. two pilot participants (through the participant pages), then their data deleted
    study.sections.update(require_full_play=False)       # the test client plays no video
    for pid in ("pilot-one", "pilot-two"):
        simulated_participant(study, pid)
    assert list(Participant.objects.values_list("pilot", flat=True)) == [True, True]
    log_in(driver, url)
    driver.get(url + reverse("studyapp:progress", args=[study.pk]) + "#pilot")
    assert driver.find_element(By.ID, "n-pilot").text == "2"
    driver.find_element(By.CSS_SELECTOR, "#delete-pilot-form input[name=confirm]").click()
    driver.find_element(By.CSS_SELECTOR, "#delete-pilot-form [type=submit]").click()
    wait_for(driver, lambda d: d.find_element(By.ID, "n-pilot").text == "0", what="the pilot data deleted")
    assert not Participant.objects.exists()

    # 7. clone the study and open the clone
    driver.find_element(By.ID, "clone-link").click()
    fill(driver, "slug", "gaits-second")
    driver.find_element(By.CSS_SELECTOR, "#clone-form [type=submit]").click()
    clone = wait_for(driver, lambda d: Study.objects.filter(slug="gaits-second").first(), what="the clone")
    wait_for(driver, lambda d: f"/study/{clone.pk}/change/" in d.current_url, what="the clone's page")
    assert clone.sections.count() == study.sections.count() and not clone.participants.exists()
    assert list(clone.sections.values_list("pool", flat=True)) == list(study.sections.values_list("pool", flat=True))
    shot(driver, shots, "workflow_6_clone.png")
    driver.get(url + reverse("admin:studyapp_clip_changelist") + "?plan=gaits-mini")
    shot(driver, shots, "workflow_7_clip_list.png")
    if shots:
        (Path(shots) / "workflow_timing.txt").write_text(
            f"journey {time.perf_counter() - started:.0f} s, of which rendering {render_s:.0f} s\n")
