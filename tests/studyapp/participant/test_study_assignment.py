"""Randomization and balanced assignment: recorded seeds, no repeats, reuse, naturalness mixing, concurrency."""
from __future__ import annotations

import threading
from collections import Counter

import pytest
from django.db import connection

from protocol.vocabulary import SECTION_TYPES
from studyapp.models import Assignment, Participant, Section, Study
from studyapp.participant.assignment import StudyUnavailable, plan_study, start_participant
from studyapp.staff.presets import PRESETS, create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def catalogue(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    return make_catalogue(settings.MEDIA_ROOT)


def started(study: Study, n: int = 1) -> list[Participant]:
    out = []
    for _ in range(n):
        p = Participant.objects.create(study=study, demographics_done=True)
        assert start_participant(p)
        out.append(p)
    return out


def test_presets_create_every_section_type(catalogue):
    study = create_study_from_preset("demo", "demo", plan="test", status="open")
    types = list(study.sections.order_by("order").values_list("section_type", flat=True))
    assert set(types) == set(SECTION_TYPES)
    for key in PRESETS:
        s = create_study_from_preset(key, f"s-{key.replace('_', '-')}", plan="test")
        assert s.sections.exists() and s.status == "draft"


def test_seed_recorded_and_no_clip_twice(catalogue):
    study = create_study_from_preset("demo", "demo", plan="test", status="open")
    (p,) = started(study)
    assert p.seed is not None
    rows = list(p.assignments.select_related("section"))
    reused = [a for a in rows if a.section.reuse_section_id]
    own = [a.clip_id for a in rows if not a.section.reuse_section_id]
    assert len(own) == len(set(own)), "a clip was shown twice outside a reuse section"
    # seed 000 section 3 shows exactly the clips of section 1
    s1 = study.sections.get(order=1)
    assert sorted(a.clip_id for a in reused) == sorted(a.clip_id for a in rows if a.section_id == s1.pk)
    # calling start again changes nothing
    assert not start_participant(p)
    assert p.assignments.count() == len(rows)


def test_plan_is_reproducible_from_the_seed(catalogue):
    study = create_study_from_preset("gait_ismar2020", "g", plan="test", status="open")
    a = [[it.clip.clip_id for it in items] for _, items in plan_study(study, 42, balanced=False)]
    b = [[it.clip.clip_id for it in items] for _, items in plan_study(study, 42, balanced=False)]
    c = [[it.clip.clip_id for it in items] for _, items in plan_study(study, 43, balanced=False)]
    assert a == b and a != c


def test_section_pools_follow_catalogue_fields(catalogue):
    study = create_study_from_preset("demo", "demo", plan="test", status="open")
    (p,) = started(study)
    for a in p.assignments.select_related("section", "clip"):
        t, clip = a.section.section_type, a.clip
        if t == "emotion_choice":
            assert clip.modality == "gait" and clip.origin == "generated" and not clip.is_transition and not clip.theme
        if t == "emotion_transition":
            assert clip.is_transition
        if t == "gesture_emotion":
            assert clip.modality == "gesture" and clip.origin == "generated"
        if t == "neutral_validation":
            assert clip.theme == "neutral"
        if t == "theme_rating":
            assert clip.theme and clip.weight > 0
        if t == "theme_inversion":
            assert clip.theme and clip.weight < 0


def test_naturalness_mixes_sources_without_their_generated_versions(catalogue):
    study = create_study_from_preset("gestures_ieeevr2021", "gest", plan="test", status="open")
    for p in started(study, 12):
        nat = list(p.assignments.filter(section__section_type="naturalness").select_related("clip"))
        origins = Counter(a.clip.origin for a in nat)
        assert origins == {"generated": 3, "source": 3}
        sources = {a.clip.clip_id for a in nat if a.clip.origin == "source"}
        assert not any(a.clip.source_clip_id in sources for a in nat if a.clip.origin == "generated")
        # all 12 clips of the two sections are distinct (seed 003 section 6.1)
        ids = list(p.assignments.values_list("clip_id", flat=True))
        assert len(ids) == 12 and len(set(ids)) == 12
    # the order is random per participant, not sources first
    orders = ["".join(a.clip.origin[0] for a in p.assignments.filter(section__section_type="naturalness")
                      .select_related("clip").order_by("position")) for p in Participant.objects.all()]
    assert len(set(orders)) > 1


def test_balanced_assignment(catalogue):
    study = create_study_from_preset("gait_ismar2020", "g", plan="test", status="open")
    section = study.sections.get(order=1)
    pool = 10      # gait_gen_00..09, 8 per participant
    started(study, 5)
    counts = Counter(Assignment.objects.filter(section=section).values_list("clip_id", flat=True))
    assert len(counts) == pool and sum(counts.values()) == 40
    assert max(counts.values()) - min(counts.values()) <= 1


def test_closed_study_refuses_start(catalogue):
    study = create_study_from_preset("demo", "demo", plan="test", status="closed")
    p = Participant.objects.create(study=study, demographics_done=True)
    with pytest.raises(StudyUnavailable, match="closed"):
        start_participant(p)


def test_reuse_must_come_before(catalogue):
    from django.core.exceptions import ValidationError

    study = create_study_from_preset("gait_ismar2020", "g", plan="test")
    first = study.sections.get(order=1)
    first.reuse_section = study.sections.get(order=3)
    with pytest.raises(ValidationError, match="before"):
        first.full_clean()
    bad = Section(study=study, order=9, section_type="naturalness", pool={"colour": "red"})
    with pytest.raises(ValidationError, match="colour"):
        bad.full_clean()


@pytest.mark.django_db(transaction=True)
def test_concurrent_starts_stay_balanced_and_within_limit(settings, tmp_path):
    """Threads start participants at once; row locks keep counts balanced and the limit exact. PostgreSQL only:
    the SQLite test database is one in-memory connection that threads cannot share (SQLite serialises writers)."""
    if connection.vendor != "postgresql":
        pytest.skip("concurrency test needs PostgreSQL (set DATABASE_URL)")
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("gait_ismar2020", "conc", plan="test", status="open", max_participants=7)
    people = [Participant.objects.create(study=study, demographics_done=True) for _ in range(10)]
    results: list[str] = []
    barrier = threading.Barrier(len(people))

    def run(p):
        barrier.wait()
        try:
            start_participant(p)
            results.append("ok")
        except StudyUnavailable:
            results.append("full")
        except Exception as exc:
            results.append(f"error: {exc!r}")
        finally:
            connection.close()

    threads = [threading.Thread(target=run, args=(p,)) for p in people]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert Counter(results) == {"ok": 7, "full": 3}
    section = study.sections.get(order=1)
    counts = Counter(Assignment.objects.filter(section=section).values_list("clip_id", flat=True))
    assert sum(counts.values()) == 7 * 8
    assert max(counts.values()) - min(counts.values()) <= 1
