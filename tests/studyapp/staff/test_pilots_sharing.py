"""Pilots and sharing (studyapp.staff.study_clone, studyapp.staff.pilots, studyapp.staff.sharing,
studyapp.staff.views_share): clone a study, run a pilot whose participants stay apart and can be deleted, share a signed
preview link that needs no account and stores nothing, and the Prolific URL with its placeholders."""
from __future__ import annotations

import csv
import io

import pytest
from django.contrib.auth.models import User
from django.contrib.sessions.models import Session
from django.test import Client
from django.urls import reverse

from studyapp.data.export import write_study_csvs
from studyapp.models import Assignment, Participant, Response, SectionClipCount, Study
from studyapp.participant.assignment import current_step, start_participant
from studyapp.participant.views import save_answers
from studyapp.questions import questions_for
from studyapp.staff.pilots import delete_pilot_data
from studyapp.staff.presets import create_study_from_preset
from studyapp.staff.reports import data_version
from studyapp.staff.sharing import preview_token
from studyapp.staff.study_clone import clone_study
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def lead():
    return User.objects.create_user("lead", password="pw-lead-12345", is_staff=True, is_superuser=True)


@pytest.fixture
def staff(lead):
    client = Client()
    client.force_login(lead)
    return client


@pytest.fixture
def study(settings, tmp_path, lead):
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.REPORTS_DIR = tmp_path / "reports"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("gait_ismar2020", "pilotable", plan="test")
    study.owners.add(lead)
    study.sections.update(require_full_play=False)
    return study


def take_part(study: Study, **fields) -> Participant:
    p = Participant.objects.create(study=study, demographics_done=True, **fields)
    start_participant(p)
    while (step := current_step(p)).kind == "item":
        a = step.assignment
        save_answers(a, {q.key: q.choices[0][0] for q in questions_for(a.section.section_type, a.section.options,
                                                                       a.clip.theme, a.options)}, 900)
    return p


def counts(study: Study) -> dict:
    return {(c.section_id, c.clip_id): c.n for c in SectionClipCount.objects.filter(section__study=study) if c.n}


def test_a_clone_copies_texts_sections_and_pools_but_no_participants(study, lead):
    Study.objects.filter(pk=study.pk).update(status=Study.Status.OPEN)
    take_part(study)
    other = User.objects.create_user("colleague", password="pw-colleague-1", is_staff=True)
    copy = clone_study(study, "pilotable-2", "Second run", other)
    assert (copy.status, copy.slug, copy.title, copy.preset) == ("draft", "pilotable-2", "Second run", study.preset)
    assert copy.consent_text == study.consent_text and copy.feedback_questions == study.feedback_questions
    assert copy.completion_code != study.completion_code and not copy.participants.exists()
    assert set(copy.owners.all()) == {lead, other}
    fields = ("order", "section_type", "title", "instructions", "pool", "options", "clips_per_participant")
    old, new = list(study.sections.order_by("order")), list(copy.sections.order_by("order"))
    assert [[getattr(s, f) for f in fields] for s in old] == [[getattr(s, f) for f in fields] for s in new]
    reused = [(s.order, s.reuse_section.order if s.reuse_section else None) for s in new]
    assert reused == [(s.order, s.reuse_section.order if s.reuse_section else None) for s in old]
    assert all(s.reuse_section.study_id == copy.pk for s in new if s.reuse_section)
    assert not SectionClipCount.objects.filter(section__study=copy, n__gt=0).exists()


def test_the_clone_page_makes_a_draft_and_opens_it(staff, study):
    page = staff.get(reverse("studyapp:clone_study", args=[study.pk]))
    assert page.status_code == 200 and page.context["form"]["slug"].value() == "pilotable-copy"
    r = staff.post(reverse("studyapp:clone_study", args=[study.pk]), {"slug": "again", "title": "Again"})
    copy = Study.objects.get(slug="again")
    assert r["Location"] == reverse("admin:studyapp_study_change", args=[copy.pk])
    assert staff.get(r["Location"]).status_code == 200
    taken = staff.post(reverse("studyapp:clone_study", args=[study.pk]), {"slug": "again", "title": "x"})
    assert taken.status_code == 200 and "already exists" in str(taken.context["form"].errors)


