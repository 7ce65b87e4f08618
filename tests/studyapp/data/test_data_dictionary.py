"""Data a reviewer can read: every export carries a data dictionary written from the protocol's definitions
(protocol.dictionary) and a Psych-DS dataset_description.json; the progress page shows the completion funnel,
median times and answers per day (studyapp.staff.progress_stats)."""
from __future__ import annotations

import csv
import io
import json
import zipfile
from datetime import timedelta

import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.urls import reverse
from django.utils import timezone

from protocol.dictionary import DictionaryError, dictionary_rows
from protocol.vocabulary import (
    ANSWER_QUESTIONS,
    ASSIGNMENT_COLUMNS,
    PAGE_COLUMNS,
    PARTICIPANT_COLUMNS,
    RESPONSE_COLUMNS,
    VIEWING_COLUMNS,
)
from studyapp.data.export import EXPORT_CLIP_COLUMNS, EXPORT_KINDS, write_data_package
from studyapp.models import Assignment, Participant, Study
from studyapp.staff.presets import create_study_from_preset
from studyapp.staff.progress_stats import progress_stats
from studyapp.testing import make_catalogue
from tests.studyapp.staff.test_pilots_sharing import take_part

PROTOCOL_FILES = {"responses.csv": RESPONSE_COLUMNS, "clips.csv": EXPORT_CLIP_COLUMNS,
                  "participants.csv": PARTICIPANT_COLUMNS, "assignments.csv": ASSIGNMENT_COLUMNS,
                  "viewing.csv": VIEWING_COLUMNS, "pages.csv": PAGE_COLUMNS}


def test_every_protocol_column_has_an_entry_and_a_new_one_fails():
    assert {f"{kind}.csv" for kind in EXPORT_KINDS} == set(PROTOCOL_FILES)
    rows = dictionary_rows(PROTOCOL_FILES)
    for file, columns in PROTOCOL_FILES.items():
        documented = {r["column"] for r in rows if r["file"] == file and r["column"]}
        assert documented == set(columns), file
        assert all(r["meaning"] and r["type"] for r in rows if r["file"] == file)
    with pytest.raises(DictionaryError, match="responses.csv: column 'mood'"):
        dictionary_rows({"responses.csv": [*RESPONSE_COLUMNS, "mood"]})


def test_answer_is_described_per_section_type_and_question():
    rows = [r for r in dictionary_rows(PROTOCOL_FILES) if r["column"] == "answer" and r["applies_to"]]
    described = {r["applies_to"] for r in rows}
    for section_type, questions in ANSWER_QUESTIONS.items():
        for question in questions:
            assert f"section_type={section_type}; question={question}" in described
    likert = next(r for r in rows if r["applies_to"] == "section_type=affect_likert; question=torso")
    assert likert["allowed_values"] == "0 | 1 | 2 | 3 | 4" and "contracted, bowed" in likert["units"]
    multi = next(r for r in rows if r["applies_to"] == "section_type=emotion_choice; question=perceived")
    assert multi["type"] == "list of labels" and multi["allowed_values"] == "happy | sad | angry | neutral"


@pytest.fixture
def lead():
    return User.objects.create_user("lead", password="pw-lead-12345", is_staff=True, is_superuser=True,
                                    first_name="Ada", last_name="Lovelace")


@pytest.fixture
def study(settings, tmp_path, lead):
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.REPORTS_DIR = tmp_path / "reports"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("gait_ismar2020", "readable", plan="test", status=Study.Status.OPEN)
    study.owners.add(lead)
    study.sections.update(require_full_play=False)
    return study


@pytest.mark.django_db
def test_the_data_zip_carries_a_dictionary_of_every_column_and_a_psych_ds_description(study, lead):
    take_part(study)
    client = Client()
    client.force_login(lead)
    r = client.get(reverse("studyapp:data_zip", args=[study.pk]))
    assert r.status_code == 200 and r["Content-Type"] == "application/zip"
    with zipfile.ZipFile(io.BytesIO(b"".join(r.streaming_content))) as zf:
        files = {name.rsplit("/", 1)[-1]: zf.read(name).decode() for name in zf.namelist()}
    assert {"data_dictionary.csv", "dataset_description.json", *(f"{k}.csv" for k in EXPORT_KINDS)} == set(files)
    dictionary = list(csv.DictReader(io.StringIO(files["data_dictionary.csv"])))
    for kind in EXPORT_KINDS:
        header = next(csv.reader(io.StringIO(files[f"{kind}.csv"])))
        documented = {d["column"] for d in dictionary if d["file"] == f"{kind}.csv"}
        assert set(header) <= documented, kind
    feedback = next(d for d in dictionary if d["column"] == study.feedback_questions[0]["key"])
    assert feedback["meaning"].startswith("Feedback question: ")
    description = json.loads(files["dataset_description.json"])
    assert description["@type"] == "Dataset" and description["name"] == study.title
    assert description["author"] == [{"@type": "Person", "name": "Ada Lovelace"}] and description["license"] == ""
    assert {"participant_id", "answer", "response_ms", "title"} <= {v["name"] for v in
                                                                     description["variableMeasured"]}


@pytest.mark.django_db
def test_the_report_data_folder_has_the_dictionary_too(study, tmp_path):
    take_part(study)
    paths = write_data_package(study, tmp_path / "data")
    assert paths["dictionary"].is_file() and paths["description"].is_file()


@pytest.mark.django_db
def test_progress_shows_the_funnel_median_times_and_answers_per_day(study, lead):
    done = [take_part(study) for _ in range(3)]
    Participant.objects.create(study=study)                                 # consented, never started
    start = timezone.now() - timedelta(minutes=30)
    for i, p in enumerate(done):
        Participant.objects.filter(pk=p.pk).update(status="completed", started_at=start,
                                                   completed_at=start + timedelta(seconds=600 + 60 * i))
    for a in Assignment.objects.filter(participant=done[0]):
        Assignment.objects.filter(pk=a.pk).update(shown_at=start, answered_at=start + timedelta(seconds=90))
    stats = progress_stats(Study.objects.get(pk=study.pk))
    assert [n for _, n in stats.funnel.steps] == [4, 3, 3] and stats.funnel.excluded is None
    assert stats.median_participant_s == 660.0 and stats.n_timed == 3
    assert any(s.median_s is not None and s.n >= 1 for s in stats.sections)
    assert sum(n for _, n in stats.per_day) > 0
    client = Client()
    client.force_login(lead)
    html = client.get(reverse("studyapp:progress", args=[study.pk])).content.decode()
    assert 'id="funnel-table"' in html and "660 s" in html and 'id="answers-per-day"' in html
