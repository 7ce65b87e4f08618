"""In headless Chromium: the replay-only player undoes a seek (script and keyboard), counts a pause, a hidden tab
and a replay, stops replays at max_replays, and viewing.csv records exactly that; a reload during play keeps the
plays (max_replays holds across reloads) and a pause the browser makes for a hidden tab is hidden time; the
consent page's device check stops a too-small window and a browser that cannot play the clips before the study
starts.
STUDY_SCREENSHOTS=<folder> saves docs/img/study_player_replay_only.png (desktop) and
study_player_replay_only_360.png (360 px wide) there."""
from __future__ import annotations

import csv
import io
import os
import time
from pathlib import Path

import pytest
from django.urls import reverse

from protocol.vocabulary import VIEWING_COLUMNS
from studyapp.data.export import stream_csv
from studyapp.models import Participant, Study
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import consent_and_demographics, make_catalogue, tiny_mp4, wait_for

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]

CLIP_S = 3.0


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    video = tiny_mp4(tmp_path / "clip.mp4", seconds=CLIP_S, size=160)
    make_catalogue(settings.MEDIA_ROOT, video_bytes=video.read_bytes(), duration_s=CLIP_S)
    s = create_study_from_preset("gait_ismar2020", "player", plan="test", status=Study.Status.OPEN)
    section = s.sections.get(order=1)
    section.options = {"controls": "replay-only", "max_replays": 1}
    section.save()
    return s


def js(driver, script: str, *args):
    return driver.execute_script(script, *args)


def player_state(driver) -> dict:
    return js(driver, "var v = document.getElementById('clip'); return {t: v.currentTime, paused: v.paused, "
                      "ended: v.ended, rate: v.playbackRate};")


def viewport(driver, width: int, height: int) -> None:
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": width < 500})


def shot(driver, folder: str | None, name: str, width: int) -> None:
    """A full-page screenshot at ``width`` CSS pixels (the page's own height), then the desktop viewport again."""
    if not folder:
        return
    viewport(driver, width, 800)
    height = int(js(driver, "return document.documentElement.scrollHeight"))
    viewport(driver, width, min(height, 2400))
    time.sleep(0.4)
    driver.save_screenshot(str(Path(folder) / name))
    driver.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})


def set_hidden(driver, hidden: bool) -> None:
    """The page as another tab would make it: document.hidden / visibilityState, then a visibilitychange event."""
    js(driver, "var h = arguments[0];"
               "Object.defineProperty(document, 'hidden', {configurable: true, get: function () { return h; }});"
               "Object.defineProperty(document, 'visibilityState', {configurable: true,"
               " get: function () { return h ? 'hidden' : 'visible'; }});"
               "document.dispatchEvent(new Event('visibilitychange'));", hidden)


def test_replay_only_player_and_viewing_csv(chromium, live_server, study):
    from selenium.webdriver.common.by import By

    driver = chromium
    shots = os.environ.get("STUDY_SCREENSHOTS")
    driver.get(live_server.url + reverse("studyapp:study_entry", args=[study.slug]) + "?PROLIFIC_PID=v-1")
    consent_and_demographics(driver)
    video = driver.find_element(By.ID, "clip")
    assert video.get_attribute("controls") is None                      # no seek bar, no speed menu
    play_pause, replay = driver.find_element(By.ID, "play-pause"), driver.find_element(By.ID, "replay")
    assert play_pause.is_displayed() and replay.is_displayed()
    assert not driver.find_element(By.ID, "next").is_enabled()
    wait_for(driver, lambda d: player_state(d)["t"] > 0.3, what="clip playing")

    # A seek (the seek bar of picture-in-picture or a script would do this) is undone; so is a speed change.
    before = player_state(driver)["t"]
    js(driver, "document.getElementById('clip').currentTime = arguments[0];", CLIP_S - 0.2)
    wait_for(driver, lambda d: not js(d, "return document.getElementById('clip').seeking;"), what="seek undone")
    assert player_state(driver)["t"] < before + 1.0
    assert "not possible" in driver.find_element(By.ID, "play-note").text
    js(driver, "var v = document.getElementById('clip'); v.focus();"
               "v.dispatchEvent(new KeyboardEvent('keydown', {key: 'ArrowRight', bubbles: true, cancelable: true}));")
    js(driver, "document.getElementById('clip').playbackRate = 4;")
    assert player_state(driver)["rate"] == 1

    # The tab is hidden while the clip plays, then shown again.
    assert not player_state(driver)["paused"]
    set_hidden(driver, True)
    set_hidden(driver, False)

    # A pause with the player's button, then play on.
    play_pause.click()
    wait_for(driver, lambda d: player_state(d)["paused"], what="paused")
    assert play_pause.text == "Play"
    play_pause.click()
    wait_for(driver, lambda d: not player_state(d)["paused"], what="playing again")

    wait_for(driver, lambda d: d.find_element(By.ID, "next").is_enabled(), timeout=20, what="clip ended")
    assert player_state(driver)["ended"]
    shot(driver, shots, "study_player_replay_only.png", 1000)
    shot(driver, shots, "study_player_replay_only_360.png", 360)

    # One replay is allowed (max_replays 1), then the button is disabled.
    replay.click()
    wait_for(driver, lambda d: not player_state(d)["ended"] and player_state(d)["t"] > 0.2, what="replaying")
    assert not replay.is_enabled()
    wait_for(driver, lambda d: player_state(d)["ended"], timeout=20, what="replay ended")
    assert "used all replays" in driver.find_element(By.ID, "play-note").text
    play_pause.click()                                                   # a replay by the play button: refused
    time.sleep(0.5)
    assert player_state(driver)["ended"] or player_state(driver)["paused"]

    driver.find_element(By.CSS_SELECTOR, "#answer-form input[value='sad']").find_element(By.XPATH, "..").click()
    driver.find_element(By.ID, "next").click()
    wait_for(driver, lambda d: "/clip/2/" in d.current_url, what="clip 2")

    p = Participant.objects.get(external_id="v-1")
    rows = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "viewing")))))
    assert tuple(rows[0]) == VIEWING_COLUMNS
    assert len(rows) == 1
    row = rows[0]
    assert row["participant_id"] == p.public_id and row["section_type"] == "emotion_choice"
    assert row["clip_id"] == p.assignments.get(seq=1).clip.clip_id
    assert (row["plays"], row["pauses"], row["hidden"]) == ("2", "1", "1"), row
    assert int(row["seeks"]) == 2, row                                   # the script seek and the arrow key
    first, ended = int(row["first_play_ms"]), int(row["ended_ms"])
    assert 0 <= first < ended, row
    assert ended >= CLIP_S * 1000 * 0.9, row                            # the pause made it longer, never shorter
    assert row["stalls"] != "" and row["stall_ms"] != ""


