"""studyapp.precompiled: a SELECT compiled once gives exactly what its queryset gives (issue 16)."""
from __future__ import annotations

import threading

import pytest
from django.db import connection
from django.test.utils import CaptureQueriesContext

from studyapp.assignment import STEP_FIELDS, open_items, start_participant
from studyapp.models import Assignment, Participant, Study
from studyapp.precompiled import PrecompiledSelect
from studyapp.presets import create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def people(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("demo", "pre", plan="test", status=Study.Status.OPEN)
    out = []
    for _ in range(3):
        p = Participant.objects.create(study=study, demographics_done=True)
        start_participant(p)
        out.append(p)
    Assignment.objects.filter(participant=out[1], seq__lte=2).update(answered_at="2026-01-01T00:00:00Z")
    return out


def as_rows(objects, fields) -> list[tuple]:
    return [tuple(getattr(o, f) for f in fields) for o in objects]


def queryset(pk):
    return (Assignment.objects.filter(participant_id=pk, answered_at__isnull=True)
            .select_related("section", "clip").only(*STEP_FIELDS).order_by("seq")[:3])


def test_same_objects_and_same_sql_as_the_queryset(people):
    pre = PrecompiledSelect(queryset, -1)
    for p in people:
        with CaptureQueriesContext(connection) as plain_q:
            plain = list(queryset(p.pk))
        with CaptureQueriesContext(connection) as pre_q:
            got = pre(p.pk)
        assert [q["sql"] for q in pre_q] == [q["sql"] for q in plain_q]
        fields = ("pk", "seq", "position", "options", "shown_at", "answered_at", "kind", "instructed")
        assert as_rows(got, fields) == as_rows(plain, fields)
        assert as_rows([a.section for a in got], ("pk", "section_type", "options", "title")) == as_rows(
            [a.section for a in plain], ("pk", "section_type", "options", "title"))
        assert as_rows([a.clip for a in got], ("pk", "clip_id", "media_key", "duration_s", "loop")) == as_rows(
            [a.clip for a in plain], ("pk", "clip_id", "media_key", "duration_s", "loop"))
        assert got[0].get_deferred_fields() == plain[0].get_deferred_fields()
    assert open_items(people[1], 2)[0].seq == 3              # the participant who answered two clips


def test_related_study_and_missing_rows(people):
    pre = PrecompiledSelect(lambda token: Participant.objects.select_related("study").filter(token=token), "\0t")
    study = Study.objects.get(slug="pre")
    p = pre(people[0].token)[0]
    with CaptureQueriesContext(connection) as q:
        assert p.study.slug == "pre" and p.study.feedback_questions == study.feedback_questions
    assert len(q) == 0                                        # the study came with the participant
    assert pre("no-such-token") == []


@pytest.mark.django_db(transaction=True)
def test_each_thread_uses_its_own_connection(people):
    pre = PrecompiledSelect(queryset, -1)
    pre(people[0].pk)                                          # compiled in this thread
    seen, errors = [], []

    def run():
        try:
            seen.append([a.seq for a in pre(people[1].pk)])
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(repr(exc))
        finally:
            connection.close()

    if connection.vendor == "sqlite":
        pytest.skip("SQLite's in-memory test database is not shared with other threads")
    t = threading.Thread(target=run)
    t.start()
    t.join(30)
    assert not errors and seen == [[3, 4, 5]]


def test_bad_sentinels_and_arguments_are_refused(people):
    twice = PrecompiledSelect(lambda pk: Assignment.objects.filter(participant_id=pk, section__study__pk=pk), 7)
    with pytest.raises(ValueError, match="appears 2 times"):
        twice(1)
    absent = PrecompiledSelect(lambda pk: Assignment.objects.filter(participant_id=1), 123456)
    with pytest.raises(ValueError, match="appears 0 times"):
        absent(1)
    with pytest.raises(TypeError):
        PrecompiledSelect(queryset, -1)(1, 2)
    with pytest.raises(ValueError):
        PrecompiledSelect(queryset)
