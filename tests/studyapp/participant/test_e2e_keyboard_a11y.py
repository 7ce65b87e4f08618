"""Keyboard use, accessibility and the player's shape, in real headless Chromium.

A participant takes the German demo study with the keyboard only: Tab and Space on the consent page, number keys
for every answer, Enter to continue, Tab to the text box of the feedback page. On the way:
- axe-core (vendored, tests/vendor/axe-core-<version>/, injected by Selenium) finds no serious or critical
  violation on the consent, demographics, first clip page of every section type, feedback and done pages;
- the Tab order of a clip page follows the document (skip link, player, questions, button);
- at 360x740 (a phone, emulated) no page scrolls sideways, and the player keeps the clips' 16:9 shape on the
  phone and on a 1366x768 desktop;
- the exported answers are the protocol's labels, not the German ones shown.

Set STUDY_SCREENSHOTS=<folder> to save docs/img/study_consent_de.png, study_item_de.png, study_done_de.png and
study_phone_360.png there (and STUDY_SCREENSHOTS_EVERY_TYPE=<folder> the first clip page of every section type, at
1000 px). The clips are SYNTHETIC 16:9 test patterns (a moving square), not study stimuli.
"""
from __future__ import annotations

import csv
import hashlib
import io
import os
import time
from pathlib import Path

import pytest
from django.urls import reverse

from protocol.vocabulary import ATTENTION_CHECK, SECTION_QUESTIONS, SECTION_TYPES, answer_values
from studyapp.data.export import stream_csv
from studyapp.models import Assignment, Participant, Response, Study
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue, wait_for

pytestmark = [pytest.mark.browser, pytest.mark.slow, pytest.mark.django_db(transaction=True)]

AXE_DIR = Path(__file__).resolve().parents[2] / "vendor" / "axe-core-4.14.1"
AXE_SHA256 = "29348999450cdf2849a8e70b7912fc2da85a849da39c0d0d5394f51d4a9ed95c"
BLOCKING_IMPACTS = ("serious", "critical")
PHONE, DESKTOP = (360, 740), (1366, 768)
CLIP_SECONDS = 1.0
# What a researcher might enter for the demo preset's sections in a German study (researcher-written text is
# shown as entered, never translated).
GERMAN_SECTIONS = {
    "emotion_choice": ("Wahrgenommene Emotion: Gang", "Sehen Sie sich jeden Gang an und geben Sie die Emotion(en) "
                                                      "an, die Sie wahrnehmen. Mehrere sind möglich."),
    "emotion_transition": ("Wechsel der Emotion", "In diesen Clips ändert sich die Emotion während des Gehens."),
    "affect_likert": ("Haltung und Bewegung", "Sie sehen die Gänge des ersten Abschnitts noch einmal. Bewerten Sie "
                                              "Oberkörper, Arme, Tempo und Bewegungsfluss jedes Gangs."),
    "naturalness": ("Natürlichkeit", "Bewerten Sie, wie natürlich und flüssig jede Animation wirkt."),
    "gesture_emotion": ("Wahrgenommene Emotion: Gesten", "Wählen Sie die Emotion, die Sie in den Gesten sehen."),
    "neutral_validation": ("Der Ausgangsgang", "Was davon beschreibt den Gang am besten?"),
    "theme_rating": ("Stilbewertung", "Bewerten Sie auf einer siebenstufigen Skala, wie stark der genannte Stil "
                                      "im Gang zu sehen ist."),
    "theme_inversion": ("Umkehrung", "Bewerten Sie jeden Gang von -7 (maximal das Gegenteil) über 0 (neutral) "
                                     "bis +7 (maximal der ursprüngliche Stil)."),
}


def wide_test_clip(path: Path, seconds: float = CLIP_SECONDS, fps: int = 10, size=(320, 180)) -> Path:
    """A SYNTHETIC 16:9 H.264 test pattern (a light square moving over grey), the shape of the rendered clips."""
    import imageio_ffmpeg
    import numpy as np

    w, h = size
    writer = imageio_ffmpeg.write_frames(str(path), (w, h), fps=fps, codec="libx264", pix_fmt_out="yuv420p",
                                         output_params=["-movflags", "+faststart"], macro_block_size=4)
    writer.send(None)
    for i in range(int(seconds * fps)):
        frame = np.full((h, w, 3), 40, dtype=np.uint8)
        x = (i * 24) % (w - 40)
        frame[70:110, x:x + 40] = 220
        writer.send(frame.tobytes())
    writer.close()
    return path


