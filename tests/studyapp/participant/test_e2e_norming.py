"""In headless Chromium: one norming session (practice, trials with the emotion, intensity and naturalness
questions, the attention check), then the staff pages: the norming monitor and the pool editor of a main study
drawing from norms (one clip out because of them, one in although the observer flagged it).
STUDY_SCREENSHOTS=<folder> saves norming_item.png, norming_monitor.png and admin_pool_norms.png there."""
from __future__ import annotations

import os
import re
import time
from pathlib import Path

import pandas as pd
import pytest
from django.contrib.auth.models import User
from django.urls import reverse

from protocol.vocabulary import ATTENTION_CHECK, CLIP_NORMS_COLUMNS, GAIT_EMOTIONS
from studyapp.models import Clip, Participant, Response, Study
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import consent_and_demographics, make_catalogue, tiny_mp4, wait_for

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]


def shot(driver, folder: str | None, name: str, element=None) -> None:
    if not folder:
        return
    if element is not None:
        driver.execute_script("arguments[0].scrollIntoView();", element)
        time.sleep(0.3)
        element.screenshot(str(Path(folder) / name))
        return
    driver.set_window_size(1100, 900)
    height = driver.execute_script("return document.documentElement.scrollHeight")
    driver.set_window_size(1100, min(int(height) + 140, 2400))
    time.sleep(0.3)
    driver.save_screenshot(str(Path(folder) / name))
    driver.set_window_size(1280, 900)


INSTRUCTION = re.compile(r"\u201c(?P<question>.+)\u201d with (?P<answer>.+) only\.")


def answer_page(driver, folder: str | None = None, name: str = "") -> None:
    """Wait until the clip has played, answer every question (the instructed answer on an attention check, else
    the first choice of each question), submit."""
    from selenium.webdriver.common.by import By

    wait_for(driver, lambda d: d.find_element(By.ID, "next").is_enabled(), timeout=15, what="clip played")
    # the note line: on an attention check it names a question ("...") and the answer to give it ("with X only")
    instructed = INSTRUCTION.search(driver.find_element(By.ID, "page-note").text)
    for fieldset in driver.find_elements(By.CSS_SELECTOR, "fieldset.question"):
        inputs = fieldset.find_elements(By.CSS_SELECTOR, "input")
        target = inputs[0]
        legend = fieldset.find_element(By.TAG_NAME, "legend").text.strip()
        if instructed and instructed["question"] == legend:      # the choice the instruction names
            target = next(i for i in inputs if instructed["answer"] in (
                i.get_attribute("value"), i.find_element(By.XPATH, "..").text.strip()))
        target.find_element(By.XPATH, "..").click()
    if name:
        shot(driver, folder, name)
    url = driver.current_url
    driver.find_element(By.ID, "next").click()
    wait_for(driver, lambda d: d.current_url != url, what="the next page")


def simulated_participant(study: Study, external_id: str) -> None:
    """A SIMULATED participant taking the whole study through the pages with the Django test client: the
    instructed answer on attention checks, else the first choice of every question."""
    from django.test import Client

    from studyapp.participant.assignment import current_step
    from studyapp.questions import questions_for

    client = Client()
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]) + f"?PROLIFIC_PID={external_id}",
                    {"consent": "on"})
    p = Participant.objects.get(token=r["Location"].rstrip("/").split("/")[-1])
    client.post(reverse("studyapp:demographics", args=[p.token]), {"gender": "male", "age_group": "18-24"})
    client.get(reverse("studyapp:resume", args=[p.token]))
    while (step := current_step(Participant.objects.get(pk=p.pk))).kind == "item":
        a = step.assignment
        data = {q.key: q.choices[0][0]
                for q in questions_for(a.section.section_type, a.section.options, a.clip.theme, a.options)}
        if a.kind == ATTENTION_CHECK:               # the section's questions, the instructed one as told
            key, _, value = a.instructed.partition("=")
            data[key] = value
        assert client.post(reverse("studyapp:item", args=[p.token, step.index]), data).status_code == 302
    client.post(reverse("studyapp:feedback", args=[p.token]), {"comments": ""})