def test_device_check_stops_small_windows_and_unplayable_browsers(chromium, live_server, study):
    from selenium.webdriver.common.by import By

    driver = chromium
    url = live_server.url + reverse("studyapp:study_entry", args=[study.slug])
    driver.get(url)
    box = driver.find_element(By.ID, "device-check")
    assert not box.is_displayed() and driver.find_element(By.ID, "start-study").is_enabled()

    viewport(driver, 280, 500)
    wait_for(driver, lambda d: d.find_element(By.ID, "device-check").is_displayed(), what="too-small message")
    assert "too small" in box.text and "320 × 300" in box.text and "280 × 500" in box.text
    assert not driver.find_element(By.ID, "start-study").is_enabled()
    viewport(driver, 360, 640)                                           # a phone: fine
    wait_for(driver, lambda d: not d.find_element(By.ID, "device-check").is_displayed(), what="message gone")
    assert driver.find_element(By.ID, "start-study").is_enabled()
    driver.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})

    # A browser without the clips' codecs.
    driver.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument",
                           {"source": "HTMLMediaElement.prototype.canPlayType = function () { return ''; };"})
    driver.get(url)
    box = driver.find_element(By.ID, "device-check")
    assert box.is_displayed() and "cannot play" in box.text
    assert not driver.find_element(By.ID, "start-study").is_enabled()


