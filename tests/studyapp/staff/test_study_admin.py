"""Researcher side: staff-only pages, create from preset, open/close, preview without recording, progress,
streamed exports in the DESIGN.md formats, management commands."""
from __future__ import annotations

import csv
import io

import pytest
from django.contrib.auth.models import User
from django.core.management import CommandError, call_command
from django.http import StreamingHttpResponse
from django.test import Client
from django.urls import reverse

from protocol.vocabulary import CLIP_COLUMNS, LIKERT_FEATURES, PARTICIPANT_COLUMNS, RESPONSE_COLUMNS
from studyapp.models import Participant, Response, Study
from studyapp.participant.assignment import current_step, start_participant
from studyapp.participant.views import save_answers
from studyapp.questions import questions_for
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import admin_form_data, make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def staff():
    user = User.objects.create_user("researcher", password="pw-researcher-1", is_staff=True, is_superuser=True)
    c = Client()
    c.force_login(user)
    return c


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    return create_study_from_preset("demo", "demo", plan="test", status="open")


def finish(p: Participant, gender="female") -> int:
    """Answer every clip of p with the first choice (library calls, no HTTP). Returns the number of answers."""
    p.demographics_done, p.gender, p.age_group = True, gender, "18-24"
    p.save()
    start_participant(p)
    n = 0
    while (step := current_step(p)).kind == "item":
        a = step.assignment
        qs = questions_for(a.section.section_type, a.section.options, a.clip.theme, a.options)
        answers = {q.key: q.choices[-1][0] for q in qs}
        save_answers(a, answers, 1000)
        n += len(answers)
    p.feedback, p.feedback_done, p.status = {"distracted_camera": "no"}, True, "completed"
    p.save()
    return n


STAFF_URLS = ["studyapp:progress", "studyapp:preview_start", "studyapp:report_zip"]


def test_staff_pages_refuse_others(study):
    anon = Client()
    user = User.objects.create_user("someone", password="pw-someone-1")
    plain = Client()
    plain.force_login(user)
    for c in (anon, plain):
        for name in STAFF_URLS:
            r = c.get(reverse(name, args=[study.pk]))
            assert r.status_code == 302 and "/admin/login/" in r["Location"], name
        r = c.get(reverse("studyapp:export_csv", args=[study.pk, "responses"]))
        assert r.status_code == 302
        assert c.get(reverse("studyapp:preview_item", args=[study.pk, 1])).status_code == 302
        assert c.get("/admin/studyapp/study/").status_code == 302


def test_admin_pages_render(staff, study):
    for u in ["/admin/studyapp/study/", f"/admin/studyapp/study/{study.pk}/change/", "/admin/studyapp/clip/",
              "/admin/studyapp/participant/", "/admin/studyapp/response/", "/admin/studyapp/study/new-from-preset/"]:
        assert staff.get(u).status_code == 200, u


def test_create_from_preset_and_open_close(staff, study):
    r = staff.post(reverse("admin:studyapp_study_from_preset"), {"preset": "gestures_ieeevr2021", "slug": "gest"})
    assert r.status_code == 302
    s = Study.objects.get(slug="gest")
    assert s.status == "draft" and list(s.sections.values_list("section_type", flat=True)) == [
        "gesture_emotion", "naturalness"]
    r = staff.post("/admin/studyapp/study/", {"action": "open_studies", "_selected_action": [s.pk]})
    assert r.status_code == 302
    s.refresh_from_db()
    assert s.status == "open"
    staff.post("/admin/studyapp/study/", {"action": "close_studies", "_selected_action": [s.pk]})
    s.refresh_from_db()
    assert s.status == "closed"


def test_reorder_sections_in_admin(staff, study):
    """Sections are reordered by their `order` field in the study's admin page (inline formset)."""
    s = create_study_from_preset("gestures_ieeevr2021", "gest", plan="test")
    url = f"/admin/studyapp/study/{s.pk}/change/"
    data = admin_form_data(staff.get(url))
    assert data["sections-TOTAL_FORMS"] == "2" and data["sections-0-section_type"] == "gesture_emotion"
    data["sections-0-order"], data["sections-1-order"] = "2", "1"
    r = staff.post(url, data)
    assert r.status_code == 302, r.context["inline_admin_formsets"][0].formset.errors if r.context else r
    assert list(s.sections.order_by("order").values_list("section_type", flat=True)) == [
        "naturalness", "gesture_emotion"]