def press(driver, *keys):
    """Keys as a keyboard sends them, to whatever has focus (no element is clicked or targeted)."""
    from selenium.webdriver.common.action_chains import ActionChains

    for key in keys:
        ActionChains(driver).send_keys(key).perform()


def active_id(driver) -> str:
    return driver.execute_script("var a = document.activeElement; return a ? (a.id || a.tagName) : ''")


def tab_until(driver, element_id: str, limit: int = 40, prefix: bool = False) -> list[str]:
    """Press Tab until the element with this id (or, with prefix, an id starting so) has focus; returns the
    ids/tags that had focus on the way."""
    from selenium.webdriver.common.keys import Keys

    seen = []
    for _ in range(limit):
        press(driver, Keys.TAB)
        seen.append(active_id(driver))
        if seen[-1] == element_id or (prefix and seen[-1].startswith(element_id)):
            return seen
    raise AssertionError(f"Tab never reached #{element_id}: {seen}")


def axe_violations(driver) -> list[dict]:
    """Serious and critical axe-core violations of the page (rule id, impact, help, first nodes)."""
    source = (AXE_DIR / "axe.min.js").read_text(encoding="utf-8")
    driver.set_script_timeout(120)
    driver.execute_script(source + "\n;window.axe = axe;")
    found = driver.execute_async_script("""
        var done = arguments[arguments.length - 1];
        axe.run(document, {resultTypes: ["violations"]}).then(function (r) {
          done(r.violations.map(function (v) {
            return {id: v.id, impact: v.impact, help: v.help,
                    nodes: v.nodes.slice(0, 4).map(function (n) { return n.target.join(" "); })};
          }));
        }).catch(function (e) { done([{id: "axe-error", impact: "critical", help: String(e), nodes: []}]); });
    """)
    return [v for v in found if v["impact"] in BLOCKING_IMPACTS]


def emulate(driver, size, mobile: bool):
    """A phone (mobile viewport and a touch screen) or a desktop window of this size, in CSS pixels."""
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {
        "width": size[0], "height": size[1], "deviceScaleFactor": 1, "mobile": mobile})
    driver.execute_cdp_cmd("Emulation.setTouchEmulationEnabled", {"enabled": mobile, "maxTouchPoints": 5})
    time.sleep(0.2)


def layout(driver) -> dict:
    """Page width vs viewport and the player's rendered box."""
    return driver.execute_script("""
        var v = document.getElementById("clip"), r = v ? v.getBoundingClientRect() : null;
        return {scroll: document.documentElement.scrollWidth, inner: window.innerWidth,
                video: r ? [r.width, r.height] : null, natural: v ? [v.videoWidth, v.videoHeight] : null};
    """)


def check_phone_and_desktop(driver, name: str, shots: Path | None = None) -> None:
    """No sideways scrolling at 360 px; the player is 16:9 on the phone and on the desktop."""
    emulate(driver, PHONE, mobile=True)
    phone = layout(driver)
    assert phone["scroll"] <= phone["inner"] == PHONE[0], f"{name} scrolls sideways on a phone: {phone}"
    if shots is not None:
        height = driver.execute_script("return document.documentElement.scrollHeight")
        emulate(driver, (PHONE[0], max(PHONE[1], int(height))), mobile=True)
        driver.save_screenshot(str(shots / "study_phone_360.png"))
    emulate(driver, DESKTOP, mobile=False)
    desktop = layout(driver)
    driver.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})
    driver.execute_cdp_cmd("Emulation.setTouchEmulationEnabled", {"enabled": False})
    for where, box in (("phone", phone["video"]), ("desktop", desktop["video"])):
        if box is None:
            continue
        width, height = box
        assert width > 0 and abs(width / height - 16 / 9) < 0.02, f"{name} player on the {where}: {box}"
        assert width <= (PHONE if where == "phone" else DESKTOP)[0]