def test_a_reload_during_play_keeps_the_plays_and_a_hidden_tab_is_no_pause(chromium, live_server, study):
    """max_replays 1. Clip 1: it plays, is paused and played on, the page is reloaded mid-play (the reload's
    autoplay is the one replay left), the tab is hidden and the browser pauses the clip, it goes on when shown
    again, it ends: 2 plays, the one pause from before the reload, the hidden time (not a pause), 2 displays.
    Clip 2: played and replayed to its end, then reloaded: it stays stopped with the answers enabled."""
    from selenium.webdriver.common.by import By

    driver = chromium
    driver.get(live_server.url + reverse("studyapp:study_entry", args=[study.slug]) + "?PROLIFIC_PID=v-2")
    consent_and_demographics(driver)
    wait_for(driver, lambda d: player_state(d)["t"] > 0.3, what="clip playing")
    p = Participant.objects.get(external_id="v-2")
    wait_for(driver, lambda d: p.assignments.get(seq=1).plays == 1, what="the play reported to the server")
    play_pause = driver.find_element(By.ID, "play-pause")
    play_pause.click()                                                   # the participant's pause, before the reload
    wait_for(driver, lambda d: player_state(d)["paused"], what="paused")
    play_pause.click()
    wait_for(driver, lambda d: not player_state(d)["paused"], what="playing again")

    driver.refresh()                                                     # mid-play
    assert driver.find_element(By.ID, "clip").get_attribute("data-plays-before") == "1"
    wait_for(driver, lambda d: p.assignments.get(seq=1).carried.get("pauses") == 1, what="the pause handed on")
    wait_for(driver, lambda d: player_state(d)["t"] > 0.3, what="replaying after the reload")
    wait_for(driver, lambda d: p.assignments.get(seq=1).plays == 2, what="the replay reported")

    # Hidden: Chromium pauses a background video by itself; that is hidden time, not the participant's pause.
    set_hidden(driver, True)
    js(driver, "document.getElementById('clip').pause();")
    time.sleep(0.6)
    set_hidden(driver, False)
    wait_for(driver, lambda d: not player_state(d)["paused"], what="playing on once shown again")

    wait_for(driver, lambda d: d.find_element(By.ID, "next").is_enabled(), timeout=20, what="clip ended")
    assert not driver.find_element(By.ID, "replay").is_enabled()        # the one replay went on the reload
    assert "used all replays" in driver.find_element(By.ID, "play-note").text

    def answer(n_next: int) -> None:
        driver.find_element(By.CSS_SELECTOR, "#answer-form input[value='sad']").find_element(By.XPATH, "..").click()
        driver.find_element(By.ID, "next").click()
        wait_for(driver, lambda d: f"/clip/{n_next}/" in d.current_url, what=f"clip {n_next}")

    answer(2)
    row = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "viewing")))))[0]
    assert row["record"] == "ok" and row["shows"] == "2", row
    assert (row["plays"], row["pauses"], row["hidden"]) == ("2", "1", "1"), row     # the pause before the reload
    assert int(row["hidden_ms"]) >= 500, row
    assert int(row["ended_ms"]) > int(row["first_play_ms"]), row
    assert int(row["page_ms"]) >= CLIP_S * 1000, row

    # Clip 2: to its end, the one replay to its end, then a reload: nothing left to play.
    wait_for(driver, lambda d: d.find_element(By.ID, "next").is_enabled(), timeout=20, what="clip 2 ended")
    driver.find_element(By.ID, "replay").click()
    wait_for(driver, lambda d: not player_state(d)["ended"] and player_state(d)["t"] > 0.2, what="replaying")
    wait_for(driver, lambda d: player_state(d)["ended"], timeout=20, what="replay ended")
    wait_for(driver, lambda d: p.assignments.get(seq=2).plays == 2, what="both plays reported")
    driver.refresh()
    video = driver.find_element(By.ID, "clip")
    assert video.get_attribute("autoplay") is None and video.get_attribute("data-ended-before") == "1"
    time.sleep(1.0)
    state = player_state(driver)
    assert state["paused"] and state["t"] < 0.1, state
    assert driver.find_element(By.ID, "next").is_enabled()              # watched to its end before the reload
    assert not driver.find_element(By.ID, "replay").is_enabled()
    driver.find_element(By.ID, "play-pause").click()                     # the play button cannot start it either
    time.sleep(0.5)
    assert player_state(driver)["paused"]
    answer(3)
    row = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "viewing")))))[1]
    assert (row["plays"], row["ended_ms"], row["shows"], row["record"]) == ("2", "0", "2", "ok"), row


def test_a_reload_mid_play_without_replays_leaves_the_answers_open(chromium, live_server, study):
    """max_replays 0 and a reload before the clip ended: it may not play again, and the participant is not stuck
    (the answers are enabled; the record shows no end)."""
    from selenium.webdriver.common.by import By

    section = study.sections.get(order=1)
    section.options = {"controls": "replay-only", "max_replays": 0}
    section.save()
    driver = chromium
    driver.get(live_server.url + reverse("studyapp:study_entry", args=[study.slug]) + "?PROLIFIC_PID=v-3")
    consent_and_demographics(driver)
    p = Participant.objects.get(external_id="v-3")
    wait_for(driver, lambda d: p.assignments.get(seq=1).plays == 1, what="the play reported")
    assert not driver.find_element(By.ID, "next").is_enabled()
    driver.refresh()
    time.sleep(1.0)
    state = player_state(driver)
    assert state["paused"] and state["t"] < 0.1, state
    assert driver.find_element(By.ID, "next").is_enabled()
    assert "used all replays" in driver.find_element(By.ID, "play-note").text
    time.sleep(CLIP_S)                  # the server still wants the clip's time to pass (require_full_play)
    driver.find_element(By.CSS_SELECTOR, "#answer-form input[value='sad']").find_element(By.XPATH, "..").click()
    driver.find_element(By.ID, "next").click()
    wait_for(driver, lambda d: "/clip/2/" in d.current_url, what="clip 2")
    row = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "viewing")))))[0]
    assert (row["plays"], row["ended_ms"], row["shows"], row["record"]) == ("1", "", "2", "ok"), row
