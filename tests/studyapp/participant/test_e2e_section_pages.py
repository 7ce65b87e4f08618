"""End to end in the participants' browsers (Chromium, WebKit, Firefox ESR; a missing one is skipped with the reason):
a break page between sections counts down under the Content-Security-Policy
(static/studyapp/page.js), enables Continue only after its wait, and an instruction page survives a reload; the
participant goes on to the next section and ends on the completion page, and pages.csv has both pages.

Set STUDY_SCREENSHOTS=<folder> to save the break page at 1366x768 there (docs/img/study_break_page.png is made
this way).
"""
from __future__ import annotations

import csv
import io
import os
import time
from pathlib import Path

import pytest
from browser_flow import PAGE_TIMEOUT_S, answer_page, click, consent_and_demographics, path_of, wait
from django.urls import reverse

from studyapp.data.export import stream_csv
from studyapp.models import Participant, Section, Study
from studyapp.testing import make_catalogue, tiny_mp4, wait_for
from tests.studyapp.participant.test_e2e_browsers import BROWSERS

ENABLED = "var b = document.getElementById('next'); return b && !b.disabled"
HELD_BACK = """
    var n = document.getElementById('page-wait'), left = Number(n.dataset.waitLeft);
    return {waitLeft: left, leftNow: left - performance.now() / 1000,
            disabled: document.getElementById('continue').disabled, note: n.textContent};"""
"""The break page's state: the wait the server wrote (seconds), what is left of it now (from the page's own
navigation start), Continue's state and the countdown's text."""

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]

WAIT_S = 6


@pytest.mark.parametrize("browser", BROWSERS)
def test_break_and_instruction_pages(browser, request, live_server, settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    video = tiny_mp4(tmp_path / "clip.mp4", seconds=1.0, size=160)
    make_catalogue(settings.MEDIA_ROOT, video_bytes=video.read_bytes(), duration_s=1.0)
    study = Study.objects.create(slug="paged", title="Perception of walking styles", status=Study.Status.OPEN)
    Section.objects.create(study=study, order=1, section_type="emotion_choice", clips_per_participant=1,
                           pool={"modality": "gait", "origin": "generated", "transition": False},
                           require_full_play=False)
    Section.objects.create(study=study, order=2, section_type="break_page", options={"wait_seconds": WAIT_S},
                           instructions="You have finished the first part. Take a short rest before the next "
                                        "part: look away from the screen, stretch, relax.")
    Section.objects.create(study=study, order=3, section_type="instruction_page", title="The last part",
                           instructions="Now rate how each walk looks.")
    Section.objects.create(study=study, order=4, section_type="affect_likert", clips_per_participant=1,
                           pool={"modality": "gait", "origin": "generated", "transition": False},
                           require_full_play=False)
    driver = request.getfixturevalue(browser)
    driver.get(live_server.url + reverse("studyapp:study_entry", args=[study.slug]) + "?PROLIFIC_PID=e2e-pages")
    consent_and_demographics(driver)
    participant = Participant.objects.get(external_id="e2e-pages")
    wait(driver, ENABLED, what="answers enabled")
    answer_page(driver)
    wait(driver, "return location.pathname.indexOf('/page/1/') >= 0", what="the break page")
    # page.js runs under the CSP: it holds Continue back and counts down while the wait the server wrote lasts
    # (a slow browser may reach this line after the wait; then only the server's count is checked)
    state = driver.execute_script(HELD_BACK)
    assert state["waitLeft"] > 0, state
    if state["leftNow"] > 0.5:
        assert state["disabled"] and "You can continue in" in state["note"], state
    if os.environ.get("STUDY_SCREENSHOTS") and browser == "chromium":
        driver.set_window_size(1366, 768)
        chrome = driver.execute_script("return [window.outerWidth - window.innerWidth, "
                                       "window.outerHeight - window.innerHeight]")
        driver.set_window_size(1366 + chrome[0], 768 + chrome[1])        # a 1366x768 viewport
        time.sleep(0.3)
        driver.save_screenshot(str(Path(os.environ["STUDY_SCREENSHOTS"]) / "study_break_page.png"))
    wait(driver, "return !document.getElementById('continue').disabled", timeout=WAIT_S + 10,
         what="Continue enabled")
    assert driver.execute_script("return document.getElementById('page-wait').textContent.trim()") == \
        "You can continue now."
    click(driver, "#continue")
    wait(driver, "return location.pathname.indexOf('/page/2/') >= 0", what="the instruction page")
    driver.refresh()
    wait(driver, "var h = document.querySelector('h1.page-title'); return h && h.textContent.trim() === arguments[0]",
         PAGE_TIMEOUT_S, "the same instruction page after a reload", "The last part")
    assert "/page/2/" in path_of(driver)
    assert not driver.execute_script("return document.getElementById('continue').disabled")
    click(driver, "#continue")
    wait(driver, "return location.pathname.indexOf('/clip/2/') >= 0", what="the clip after the pages")
    wait(driver, ENABLED, what="answers enabled")
    answer_page(driver)
    wait(driver, "return location.pathname.indexOf('/done/') >= 0", what="the completion page")
    participant.refresh_from_db()
    assert participant.status == Participant.Status.COMPLETED
    rows = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "pages")))))
    assert [r["section_type"] for r in rows] == ["break_page", "instruction_page"]
    assert float(rows[0]["seconds"]) >= WAIT_S and all(r["continued_at"] for r in rows)