def test_pilot_participants_are_marked_kept_out_of_the_report_and_deleted(study, tmp_path):
    study.pilot = True
    study.save()
    entry = Client().get(reverse("studyapp:study_entry", args=[study.slug]))
    assert entry.status_code == 200 and b"start-study" in entry.content      # a draft in pilot mode takes people
    pilots = [take_part(study) for _ in range(2)]
    assert all(p.pilot and p.public_id.startswith("pilot-") for p in pilots)
    study.pilot = False
    study.status = Study.Status.OPEN
    study.save()
    real = take_part(study)
    assert not real.pilot and not real.public_id.startswith("pilot-")
    every = write_study_csvs(study, tmp_path / "all")
    for kind in ("responses", "participants", "assignments"):
        ids = {row["participant_id"] for row in csv.DictReader(io.StringIO(every[kind].read_text()))}
        assert ids == {real.public_id, *(p.public_id for p in pilots)}, kind
    report = write_study_csvs(study, tmp_path / "report", include_pilot=False)
    for kind in ("responses", "participants", "assignments", "viewing"):
        ids = {row["participant_id"] for row in csv.DictReader(io.StringIO(report[kind].read_text()))}
        assert ids <= {real.public_id}, kind
    before = data_version(study)
    study.report_includes_pilot = True
    assert data_version(study) != before                # a report with pilots is another report

    real_counts = {}
    for a in Assignment.objects.filter(participant=real, kind="", section__reuse_section__isnull=True):
        real_counts[(a.section_id, a.clip_id)] = real_counts.get((a.section_id, a.clip_id), 0) + 1
    assert counts(study) != real_counts
    assert delete_pilot_data(study) == 2
    assert not Participant.objects.filter(pilot=True).exists()
    assert not Response.objects.filter(participant__public_id__startswith="pilot-").exists()
    assert counts(study) == real_counts                  # the balancing counts hold only the real participant
    assert Response.objects.filter(participant=real).exists()


def test_the_progress_page_deletes_pilot_data_only_when_confirmed(staff, study):
    study.pilot = True
    study.save()
    take_part(study)
    page = staff.get(reverse("studyapp:progress", args=[study.pk]))
    assert page.context["n_pilot"] == 1 and b'id="delete-pilot-form"' in page.content
    url = reverse("studyapp:delete_pilot", args=[study.pk])
    staff.post(url)
    assert Participant.objects.filter(pilot=True).count() == 1
    staff.post(url, {"confirm": "yes"})
    assert not Participant.objects.exists()


def test_opening_a_study_ends_pilot_mode(staff, study):
    study.pilot = True
    study.save()
    take_part(study)
    staff.post(reverse("admin:studyapp_study_changelist"),
               {"action": "open_studies", "_selected_action": [study.pk]}, follow=True)
    study.refresh_from_db()
    assert study.status == Study.Status.OPEN and not study.pilot
    assert not take_part(study).pilot


def test_a_shared_preview_link_needs_no_account_and_stores_nothing(staff, study):
    r = staff.post(reverse("studyapp:share_preview", args=[study.pk]), {"days": "7"}, follow=True)
    html = r.content.decode()
    start = html.index('id="shared-preview-url" value="') + len('id="shared-preview-url" value="')
    url = html[start:html.index('"', start)].replace("http://testserver", "")
    sessions = Session.objects.count()                  # the researcher's own
    anyone = Client()
    first = anyone.get(url)
    assert first.status_code == 200 and b"Start the preview" in first.content
    item_url = reverse("studyapp:shared_preview_item", args=[url.split("/")[2], 1]) + "?seed=3"
    page = anyone.get(item_url)
    assert page.status_code == 200 and page.context["preview"] and page.context["form_action"] == item_url
    answers = {f["q"].key: f["q"].choices[0][0] for f in page.context["fields"]}
    moved = anyone.post(item_url, answers)
    assert moved.status_code == 302 and moved["Location"].endswith("/2/?seed=3")
    assert anyone.post(item_url, {}).status_code == 400                      # checked like a participant's
    total = page.context["total"]
    end = anyone.get(reverse("studyapp:shared_preview_item", args=[url.split("/")[2], total + 1]))
    assert b"End of the preview" in end.content
    assert not Participant.objects.exists() and not Response.objects.exists() and not Assignment.objects.exists()
    assert "sessionid" not in anyone.cookies and Session.objects.count() == sessions


def test_a_preview_link_cannot_be_altered_and_expires(study):
    token = preview_token(study, 1)
    assert Client().get(reverse("studyapp:shared_preview", args=[token])).status_code == 200
    assert Client().get(reverse("studyapp:shared_preview", args=[token[:-2] + "xx"])).status_code == 404
    old = preview_token(study, 1, now=0)
    assert Client().get(reverse("studyapp:shared_preview", args=[old])).status_code == 404
    with pytest.raises(ValueError):
        preview_token(study, 365)


def test_the_progress_page_shows_the_prolific_url_and_completion_code(staff, study):
    html = staff.get(reverse("studyapp:progress", args=[study.pk])).content.decode()
    url = ("http://testserver/s/pilotable/?PROLIFIC_PID={{%PROLIFIC_PID%}}&amp;STUDY_ID={{%STUDY_ID%}}"
           "&amp;SESSION_ID={{%SESSION_ID%}}")
    assert f'id="prolific-url" value="{url}"' in html
    assert f'id="completion-code" value="{study.completion_code}"' in html
    assert f"cc={study.completion_code}" in html and 'data-copy="prolific-url"' in html
