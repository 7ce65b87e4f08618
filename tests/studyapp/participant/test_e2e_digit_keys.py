"""Every number key on every scale of every section type, in real headless Chromium, down to the stored answer.

On each clip page of the demo study, every question gets every digit 0-9 (and, on a scale with negative values,
the minus key before each digit): on a numbered scale the key must choose the option that shows that number (or
nothing, when no option shows it), on any other question the n-th option. The last key pressed on each question is
then saved and the stored answer read back from the database. The clips are SYNTHETIC test patterns.
"""
from __future__ import annotations

import re

import pytest
from django.urls import reverse

from studyapp.models import Participant, Response, Study
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue, wait_for
from tests.studyapp.participant.test_e2e_keyboard_a11y import CLIP_SECONDS, press, wide_test_clip

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]

NUMBER = re.compile(r"^-?[0-9]+$")


@pytest.fixture
def demo_study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    clip = wide_test_clip(tmp_path / "wide.mp4").read_bytes()
    make_catalogue(settings.MEDIA_ROOT, video_bytes=clip, duration_s=CLIP_SECONDS, gesture_video_bytes=clip)
    return create_study_from_preset("demo", "digits", plan="test", status=Study.Status.OPEN)


def question_state(driver, key: str) -> tuple[list[str], list[str], str]:
    """(option values in page order, checked values, input type) of the question named ``key``."""
    inputs = driver.find_elements("css selector", f"#answer-form input[name='{key}']")
    values = [i.get_attribute("value") for i in inputs]
    checked = [i.get_attribute("value") for i in inputs if i.is_selected()]
    return values, checked, inputs[0].get_attribute("type")


def expected_after(values: list[str], checked: list[str], kind: str, digit: int, negative: bool) -> list[str]:
    """What a key must leave checked: the option showing the number on a numbered scale, else the n-th option."""
    if all(NUMBER.match(v) for v in values):
        want = str(-digit if negative else digit)
        target = next((v for v in values if int(v) == int(want)), None)
    else:
        target = values[digit - 1] if not negative and 1 <= digit <= len(values) else None
    if target is None:
        return checked
    if kind == "checkbox":
        return [v for v in values if (v in checked) != (v == target)]
    return [target]


def sweep_question(driver, key: str) -> str:
    """Press every digit (and minus + digit where the scale has negatives) on question ``key``; returns the value the
    last key left checked (joined by ';' for a multi-select)."""
    first = driver.find_element("css selector", f"#answer-form input[name='{key}']")
    values, _, _ = question_state(driver, key)
    signs = (False, True) if any(v.startswith("-") for v in values) else (False,)
    for negative in signs:
        for digit in range(10):
            driver.execute_script("arguments[0].focus()", first)
            _, before, kind = question_state(driver, key)
            press(driver, *(["-", str(digit)] if negative else [str(digit)]))
            _, after, _ = question_state(driver, key)
            want = expected_after(values, before, kind, digit, negative)
            assert after == want, (f"question {key} {values}: key {'-' if negative else ''}{digit} left {after}, "
                                   f"the page shows {want}")
    # end on a definite answer: the highest number shown (or the 2nd option), the minus key on a negative scale
    driver.execute_script("arguments[0].focus()", first)
    _, before, kind = question_state(driver, key)
    if signs == (False, True):
        press(driver, "-", "3")
    else:
        digits = [int(v) for v in values if NUMBER.match(v) and 0 <= int(v) <= 9]
        press(driver, str(max(digits)) if len(digits) == len(values) else "2")
    _, after, _ = question_state(driver, key)
    assert after, f"question {key}: the final key chose nothing"
    return ";".join(after)


def test_every_digit_on_every_scale_records_the_number_shown(chromium, live_server, demo_study):
    from selenium.webdriver.common.keys import Keys

    driver = chromium
    driver.get(live_server.url + reverse("studyapp:study_entry", args=[demo_study.slug]) + "?PROLIFIC_PID=digits-1")
    driver.find_element("id", "id_consent").click()
    driver.find_element("css selector", "form button[type=submit]").click()
    wait_for(driver, lambda d: "/about-you/" in d.current_url, what="demographics page")
    press(driver, "2", "3", Keys.ENTER)
    wait_for(driver, lambda d: "/clip/1/" in d.current_url, what="first clip")
    participant = Participant.objects.get(external_id="digits-1")
    items = list(participant.assignments.select_related("section").order_by("seq"))
    expected: dict[tuple[str, str], str] = {}
    swept_kinds = set()
    for n, item in enumerate(items, start=1):
        page = f"/clip/{n}/"
        wait_for(driver, lambda d, page=page: page in d.current_url, what=f"clip {n}")
        wait_for(driver, lambda d: d.find_element("id", "next").is_enabled(), timeout=10 + 3 * CLIP_SECONDS,
                 what="clip played")
        keys = [q.get_attribute("data-key") for q in
                driver.find_elements("css selector", "#answer-form fieldset.question")]
        for key in keys:
            answer = sweep_question(driver, key)
            values, _, _ = question_state(driver, key)
            swept_kinds.add(tuple(values))
            if item.kind == "":
                expected[(item.clip_id, item.section.section_type, key)] = answer
        if item.instructed:          # an attention check: answer as instructed, then it is not a trial answer
            question, answer = item.instructed.split("=", 1)
            for box in driver.find_elements("css selector", f"#answer-form input[name='{question}']"):
                if box.is_selected() != (box.get_attribute("value") == answer):
                    driver.execute_script("arguments[0].click()", box)
        press(driver, Keys.ENTER)
        wait_for(driver, lambda d, page=page: page not in d.current_url, what=f"leave clip {n}")
    assert ("-7", "-6", "-5", "-4", "-3", "-2", "-1", "0", "1", "2", "3", "4", "5", "6", "7") in swept_kinds
    assert ("0", "1", "2", "3", "4") in swept_kinds
    stored = {(r.clip_id, r.section.section_type, r.question): r.answer
              for r in Response.objects.filter(participant=participant).select_related("section")}
    assert expected and {k: stored.get(k) for k in expected} == expected