def full_shot(driver, path: Path, width: int = 1000):
    """Screenshot of the whole page at this width (the viewport made as tall as the document)."""
    emulate(driver, (width, 900), mobile=False)
    height = driver.execute_script("return document.documentElement.scrollHeight")
    emulate(driver, (width, int(height)), mobile=False)
    driver.save_screenshot(str(path))
    driver.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})


def assert_accessible(driver, page: str) -> None:
    bad = axe_violations(driver)
    assert not bad, f"axe-core on the {page} page:\n" + "\n".join(map(str, bad))


def test_axe_is_the_pinned_release():
    assert hashlib.sha256((AXE_DIR / "axe.min.js").read_bytes()).hexdigest() == AXE_SHA256
    assert "Mozilla Public" in (AXE_DIR / "axe.min.js").read_text(encoding="utf-8")[:600]


@pytest.fixture
def german_study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    clip = wide_test_clip(tmp_path / "wide.mp4").read_bytes()
    make_catalogue(settings.MEDIA_ROOT, video_bytes=clip, duration_s=CLIP_SECONDS, gesture_video_bytes=clip)
    study = create_study_from_preset("demo", "demo-de", plan="test", status=Study.Status.OPEN,
                                     completion_redirect="https://example.org/complete?cc={code}")
    study.language = "de"
    study.title = "Demo-Studie: emotionale Bewegung virtueller Figuren"
    study.introduction = "Eine kurze Demonstration mit jeder Art von Frage. Jeder Clip dauert wenige Sekunden."
    study.consent_text = ("Die Teilnahme ist freiwillig und anonym. Sie können jederzeit abbrechen.\n\n"
                          "Ihre Antworten werden nur für die Forschung verwendet.")
    study.save()
    for section in study.sections.all():       # the researcher writes the section texts in the study's language
        title, instructions = GERMAN_SECTIONS.get(section.section_type, ("", ""))
        section.title, section.instructions = title or section.title, instructions or section.instructions
        section.save(update_fields=["title", "instructions"])
    # what a researcher sets up for Prolific: a practice item and an instructed-response attention check in the
    # first section, and the sections' order counterbalanced across participants
    walks = study.sections.get(section_type="emotion_choice")
    walks.options = {**walks.options, "practice": True, "attention_checks": {"answer": "sad", "positions": [2]}}
    walks.save(update_fields=["options"])
    study.counterbalance_sections = True
    study.save(update_fields=["counterbalance_sections"])
    return study


def keyboard_consent(driver, shots):
    from selenium.webdriver.common.keys import Keys

    assert driver.find_element("css selector", "html").get_attribute("lang") == "de"
    assert "Information und Einwilligung" in driver.page_source
    assert_accessible(driver, "consent")
    check_phone_and_desktop(driver, "consent")
    if shots:
        full_shot(driver, shots / "study_consent_de.png")
    tab_until(driver, "id_consent")
    press(driver, Keys.SPACE)
    assert driver.find_element("id", "id_consent").is_selected()
    press(driver, Keys.ENTER)             # Enter in the form submits it (no click)


def keyboard_demographics(driver):
    from selenium.webdriver.common.keys import Keys

    wait_for(driver, lambda d: "/about-you/" in d.current_url, what="demographics page")
    assert "Zu Ihrer Person" in driver.page_source
    assert_accessible(driver, "demographics")
    check_phone_and_desktop(driver, "demographics")
    press(driver, "2", "3", Keys.ENTER)   # gender: option 2, age group: option 3, continue


def focus_order_of_clip_page(driver, seen: list[str]) -> None:
    """Tab from the top: skip link, the player's play/pause and replay buttons (the default replay-only player: the
    video itself has no controls, so it is no tab stop), one stop per question, the button, in document order."""
    seen = seen + tab_until(driver, "next")
    ordered = driver.execute_script("""
        var ids = arguments[0], els = [];
        ids.forEach(function (id) {
          var e = document.getElementById(id) || document.querySelector(id);
          if (e) { els.push(e); }
        });
        for (var i = 1; i < els.length; i++) {
          var after = els[i - 1].compareDocumentPosition(els[i]) & Node.DOCUMENT_POSITION_FOLLOWING;
          if (els[i] !== els[i - 1] && !after) { return false; }
        }
        return true;
    """, seen)
    assert ordered, f"Tab order does not follow the page: {seen}"
    assert seen[:3] == ["A", "play-pause", "replay"] and "clip" not in seen, seen
    n_questions = len(driver.find_elements("css selector", "#answer-form fieldset.question"))
    in_questions = {s for s in seen if s.startswith("q-")}
    assert len(in_questions) >= n_questions, (seen, n_questions)