def test_preview_records_nothing(staff, study):
    start = staff.get(reverse("studyapp:preview_start", args=[study.pk]))
    assert start.status_code == 200 and b"Preview" in start.content
    n, seen = 1, 0
    while True:
        r = staff.get(reverse("studyapp:preview_item", args=[study.pk, n]) + "?seed=7")
        assert r.status_code == 200
        if b"End of the preview" in r.content:
            break
        assert b"nothing you answer here is recorded" in r.content
        bad = staff.post(reverse("studyapp:preview_item", args=[study.pk, n]) + "?seed=7", {})
        assert bad.status_code == 400
        ctx = r.context
        data = {f["q"].key: f["q"].choices[0][0] for f in ctx["fields"]}
        r = staff.post(reverse("studyapp:preview_item", args=[study.pk, n]) + "?seed=7", data)
        assert r.status_code == 302
        n, seen = n + 1, seen + 1
    assert seen > 8
    assert not Participant.objects.exists() and not Response.objects.exists()


def test_progress_counts(staff, study):
    finish(Participant.objects.create(study=study))
    Participant.objects.create(study=study)
    r = staff.get(reverse("studyapp:progress", args=[study.pk]))
    assert r.status_code == 200
    assert r.context["completed"] == 1 and r.context["consented"] == 1
    assert b"gait_gen_" in r.content


def read_csv(resp) -> list[dict]:
    assert isinstance(resp, StreamingHttpResponse)
    text = b"".join(resp.streaming_content).decode()
    return list(csv.DictReader(io.StringIO(text)))


def test_exports_match_design_formats(staff, study):
    p1, p2 = Participant.objects.create(study=study, external_id="PID1"), Participant.objects.create(study=study)
    n_answers = finish(p1) + finish(p2, gender="male")
    r = staff.get(reverse("studyapp:export_csv", args=[study.pk, "responses"]))
    assert r["Content-Type"].startswith("text/csv")
    rows = read_csv(r)
    assert tuple(rows[0]) == RESPONSE_COLUMNS
    assert len(rows) == n_answers == Response.objects.count()
    keys = {(x["participant_id"], x["section_type"], x["clip_id"], x["question"]) for x in rows}
    assert len(keys) == len(rows)                    # every answer exactly once
    inv = [x for x in rows if x["section_type"] == "theme_inversion"]
    assert inv and all(x["answer"] == "7" and x["question"] == "rating" for x in inv)
    likert = {x["question"] for x in rows if x["section_type"] == "affect_likert"}
    assert likert == set(LIKERT_FEATURES)
    assert {x["participant_id"] for x in rows} == {p1.public_id, p2.public_id}
    clips = read_csv(staff.get(reverse("studyapp:export_csv", args=[study.pk, "clips"])))
    assert tuple(clips[0]) == (*CLIP_COLUMNS, "title", "licence", "citation", "body")  # public, provenance, body
    assert {x["clip_id"] for x in rows} <= {c["clip_id"] for c in clips}
    tr = next(c for c in clips if c["clip_id"].startswith("gait_tr_"))
    assert tr["final_happy"] != "" and next(c for c in clips if c["clip_id"] == "gait_gen_00")["final_happy"] == ""
    people = read_csv(staff.get(reverse("studyapp:export_csv", args=[study.pk, "participants"])))
    assert tuple(people[0])[:len(PARTICIPANT_COLUMNS)] == PARTICIPANT_COLUMNS and "distracted_camera" in people[0]
    from studyapp.data.privacy import pseudonym
    assert "PID1" not in {x["external_id"] for x in people}          # pseudonymised by default
    row = next(x for x in people if x["external_id"] == pseudonym(study.pk, "PID1"))
    assert row["gender"] == "female" and row["status"] == "completed" and row["started_at"]
    assert staff.get(reverse("studyapp:export_csv", args=[study.pk, "secrets"])).status_code == 404


def test_export_and_setup_demo_commands(study, tmp_path):
    finish(Participant.objects.create(study=study))
    out = tmp_path / "export"
    call_command("export_study", "demo", "--out", str(out), stdout=io.StringIO())
    for name in ("responses.csv", "clips.csv", "participants.csv"):
        assert (out / name).stat().st_size > 0
    with pytest.raises(CommandError, match="no study"):
        call_command("export_study", "nope", "--out", str(out))
    buf = io.StringIO()
    call_command("setup_demo", stdout=buf)
    call_command("setup_demo", stdout=buf)                      # idempotent
    assert Study.objects.filter(slug="demo").count() == 1
    assert "Participant URL: http://127.0.0.1:8000/s/demo/" in buf.getvalue()
    from django.contrib.auth.models import User

    demo_admin = User.objects.create_user("demo-admin", password="pw-demo-admin-1", is_staff=True)
    call_command("setup_demo", "--owner", "demo-admin", stdout=buf)     # what demo.sh runs: its admin may see it
    assert Study.objects.get(slug="demo").owners.filter(pk=demo_admin.pk).exists()
    with pytest.raises(CommandError, match="no account"):
        call_command("setup_demo", "--owner", "nobody", stdout=buf)


