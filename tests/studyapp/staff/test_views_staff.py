"""What the researcher pages do (studyapp.staff.views): create from a preset, preview without recording anything,
progress counts, CSV exports. Who may open them is tests/studyapp/staff/test_staff_permissions.py's subject."""
from __future__ import annotations

import csv
import io
import re

import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.urls import reverse

from protocol.presets import PRESETS
from studyapp.models import Assignment, Participant, Response, Study
from studyapp.participant.assignment import start_participant
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def staff():
    client = Client()
    client.force_login(User.objects.create_user("boss", password="pw-boss-12345", is_staff=True, is_superuser=True))
    return client


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("gait_ismar2020", "staffed", plan="test", status=Study.Status.OPEN)
    study.sections.update(require_full_play=False)
    return study


def test_create_from_preset_makes_a_draft_with_the_presets_sections(staff, settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    r = staff.post(reverse("studyapp:create_from_preset"), {"preset": "demo", "slug": "from-preset", "title": ""})
    study = Study.objects.get(slug="from-preset")
    assert r.status_code == 302 and r["Location"] == reverse("admin:studyapp_study_change", args=[study.pk])
    assert study.status == Study.Status.DRAFT
    assert [s.section_type for s in study.sections.order_by("order")] == [
        s["section_type"] for s in PRESETS["demo"]["sections"]]
    again = staff.post(reverse("studyapp:create_from_preset"), {"preset": "demo", "slug": "from-preset"})
    assert again.status_code == 200 and Study.objects.filter(slug="from-preset").count() == 1   # form error


def _clip_ids(staff, study, seed: int, n_items: int) -> list[str]:
    ids = []
    for n in range(1, n_items + 1):
        page = staff.get(reverse("studyapp:preview_item", args=[study.pk, n]) + f"?seed={seed}").content.decode()
        ids.append(re.search(r"gait_\w+|gest_\w+|rbf_\w+", page).group(0))
    return ids


def test_preview_walks_the_study_and_stores_nothing(staff, study):
    first = staff.get(reverse("studyapp:preview_item", args=[study.pk, 1]) + "?seed=5")
    assert first.status_code == 200 and first.context["preview"] and first.context["seed"] == 5
    # a wrong answer is refused with the page's error; a valid one goes to the next clip, same seed
    bad = staff.post(reverse("studyapp:preview_item", args=[study.pk, 1]) + "?seed=5", {"perceived": "joy"})
    assert bad.status_code == 400 and bad.context["error"]
    total = first.context["total"]
    done = staff.get(reverse("studyapp:preview_item", args=[study.pk, total + 1]) + "?seed=5")
    assert done.status_code == 200 and done.templates[0].name == "studyapp/done.html"
    assert _clip_ids(staff, study, 5, 3) == _clip_ids(staff, study, 5, 3)          # the seed fixes the order
    assert not Participant.objects.exists() and not Response.objects.exists() and not Assignment.objects.exists()


def test_progress_counts_participants_and_clips(staff, study):
    people = [Participant.objects.create(study=study, demographics_done=True) for _ in range(2)]
    for p in people:
        start_participant(p)
    answered = Assignment.objects.filter(participant=people[0]).order_by("seq").first()
    Assignment.objects.filter(pk=answered.pk).update(answered_at="2026-01-01T00:00:00Z")
    page = staff.get(reverse("studyapp:progress", args=[study.pk]))
    assert page.status_code == 200 and page.context["started"] == 2
    first = next(s for s in page.context["sections"] if s["section"].pk == answered.section_id)
    rows = {row["clip__clip_id"]: row for row in first["clips"]}
    assert sum(r["assigned"] for r in rows.values()) == Assignment.objects.filter(section=first["section"]).count()
    assert sum(r["answered"] for r in rows.values()) == 1 and rows[answered.clip.clip_id]["answered"] == 1


def test_exports_stream_the_public_csvs_and_refuse_unknown_kinds(staff, study):
    Participant.objects.create(study=study, demographics_done=True, external_id="prolific-1")
    r = staff.get(reverse("studyapp:export_csv", args=[study.pk, "participants"]))
    assert r.status_code == 200 and r["Content-Disposition"] == 'attachment; filename="staffed-participants.csv"'
    rows = list(csv.DictReader(io.StringIO(b"".join(r.streaming_content).decode())))
    from studyapp.data.privacy import pseudonym
    assert [row["external_id"] for row in rows] == [pseudonym(study.pk, "prolific-1")]
    assert staff.get(reverse("studyapp:export_csv", args=[study.pk, "passwords"])).status_code == 404
