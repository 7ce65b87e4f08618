"""studyapp.participant.page_reads: the participant pages' two plain-SQL reads give what the ORM querysets give."""
from __future__ import annotations

import threading

import pytest
from django.db import connection
from django.test.utils import CaptureQueriesContext

from studyapp.models import Assignment, Participant, Study
from studyapp.participant.assignment import open_items, start_participant
from studyapp.participant.page_reads import ASSIGNMENT_FIELDS, CLIP_FIELDS, open_assignments, participant_by_token
from studyapp.staff.presets import create_study_from_preset
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
    Assignment.objects.filter(participant=out[2], seq=1).update(shown_at="2026-01-02T03:04:05Z",
                                                                options={"shown": ["happy", "sad"]})
    return out


def values(obj, model) -> dict:
    """Every loaded (not deferred) concrete field value of an instance."""
    deferred = obj.get_deferred_fields()
    return {f.attname: getattr(obj, f.attname) for f in model._meta.concrete_fields if f.attname not in deferred}


def orm_assignments(pk, n):
    only = (*ASSIGNMENT_FIELDS, "section", "clip", *(f"clip__{f}" for f in CLIP_FIELDS))
    return list(Assignment.objects.filter(participant_id=pk, answered_at__isnull=True)
                .select_related("section", "clip").only(*only).order_by("seq")[:n])


@pytest.mark.parametrize("n", [1, 2, 3])
def test_assignments_equal_the_querysets(people, n):
    from studyapp.models import Clip, Section

    for p in people:
        plain = orm_assignments(p.pk, n)
        with CaptureQueriesContext(connection) as q:
            got = open_assignments(p.pk, n)
        assert len(q) == 1 and len(got) == len(plain) == n
        for a, b in zip(got, plain):
            assert values(a, Assignment) == values(b, Assignment)
            assert a.get_deferred_fields() == b.get_deferred_fields()
            assert values(a.section, Section) == values(b.section, Section)
            assert values(a.clip, Clip) == values(b.clip, Clip)
            assert a.clip.get_deferred_fields() == b.clip.get_deferred_fields() != set()
    # typed values, as the ORM gives them on every backend
    first = open_assignments(people[2].pk, 1)[0]
    assert first.options == {"shown": ["happy", "sad"]} and first.shown_at.tzinfo is not None
    assert isinstance(first.section.require_full_play, bool) and isinstance(first.clip.loop, bool)
    assert [a.seq for a in open_items(people[1], 2)] == [3, 4]          # the participant who answered two clips


def test_participant_with_its_study_and_missing_tokens(people):
    study = Study.objects.get(slug="pre")
    plain = Participant.objects.select_related("study").get(pk=people[0].pk)
    with CaptureQueriesContext(connection) as q:
        p = participant_by_token(people[0].token)
        assert p.study.slug == "pre" and p.study.feedback_questions == study.feedback_questions
    assert len(q) == 1                                        # the study came with the participant
    assert values(p, Participant) == values(plain, Participant)
    assert values(p.study, Study) == values(plain.study, Study)
    assert p._state.adding is False and p._state.db == "default"
    p.save(update_fields=["demographics_done"])               # a normal, saveable instance
    assert participant_by_token("no-such-token") is None
    assert open_assignments(10 ** 9, 2) == []
    with pytest.raises(ValueError, match="n must be >= 1"):
        open_assignments(people[0].pk, 0)


@pytest.mark.django_db(transaction=True)
def test_each_thread_uses_its_own_connection(people):
    if connection.vendor == "sqlite":
        pytest.skip("SQLite's in-memory test database is not shared with other threads")
    open_assignments(people[0].pk, 1)                          # SQL written in this thread
    seen, errors = [], []

    def run():
        try:
            seen.append([a.seq for a in open_assignments(people[1].pk, 3)])
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(repr(exc))
        finally:
            connection.close()

    t = threading.Thread(target=run)
    t.start()
    t.join(30)
    assert not errors and seen == [[3, 4, 5]]