def test_setup_demo_without_clips_says_what_to_run():
    with pytest.raises(CommandError, match="generate_clips --plan demo"):
        call_command("setup_demo")


@pytest.fixture
def gait_study(study):
    return create_study_from_preset("gait_ismar2020", "gaits", plan="test", status="open")


def test_analyze_command_and_report_zip(gait_study, staff, tmp_path, settings):
    for _ in range(3):
        finish(Participant.objects.create(study=gait_study))
    buf = io.StringIO()
    call_command("analyze", "gaits", "--out", str(tmp_path / "rep"), stdout=buf)
    assert (tmp_path / "rep" / "report.json").exists() and (tmp_path / "rep" / "report.html").exists()
    assert "gait_emotion_ad" in buf.getvalue()
    settings.REPORTS_DIR = tmp_path / "reports"
    # The zip is built outside the request (manage.py build_report); until then the download sends staff to the
    # progress page.
    assert staff.get(reverse("studyapp:report_zip", args=[gait_study.pk])).status_code == 302
    call_command("build_report", str(gait_study.pk), stdout=io.StringIO())
    r = staff.get(reverse("studyapp:report_zip", args=[gait_study.pk]))
    assert r.status_code == 200 and r["Content-Type"] == "application/zip"
    import zipfile

    names = zipfile.ZipFile(io.BytesIO(b"".join(r.streaming_content))).namelist()
    assert "report.json" in names and "data/responses.csv" in names


def test_analyze_reports_invalid_exports(gait_study, tmp_path):
    finish(Participant.objects.create(study=gait_study))
    Response.objects.filter(question="torso").update(answer="9")      # out of the Likert range
    with pytest.raises(CommandError, match="did not validate"):
        call_command("analyze", "gaits", "--out", str(tmp_path / "rep"), stdout=io.StringIO())


def test_assignments_export_records_options_shown(staff, study):
    p = Participant.objects.create(study=study)
    finish(p)
    rows = read_csv(staff.get(reverse("studyapp:export_csv", args=[study.pk, "assignments"])))
    assert len(rows) == p.assignments.count()
    gest = [r for r in rows if r["section_type"] == "gesture_emotion"]
    assert gest and all(len(r["options"].split(";")) == 4 for r in gest)
    assert all(r["answered_at"] for r in rows)


def test_clip_admin_shows_poster_and_video_and_downloads_a_contact_sheet(staff, study, settings):
    from PIL import Image

    from studyapp.models import Clip

    clips = list(Clip.objects.order_by("clip_id")[:3])
    for i, clip in enumerate(clips):
        Image.new("RGB", (64, 48), (40 * i, 120, 200)).save(settings.MEDIA_ROOT / f"poster{i}.png")
        clip.poster = f"poster{i}.png"
        clip.save()
    page = staff.get(reverse("admin:studyapp_clip_change", args=[clips[0].pk]))
    assert page.status_code == 200
    assert reverse("studyapp:media", args=[clips[0].media_key, "mp4"]).encode() in page.content
    assert b"<video" in page.content
    listing = staff.get(reverse("admin:studyapp_clip_changelist"))
    assert reverse("studyapp:media", args=[clips[1].media_key, "png"]).encode() in listing.content

    sheet = staff.post(reverse("admin:studyapp_clip_changelist"),
                       {"action": "download_contact_sheet", "_selected_action": [c.pk for c in clips]})
    assert sheet.status_code == 200 and sheet["Content-Type"] == "image/png"
    image = Image.open(io.BytesIO(b"".join(sheet.streaming_content)))
    assert image.width >= 64 and image.height >= 48

    no_poster = Clip.objects.exclude(pk__in=[c.pk for c in clips])[:1]
    refused = staff.post(reverse("admin:studyapp_clip_changelist"),
                         {"action": "download_contact_sheet", "_selected_action": [c.pk for c in no_poster]},
                         follow=True)
    assert b"has a poster image" in refused.content
