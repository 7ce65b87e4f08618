"""The study admin page in steps, in headless Chromium: from the study list to the first step, along the step bar
(each step's page short, the clips step showing a naturalness section's halves), moving a section, and saving a
step without losing the others (studyapp.admin.study_steps, studyapp.admin.steps)."""
from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.urls import reverse

from studyapp.admin import study_steps
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue, wait_for

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]


def test_walk_the_steps_in_chromium(chromium, live_server, settings, tmp_path):
    from selenium.webdriver.common.by import By

    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("gestures_ieeevr2021", "steps", plan="test")
    study.exclusion_rules = {"min_straight": 6}
    study.save()
    User.objects.create_superuser("researcher", "r@example.org", "steps-pw-12345")
    driver = chromium
    driver.set_window_size(1280, 900)
    driver.get(live_server.url + "/admin/login/")
    driver.find_element(By.ID, "id_username").send_keys("researcher")
    driver.find_element(By.ID, "id_password").send_keys("steps-pw-12345")
    driver.find_element(By.CSS_SELECTOR, "input[type=submit]").click()
    wait_for(driver, lambda d: "/admin/login/" not in d.current_url, what="admin login")

    driver.get(live_server.url + reverse("admin:studyapp_study_changelist"))
    driver.find_element(By.LINK_TEXT, study.title).click()
    wait_for(driver, lambda d: d.current_url.endswith("?step=overview"), what="the first step")
    heights = {}
    for step in study_steps.STEPS:
        current = driver.find_element(By.CSS_SELECTOR, ".study-steps [aria-current=page]")
        assert current.text == step.title
        heights[step.key] = driver.execute_script("return document.body.scrollHeight")
        if step.key == "clips":
            natural = driver.find_element(By.ID, "sections-1")
            assert natural.find_element(By.CSS_SELECTOR, "fieldset.only-naturalness").is_displayed()
            assert not driver.find_element(By.ID, "sections-0").find_element(
                By.CSS_SELECTOR, "fieldset.only-naturalness").is_displayed()
        if step is not study_steps.STEPS[-1]:
            following = study_steps.STEPS[study_steps.STEPS.index(step) + 1]
            link = driver.find_element(By.CSS_SELECTOR, f".study-steps a[href$='?step={following.key}']")
            assert link.text == following.title
            link.click()
            wait_for(driver, lambda d, key=following.key: d.current_url.endswith(f"?step={key}"),
                     what=f"the {following.key} step")
    driver.get(live_server.url + reverse("admin:studyapp_study_change", args=[study.pk]))
    whole = driver.execute_script("return document.body.scrollHeight")
    assert max(heights.values()) < whole, (heights, whole)

    # move the second section up, then save the exclusions step: nothing else changes
    driver.get(live_server.url + reverse("admin:studyapp_study_change", args=[study.pk]) + "?step=sections")
    driver.find_elements(By.CSS_SELECTOR, ".section-moves button")[1].click()
    wait_for(driver, lambda d: "Moved section 1 (naturalness" in d.page_source, what="the move message")
    assert list(study.sections.order_by("order").values_list("section_type", flat=True)) == [
        "naturalness", "gesture_emotion"]
    driver.find_element(By.CSS_SELECTOR, ".study-steps a[href$='?step=exclusions']").click()
    box = wait_for(driver, lambda d: d.find_element(By.NAME, "rule_min_straight"), what="the exclusions step")
    box.clear()
    box.send_keys("8")
    driver.find_element(By.NAME, "_continue").click()
    wait_for(driver, lambda d: "was changed successfully" in d.page_source, what="the save")
    study.refresh_from_db()
    assert study.exclusion_rules == {"min_straight": 8}
    assert study.sections.count() == 2 and study.title
