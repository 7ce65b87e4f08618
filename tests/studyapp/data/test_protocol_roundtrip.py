"""Round trip of the study protocol: the demo study, answered by participants through the real pages, exported by
studyapp.data.export and read back by analysis.io without a single problem; every section type, question and answer of
the export lies inside protocol.vocabulary's vocabularies."""
from __future__ import annotations

import random

import pytest
from django.test import Client
from django.urls import reverse

from analysis.io import read_clips, read_participants, read_responses
from protocol.vocabulary import (
    CLIP_BODY_COLUMNS,
    CLIP_COLUMNS,
    CLIP_PROVENANCE_COLUMNS,
    MULTI_SELECT_KINDS,
    PARTICIPANT_COLUMNS,
    RESPONSE_COLUMNS,
    SECTION_QUESTIONS,
    SECTION_TYPES,
    answer_values,
)
from studyapp.data.export import write_study_csvs
from studyapp.models import Participant, Response, Study
from studyapp.participant.assignment import current_step
from studyapp.questions import questions_for
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


def random_answers(rng: random.Random, assignment) -> dict[str, list[str]]:
    """A random valid POST for one clip page (several labels for multi-select questions)."""
    section, clip = assignment.section, assignment.clip
    data = {}
    for q in questions_for(section.section_type, section.options, clip.theme, assignment.options):
        values = [v for v, _ in q.choices]
        data[q.key] = rng.sample(values, rng.randint(1, 2)) if q.kind == "multi" else [rng.choice(values)]
    return data


def take_part(study: Study, seed: int, gender: str) -> Participant:
    """One participant through the HTTP pages: consent, demographics, every clip, feedback."""
    client, rng = Client(), random.Random(seed)
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]) + f"?PROLIFIC_PID=PID{seed}",
                    {"consent": "on", "PROLIFIC_PID": f"PID{seed}"})
    assert r.status_code == 302
    p = Participant.objects.get(token=r["Location"].rstrip("/").split("/")[-1])
    assert client.post(reverse("studyapp:demographics", args=[p.token]),
                       {"gender": gender, "age_group": "25-34"}).status_code == 302
    assert client.get(reverse("studyapp:resume", args=[p.token])).status_code == 302
    p.refresh_from_db()
    while (step := current_step(p)).kind == "item":
        r = client.post(reverse("studyapp:item", args=[p.token, step.index]), random_answers(rng, step.assignment))
        assert r.status_code == 302, r.content[:300]
        p.refresh_from_db()
    assert step.kind == "feedback"
    feedback = {q["key"]: "no" for q in study.feedback_questions if q.get("kind", "yesno") == "yesno"}
    assert client.post(reverse("studyapp:feedback", args=[p.token]), feedback).status_code == 302
    client.get(reverse("studyapp:resume", args=[p.token]))
    p.refresh_from_db()
    assert p.status == "completed"
    return p


def test_demo_study_round_trip(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("demo", "demo", plan="test", status=Study.Status.OPEN)
    assert {s.section_type for s in study.sections.all()} == set(SECTION_TYPES)
    people = [take_part(study, seed, gender) for seed, gender in ((1, "female"), (2, "male"), (3, "non-binary"))]
    Participant.objects.create(study=study)            # consented, never started: still a participants.csv row

    paths = write_study_csvs(study, tmp_path / "export")
    clips = read_clips(paths["clips"])
    participants = read_participants(paths["participants"])
    responses = read_responses(paths["responses"], clips, participants)

    def header(kind: str) -> tuple[str, ...]:
        return tuple(paths[kind].read_text(encoding="utf-8").splitlines()[0].split(","))

    assert header("clips") == (*CLIP_COLUMNS, *CLIP_PROVENANCE_COLUMNS, *CLIP_BODY_COLUMNS)
    assert header("responses") == RESPONSE_COLUMNS
    assert header("participants")[:len(PARTICIPANT_COLUMNS)] == PARTICIPANT_COLUMNS
    assert not clips.attrs.get("ignored_columns") and not responses.attrs.get("ignored_columns")
    assert len(responses) == Response.objects.count() > 0
    assert len(participants) == 4 and participants["completed"].sum() == 3
    assert set(participants["participant_id"]) >= {p.public_id for p in people}
    assert set(responses["section_type"].astype(str)) == set(SECTION_TYPES)    # every section type answered
    for row in responses[["section_type", "question", "answer"]].astype(str).itertuples(index=False):
        questions = SECTION_QUESTIONS[row.section_type]
        assert row.question in questions, row
        kind = questions[row.question]
        parts = row.answer.split(";") if kind in MULTI_SELECT_KINDS else [row.answer]
        assert parts and set(parts) <= set(answer_values(kind)), row
    assert set(responses["clip_id"].astype(str)) <= set(clips["clip_id"].astype(str))