def press_instructed(driver, instructed: str) -> None:
    """On an attention-check page (``instructed`` is "<question key>=<answer>"): the instruction is shown, and the
    number key of the instructed answer chooses it."""
    from selenium.webdriver.common.by import By

    key, _, value = instructed.partition("=")
    note = driver.find_element(By.ID, "page-note")
    label = driver.find_element(By.CSS_SELECTOR, f"#answer-form input[name='{key}'][value='{value}']").find_element(
        By.XPATH, "..").text.strip()
    assert note.is_displayed() and label in note.text, note.text      # the instruction names the answer
    values = [e.get_attribute("value") for e in driver.find_elements(By.CSS_SELECTOR, "#answer-form input")
              if e.get_attribute("type") in ("checkbox", "radio")]
    press(driver, str(values.index(value) + 1))


def answer_clip_page(driver, n: int, section_type: str, seen: set[str], shots, instructed: str = "") -> None:
    """Answer clip page n with number keys (the first unanswered question takes each key; on an attention check
    the instructed answer's key) and continue."""
    from selenium.webdriver.common.keys import Keys

    wait_for(driver, lambda d: f"/clip/{n}/" in d.current_url, what=f"clip {n}")
    # Before the clip has played the keys do nothing (answers not enabled yet)
    if n == 1 and not driver.find_element("id", "next").is_enabled():
        press(driver, "1", Keys.ENTER)
        assert f"/clip/{n}/" in driver.current_url
        assert not driver.find_elements("css selector", "#answer-form input:checked")
    wait_for(driver, lambda d: d.find_element("id", "next").is_enabled(), timeout=10 + 3 * CLIP_SECONDS,
             what="clip played")
    questions = driver.find_elements("css selector", "#answer-form fieldset.question")
    first_of_type = section_type not in seen
    if first_of_type:
        seen.add(section_type)
        assert_accessible(driver, f"{section_type} clip")
        check_phone_and_desktop(driver, section_type,
                                shots if shots and section_type == "affect_likert" else None)
    tabbed = []
    if n == 1 and len(questions) == 1:
        # Tab into the question: the keys now answer the question that has focus (a checkbox toggles)
        tabbed = tab_until(driver, "q-", prefix=True)
        multi = "q-multi" in questions[0].get_attribute("class")
        key = questions[0].get_attribute("data-key")
        if multi:
            press(driver, "1", "3", "3", "3")     # 1 on, 3 on, off, on
        else:
            press(driver, "2", "1")               # the last key wins
        checked = [e.get_attribute("id") for e in driver.find_elements("css selector", "#answer-form input:checked")]
        assert checked == [f"q-{key}-1"] + ([f"q-{key}-3"] if multi else []), checked
        assert active_id(driver) in checked       # focus follows the key
    elif instructed:
        press_instructed(driver, instructed)
    else:
        numbered = section_type == "affect_likert"      # 0-4 scales: the key is the number shown, 0 included
        digits = [str((n + i) % 3 + (0 if numbered else 1)) for i, _ in enumerate(questions)]
        press(driver, *digits)
        if numbered:
            chosen = [driver.find_element("css selector", f"#answer-form input[name='{q.get_attribute('data-key')}']"
                                          ":checked").get_attribute("value") for q in questions]
            assert chosen == digits, (chosen, digits)
    checked = driver.find_elements("css selector", "#answer-form input:checked")
    assert {c.get_attribute("name") for c in checked} == {q.get_attribute("data-key") for q in questions}, \
        "a number key did not answer its question"
    if shots and first_of_type and section_type == "affect_likert":
        full_shot(driver, shots / "study_item_de.png")
    if first_of_type and os.environ.get("STUDY_SCREENSHOTS_EVERY_TYPE"):
        full_shot(driver, Path(os.environ["STUDY_SCREENSHOTS_EVERY_TYPE"]) / f"study_{section_type}_de.png")
    if n == 1:
        focus_order_of_clip_page(driver, tabbed)  # ends on the button: Enter presses it
    press(driver, Keys.ENTER)
    wait_for(driver, lambda d: f"/clip/{n}/" not in d.current_url, what=f"leave clip {n}")


