"""A participant taking a study in a real browser, from the consent page to the last page, written against the
small part of the WebDriver API that Selenium's Chromium and WebKitGTK drivers and the Marionette adapter
(tests/conftest.py) share: get, current_url, refresh, execute_script. Every click and every read goes through a
script, so the three browsers are driven the same way.

The test's database tells the flow which section each page belongs to and what an attention check instructs (the
page itself does not show either to a script, studyapp.participant.page_notes); everything else is read from the page.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

from studyapp.models import Participant, Study
from studyapp.participant.assignment import current_step

PAGE_TIMEOUT_S = 30.0


def wait(driver, script: str, timeout: float = PAGE_TIMEOUT_S, what: str = "the page", *args):
    """Run ``script`` (a function body returning a value) until it returns something truthy; that value."""
    end = time.time() + timeout
    last = None
    while time.time() < end:
        try:
            value = driver.execute_script(script, *args)
            if value:
                return value
        except Exception as exc:      # the page is changing under the script
            last = exc
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what} at {driver.current_url} ({last})")


def path_of(driver) -> str:
    return driver.execute_script("return window.location.pathname")


def click(driver, selector: str) -> None:
    driver.execute_script("document.querySelector(arguments[0]).click()", selector)


def consent_and_demographics(driver) -> None:
    wait(driver, "return document.getElementById('id_consent')", what="the consent page")
    click(driver, "#id_consent")
    wait(driver, "var b = document.getElementById('start-study'); return b && !b.disabled", what="start enabled")
    click(driver, "#start-study")
    wait(driver, "return location.pathname.indexOf('/about-you/') >= 0", what="the demographics page")
    driver.execute_script("""
        ['gender', 'age_group'].forEach(function (n) { document.querySelector('input[name=' + n + ']').click(); });
        document.querySelector('button[type=submit]').click();""")
    wait(driver, "return location.pathname.indexOf('/clip/1/') >= 0", what="the first clip page")


PLAYED = """
    var v = document.getElementById('clip'), b = document.getElementById('next');
    if (!v || !b || b.disabled || !v.currentSrc || v.readyState < 2) { return null; }
    return {src: v.currentSrc, width: v.videoWidth, height: v.videoHeight, time: v.currentTime,
            ended: v.ended, played: v.played.length};"""
"""The clip page once its answers are enabled (the clip has played) and the video has a frame: the rendition the
player chose (its URL ends in .mp4 or .webm) and its frame size."""


@dataclass
class Page:
    n: int
    section_type: str
    kind: str
    rendition: str           # "mp4" or "webm": what the player played
    frame: tuple[int, int]


@dataclass
class Run:
    pages: list[Page] = field(default_factory=list)
    reloaded_at: int = 0

    @property
    def renditions(self) -> set[str]:
        return {p.rendition for p in self.pages}


def answer_page(driver, instructed: str = "") -> None:
    """Choose the first answer of every question (on an attention check, the instructed one), then continue."""
    driver.execute_script("""
        var key = arguments[0], value = arguments[1];
        document.querySelectorAll('#answer-form fieldset.question').forEach(function (f) {
          var inputs = f.querySelectorAll('input'), target = inputs[0];
          if (f.dataset.key === key) {
            inputs.forEach(function (i) { if (i.value === value) { target = i; } });
          }
          if (!target.checked) { target.click(); }
        });
        document.getElementById('next').click();""", *instructed.split("=", 1) if instructed else ("", ""))


def take_study(driver, base_url: str, study: Study, external_id: str, reload_at: int = 3, on_page=None) -> Run:
    """Take ``study`` as participant ``external_id`` (a Prolific PID in the link) from consent to the last page,
    reloading clip page ``reload_at`` once before answering it; ``on_page(driver, page)`` is called on every
    clip page once its clip has played. Returns what each page showed and played."""
    from django.urls import reverse

    driver.get(base_url + reverse("studyapp:study_entry", args=[study.slug]) + f"?PROLIFIC_PID={external_id}")
    consent_and_demographics(driver)
    participant = Participant.objects.get(study=study, external_id=external_id)
    run = Run()
    while "/clip/" in path_of(driver):
        step = current_step(Participant.objects.get(pk=participant.pk))
        assert step.kind == "item" and f"/clip/{step.index}/" in path_of(driver), (step.kind, path_of(driver))
        if step.index == reload_at and not run.reloaded_at:
            wait(driver, PLAYED, what=f"clip {step.index} played")
            driver.execute_script("window.beforeReload = true")
            driver.refresh()                          # the participant reloads in the middle of the study
            run.reloaded_at = step.index
            wait(driver, "return !window.beforeReload && document.readyState === 'complete'",
                 what="the reloaded page")
            assert f"/clip/{step.index}/" in path_of(driver), f"a reload must resume on the same clip page, not " \
                                                              f"{path_of(driver)}"
        played = wait(driver, PLAYED, what=f"clip {step.index} played")
        rendition = played["src"].rsplit(".", 1)[-1].split("?")[0]
        a = step.assignment
        page = Page(step.index, a.section.section_type, a.kind, rendition, (played["width"], played["height"]))
        run.pages.append(page)
        if on_page is not None:
            on_page(driver, page)
        before = path_of(driver)
        answer_page(driver, a.instructed if a.kind == "attention_check" else "")
        wait(driver, "return location.pathname !== arguments[0] && document.readyState === 'complete'",
             PAGE_TIMEOUT_S, f"the page after clip {step.index}", before)
    if "/feedback/" in path_of(driver):
        driver.execute_script("""
            document.querySelectorAll('input[type=radio]').forEach(function (r) {
              if (!document.querySelector('input[name="' + r.name + '"]:checked')) { r.click(); } });
            document.querySelector('button[type=submit]').click();""")
        wait(driver, "return location.pathname.indexOf('/done/') >= 0", what="the last page")
    assert "/done/" in path_of(driver), path_of(driver)
    return run