def test_a_researcher_adds_a_break_page_in_the_admin_in_chromium(chromium, live_server, settings, tmp_path):
    """The study's admin page: a new section of type break_page shows its wait field and hides the clip pool and
    the practice and check fields (static/studyapp/admin_pool.js); saved, it is a break page with that wait."""
    from django.contrib.auth.models import User
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = Study.objects.create(slug="paged-admin", title="Paged study")
    Section.objects.create(study=study, order=1, section_type="emotion_choice", clips_per_participant=2,
                           pool={"modality": "gait"})
    User.objects.create_superuser("researcher", "r@example.org", "pages-pw-12345")
    driver = chromium
    driver.get(live_server.url + "/admin/login/")
    driver.find_element(By.ID, "id_username").send_keys("researcher")
    driver.find_element(By.ID, "id_password").send_keys("pages-pw-12345")
    driver.find_element(By.CSS_SELECTOR, "input[type=submit]").click()
    wait_for(driver, lambda d: "/admin/login/" not in d.current_url, what="admin login")
    driver.get(live_server.url + reverse("admin:studyapp_study_change", args=[study.pk]))
    driver.execute_script("document.querySelector('#sections-group .add-row a').click()")
    row = wait_for(driver, lambda d: d.find_element(By.ID, "sections-1"), what="a new section form")
    Select(row.find_element(By.NAME, "sections-1-section_type")).select_by_value("break_page")
    driver.execute_script("arguments[0].dispatchEvent(new Event('change', {bubbles: true}))",
                          row.find_element(By.NAME, "sections-1-section_type"))
    wait_for(driver, lambda d: d.find_element(By.NAME, "sections-1-opt_wait_seconds").is_displayed(),
             what="the break's wait field")
    assert not row.find_element(By.NAME, "sections-1-pool_plan").is_displayed()
    assert not row.find_element(By.NAME, "sections-1-opt_practice").is_displayed()
    row.find_element(By.NAME, "sections-1-order").clear()
    row.find_element(By.NAME, "sections-1-order").send_keys("2")
    row.find_element(By.NAME, "sections-1-title").send_keys("Rest a moment")
    row.find_element(By.NAME, "sections-1-opt_wait_seconds").send_keys("20")
    driver.find_element(By.CSS_SELECTOR, "input[name=_continue]").click()
    wait_for(driver, lambda d: Section.objects.filter(study=study, order=2).exists(), what="the saved page")
    page = Section.objects.get(study=study, order=2)
    assert (page.section_type, page.title, page.options, page.pool) == ("break_page", "Rest a moment",
                                                                        {"wait_seconds": 20}, {})