def keyboard_feedback(driver):
    from selenium.webdriver.common.keys import Keys

    wait_for(driver, lambda d: "/feedback/" in d.current_url, what="feedback page")
    assert "Letzte Fragen" in driver.page_source
    assert_accessible(driver, "feedback")
    check_phone_and_desktop(driver, "feedback")
    yes_no = [fs for fs in driver.find_elements("css selector", "fieldset.question")
              if fs.find_elements("css selector", "input[type=radio]")]
    press(driver, *["2"] * len(yes_no))          # "Nein" to every yes/no question
    textarea = driver.find_element("css selector", "textarea").get_attribute("id")
    tab_until(driver, textarea)
    press(driver, "Klare Clips, danke. 1 2 3")   # digits in a text box are text, not answers
    tab_until(driver, "next")
    press(driver, Keys.ENTER)


def test_german_study_by_keyboard_only_is_accessible(chromium, live_server, german_study):
    driver = chromium
    shots = Path(os.environ["STUDY_SCREENSHOTS"]) if os.environ.get("STUDY_SCREENSHOTS") else None
    driver.get(live_server.url + reverse("studyapp:study_entry", args=[german_study.slug]) + "?PROLIFIC_PID=kb-1")
    keyboard_consent(driver, shots)
    keyboard_demographics(driver)
    wait_for(driver, lambda d: "/clip/1/" in d.current_url, what="first clip")
    participant = Participant.objects.get(external_id="kb-1")
    items = list(participant.assignments.select_related("section").order_by("seq"))
    assert {a.kind for a in items} >= {Assignment.Kind.PRACTICE, Assignment.Kind.ATTENTION}
    participant.refresh_from_db()
    assert sorted(participant.section_order) == sorted(german_study.sections.values_list("pk", flat=True))
    seen: set[str] = set()
    for n, a in enumerate(items, start=1):
        answer_clip_page(driver, n, a.section.section_type, seen, shots, instructed=a.instructed)
    assert seen >= set(SECTION_TYPES)
    keyboard_feedback(driver)
    wait_for(driver, lambda d: "/done/" in d.current_url, what="completion page")
    assert "Vielen Dank!" in driver.page_source
    assert_accessible(driver, "done")
    check_phone_and_desktop(driver, "done")
    if shots:
        full_shot(driver, shots / "study_done_de.png")
    # the check is not vacuous: an unlabelled text box on the same page is a critical violation
    driver.execute_script("document.querySelector('main').appendChild(document.createElement('input'))")
    assert "label" in {v["id"] for v in axe_violations(driver)}

    participant.refresh_from_db()
    assert participant.status == "completed"
    assert participant.feedback["comments"] == "Klare Clips, danke. 1 2 3"
    assert participant.feedback["distracted_camera"] == "no"
    rows = list(csv.DictReader(io.StringIO("".join(stream_csv(german_study, "responses")))))
    assert len(rows) == Response.objects.filter(participant=participant).count() > 0
    for row in rows:
        kind = SECTION_QUESTIONS.get(row["section_type"], {}).get(row["question"])
        if kind is not None:
            assert set(row["answer"].split(";")) <= set(answer_values(kind)), row
    labels = {r["answer"] for r in rows if r["section_type"] == "emotion_choice"}
    assert labels and not any(a[:1].isupper() for a in labels), labels   # protocol labels, not "Glücklich"
    # the attention check is exported as such with the instructed answer in the question; the practice item never
    checks = [r for r in rows if r["section_type"] == ATTENTION_CHECK]
    assert [(r["question"], r["answer"]) for r in checks] == [("perceived=sad", "sad")], checks
    practice = participant.assignments.get(kind=Assignment.Kind.PRACTICE)
    assert not Response.objects.filter(participant=participant, clip_id=practice.clip_id,
                                       section_id=practice.section_id).exists()
    people = list(csv.DictReader(io.StringIO("".join(stream_csv(german_study, "participants")))))
    assert (people[0]["attention_passed"], people[0]["attention_total"]) == ("1", "1"), people
    assert people[0]["section_order"], people   # the counterbalanced order, recorded per participant
