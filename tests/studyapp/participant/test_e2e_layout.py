"""The clip page keeps the clip in view, in headless Chromium: on a 1366x768 laptop (and 1920x1080) the video and
each question of the page are inside the window together on every section type; on a 390x844 phone the player is
as wide as the screen. LAYOUT_SCREENSHOTS=<folder> saves what each size shows of the first page of every section
type (docs/img/study_layout_<section type>_<width>x<height>.png; the clips are SYNTHETIC test patterns)."""
from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
from browser_flow import take_study, wait
from django.urls import reverse

from protocol.vocabulary import SECTION_TYPES
from studyapp.models import Participant, Study
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue, wide_clip

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]

LAPTOP, DESKTOP, PHONE = (1366, 768), (1920, 1080), (390, 844)


def emulate(driver, size, mobile: bool) -> None:
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {
        "width": size[0], "height": size[1], "deviceScaleFactor": 1, "mobile": mobile})
    driver.execute_cdp_cmd("Emulation.setTouchEmulationEnabled", {"enabled": mobile, "maxTouchPoints": 5})
    time.sleep(0.25)


IN_VIEW = """
    var key = arguments[0], vh = window.innerHeight, vw = window.innerWidth;
    var f = document.querySelector('#answer-form fieldset.question[data-key="' + key + '"]');
    f.scrollIntoView({block: 'nearest'});
    function box(e) { var r = e.getBoundingClientRect();
      return {top: r.top, bottom: r.bottom, left: r.left, right: r.right, inside:
              r.top >= -0.5 && r.left >= -0.5 && r.bottom <= vh + 0.5 && r.right <= vw + 0.5}; }
    return {video: box(document.getElementById('clip')), question: box(f), viewport: [vw, vh]};"""


def question_keys(driver) -> list[str]:
    return driver.execute_script("return Array.from(document.querySelectorAll('#answer-form fieldset.question'))"
                                 ".map(function (f) { return f.dataset.key; })")


@pytest.fixture
def demo(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    video = wide_clip(tmp_path / "clip.mp4", seconds=1.0)
    make_catalogue(settings.MEDIA_ROOT, video_bytes=video.read_bytes(), duration_s=1.0)
    return create_study_from_preset("demo", "layout", plan="test", status=Study.Status.OPEN)


def test_clip_and_current_question_in_view_on_every_section_type(chromium, live_server, demo):
    shots = os.environ.get("LAYOUT_SCREENSHOTS")
    checked: dict[str, dict] = {}

    def on_page(driver, page):
        if page.section_type in checked:
            return
        seen = {}
        for size in (LAPTOP, DESKTOP):
            emulate(driver, size, mobile=False)
            for key in question_keys(driver):
                where = driver.execute_script(IN_VIEW, key)
                assert where["video"]["inside"] and where["question"]["inside"], (page.section_type, size, key,
                                                                                 where)
                seen[(size, key)] = where
            driver.execute_script("window.scrollTo(0, 0)")
            if shots:
                driver.save_screenshot(str(Path(shots) / f"study_layout_{page.section_type}_{size[0]}x{size[1]}.png"))
        emulate(driver, PHONE, mobile=True)
        phone = driver.execute_script("""
            var r = document.getElementById('clip').getBoundingClientRect();
            return {width: r.width, height: r.height, inner: window.innerWidth,
                    scroll: document.documentElement.scrollWidth};""")
        assert phone["scroll"] <= phone["inner"] == PHONE[0], (page.section_type, phone)
        assert phone["width"] == PHONE[0] and abs(phone["width"] / phone["height"] - 16 / 9) < 0.02, phone
        driver.execute_script("window.scrollTo(0, 0)")
        if shots:
            driver.save_screenshot(str(Path(shots) / f"study_layout_{page.section_type}_{PHONE[0]}x{PHONE[1]}.png"))
        driver.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})
        driver.execute_cdp_cmd("Emulation.setTouchEmulationEnabled", {"enabled": False})
        checked[page.section_type] = seen

    take_study(chromium, live_server.url, demo, "layout-1", on_page=on_page)
    assert set(checked) == set(SECTION_TYPES)
    # the likert page's four questions each shared the laptop's window with the clip
    assert sum(1 for size, _ in checked["affect_likert"] if size == LAPTOP) == 4


def test_consent_page_turns_phones_away_when_the_study_admits_none(chromium, live_server, demo):
    """The consent page's script: a phone (touch screen, narrow) is told why and cannot start; a desktop window
    below the study's minimum is told its size; a large enough desktop starts, and its window is recorded."""
    Study.objects.filter(pk=demo.pk).update(admit_phones=False, min_viewport_width=1200, min_viewport_height=700)
    url = live_server.url + reverse("studyapp:study_entry", args=[demo.slug]) + "?PROLIFIC_PID=device-1"
    state = "var b = document.getElementById('device-check'); return [b.hidden, b.textContent, " \
            "document.getElementById('start-study').disabled]"
    emulate(chromium, PHONE, mobile=True)
    chromium.get(url)
    hidden, text, disabled = chromium.execute_script(state)
    assert not hidden and disabled and "cannot be taken on a phone" in text, text
    emulate(chromium, (1000, 700), mobile=False)
    hidden, text, disabled = chromium.execute_script(state)     # re-checked on resize
    assert "at least 1200 × 700" in text and "1000 × 700" in text and disabled, text
    emulate(chromium, LAPTOP, mobile=False)
    hidden, text, disabled = chromium.execute_script(state)
    assert hidden and not disabled, text
    chromium.execute_script("document.getElementById('id_consent').click(); "
                            "document.getElementById('start-study').click()")
    wait(chromium, "return location.pathname.indexOf('/about-you/') >= 0", what="the demographics page")
    p = Participant.objects.get(external_id="device-1")
    assert (p.viewport_width, p.viewport_height, p.device_kind) == (1366, 768, "desktop")