def test_norming_session_and_staff_pages_in_chromium(chromium, live_server, settings, tmp_path):
    from selenium.webdriver.common.by import By

    settings.MEDIA_ROOT = tmp_path / "media"
    settings.DATA_DIR = tmp_path
    video = tiny_mp4(tmp_path / "clip.mp4", seconds=1.0, size=160)
    make_catalogue(settings.MEDIA_ROOT, video_bytes=video.read_bytes(), duration_s=1.0)
    study = create_study_from_preset("norming", "norming", plan="test", max_participants=48)
    for section, m in zip(study.sections.order_by("order"), (2, 1, 1)):
        section.clips_per_participant = m
        section.options = {**section.options, "norming": {"ratings_per_clip": 2}}
        section.save()
    Study.objects.filter(pk=study.pk).update(status=Study.Status.OPEN)
    shots = os.environ.get("STUDY_SCREENSHOTS")
    driver = chromium
    driver.get(live_server.url + reverse("studyapp:study_entry", args=[study.slug]) + "?PROLIFIC_PID=sim-browser")
    consent_and_demographics(driver)
    pages = 0
    while "/clip/" in driver.current_url:
        answer_page(driver, shots, "norming_item.png" if pages == 1 else "")
        pages += 1
    # practice + 2 walks + 1 attention check, 1 gesture + 1 attention check (every gesture is in the pool: no
    # practice clip left), practice + 1 theme clip + 1 attention check
    p = Participant.objects.get(external_id="sim-browser")
    assert pages == p.assignments.count() == 9
    trials = Response.objects.filter(participant=p, kind="")
    assert trials.count() == 4 * 3
    assert set(trials.values_list("question", flat=True)) == {"perceived", "rating", "intensity", "naturalness"}
    checks = Response.objects.filter(participant=p, kind=ATTENTION_CHECK)
    assert sorted(checks.values_list("answer", flat=True)) == ["1", "sad", "sad"]

    # eight more SIMULATED participants through the pages (test client), so the monitor shows a study under way
    study.sections.update(require_full_play=False)
    for i in range(8):
        simulated_participant(study, f"sim-{i}")

    User.objects.create_superuser("admin", "admin@example.org", "pw-for-tests")
    driver.get(live_server.url + "/admin/login/")
    driver.find_element(By.NAME, "username").send_keys("admin")
    driver.find_element(By.NAME, "password").send_keys("pw-for-tests")
    driver.find_element(By.CSS_SELECTOR, "input[type=submit]").click()
    wait_for(driver, lambda d: "/admin/login/" not in d.current_url, what="admin login")
    driver.get(live_server.url + reverse("studyapp:norming_monitor", args=[study.pk]))
    text = driver.find_element(By.ID, "content").text
    assert "Ratings so far: 18; clips below K: 10 of 14." in text
    shot(driver, shots, "norming_monitor.png")

    # the main study: walks whose pilot norms pass
    rows = []
    for clip_id, intended, share in (("gait_gen_00", "happy", 0.85), ("gait_gen_01", "sad", 0.35),
                                     ("gait_gen_02", "angry", 0.7), ("gait_gen_03", "neutral", 0.75)):
        rest = (1 - share) / 3
        rows.append({"clip_id": clip_id, "modality": "gait", "section_type": "emotion_choice",
                     "question": "perceived", "n_ratings": 20, "intended": intended, "top_label": intended,
                     "top_share": share, "intended_share": share, "intended_ci_low": share - 0.2,
                     "intended_ci_high": min(1.0, share + 0.15), "entropy_bits": 1.1, "ad_statistic": "",
                     "ad_p_value": "", "intensity_mean": 3.2, "naturalness_mean": 3.9, "naturalness_n": 20,
                     **{f"share_{e}": share if e == intended else rest for e in GAIT_EMOTIONS}})
    pd.DataFrame(rows)[[*CLIP_NORMS_COLUMNS, *[f"share_{e}" for e in GAIT_EMOTIONS]]].to_csv(
        tmp_path / "pilot_norms.csv", index=False)
    Clip.objects.filter(clip_id="gait_gen_03").update(qa_flag="observer", qa={"observed": "happy",
                                                                              "observed_p": 0.46})
    main = create_study_from_preset("gait_ismar2020", "main", plan="test")
    main.sections.filter(order=1).update(pool={"modality": "gait", "origin": "generated", "transition": False,
                                               "rbf": False, "plan": "test",
                                               "norms": {"from": "pilot_norms.csv", "min_ratings": 10,
                                                         "min_intended_share": 0.5}})
    driver.get(live_server.url + reverse("admin:studyapp_study_change", args=[main.pk]))
    table = driver.find_element(By.CSS_SELECTOR, ".norms-table")
    assert "out: intended share 0.35 < 0.5" in table.text
    assert "observer flag advisory" in table.text
    row = table.find_element(By.XPATH, "ancestor::div[contains(@class, 'field-matching_clips')]")
    shot(driver, shots, "admin_pool_norms.png", row)
