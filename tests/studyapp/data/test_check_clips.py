"""Attention checks never show a clip the participant rates: spare pool clips, a dedicated check clip or the
practice clip, else fewer checks; the admin refuses a section whose checks would find no such clip."""
from __future__ import annotations

import pytest

from protocol.pools import options_errors
from protocol.presets import PRESETS
from protocol.vocabulary import ATTENTION_CHECK
from studyapp.data.catalogue import pool_queryset
from studyapp.data.check_clips import check_clip_problems
from studyapp.models import Clip, Participant, Study
from studyapp.participant.assignment import start_participant
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue, section_form_errors

pytestmark = pytest.mark.django_db


@pytest.fixture
def catalogue(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)


def _checks_never_rated(study: Study, n: int = 8) -> int:
    """Start n participants; assert no check clip is a clip the participant rates; the number of checks given."""
    checks = 0
    for _ in range(n):
        p = Participant.objects.create(study=study, demographics_done=True)
        start_participant(p)
        rated = set(p.assignments.filter(kind="").values_list("clip_id", flat=True))
        mine = list(p.assignments.filter(kind=ATTENTION_CHECK).values_list("clip_id", flat=True))
        assert not rated & set(mine), "a check shows a clip the participant rates"
        checks += len(mine)
    return checks


def test_section_with_no_spare_clip_is_refused_with_what_to_add(catalogue):
    study = create_study_from_preset("gait_ismar2020", "g", plan="test")
    section = study.sections.get(order=1)
    size = pool_queryset(section.pool).count()
    section.clips_per_participant = size                       # every clip of the pool is rated
    section.options = {"attention_checks": {"answer": "sad"}}
    message = " ".join(section_form_errors(section)["options"])
    assert "spare pool clips: 0" in message and "practice" in message and "attention_checks.clip" in message
    section.options = {"attention_checks": {"answer": "sad"}, "practice": True}
    assert section_form_errors(section) == {}                  # the practice clip serves as the check clip
    section.options = {"attention_checks": {"answer": "sad", "count": 2}, "practice": True}
    assert "options" in section_form_errors(section)
    section.clips_per_participant = size - 1
    assert section_form_errors(section) == {}                  # one spare + the practice clip


def test_reusing_section_counts_the_reused_pool(catalogue):
    study = create_study_from_preset("gait_ismar2020", "g", plan="test")
    likert = study.sections.get(section_type="affect_likert")
    source = likert.reuse_section
    source.clips_per_participant = 0
    source.save()
    likert.refresh_from_db()
    likert.options = {"attention_checks": {"answer": "2", "question": "pace"}}
    assert check_clip_problems(likert)
    source.clips_per_participant = pool_queryset(source.pool).count() - 1
    source.save()
    likert.refresh_from_db()
    likert.options = {"attention_checks": {"answer": "2", "question": "pace"}}
    assert check_clip_problems(likert) == []


def test_dedicated_check_clip_used_and_never_rated(catalogue):
    study = create_study_from_preset("gait_ismar2020", "g", plan="test", status="open")
    section = study.sections.get(order=1)
    pool = set(pool_queryset(section.pool).values_list("pk", flat=True))
    outside = Clip.objects.filter(modality="gait").exclude(theme="").order_by("clip_id").first()   # in no pool
    inside = Clip.objects.get(pk=min(pool))
    transition = Clip.objects.filter(modality="gait", final_happy__isnull=False).first()           # section 2's
    section.options = {"attention_checks": {"answer": "sad", "clip": transition.clip_id}}
    assert "in the pool of section 2" in " ".join(section_form_errors(section)["options"])
    section.clips_per_participant = 0
    section.options = {"attention_checks": {"answer": "sad", "clip": inside.clip_id}}
    assert "is in this section's pool" in " ".join(section_form_errors(section)["options"])
    section.options = {"attention_checks": {"answer": "sad", "clip": "no-such-clip"}}
    assert "not a usable clip" in " ".join(section_form_errors(section)["options"])
    section.options = {"attention_checks": {"answer": "sad", "clip": outside.clip_id}}
    assert section_form_errors(section) == {}
    section.save()
    assert _checks_never_rated(study, 3) == 3
    assert set(study.participants.first().assignments.filter(kind=ATTENTION_CHECK)
               .values_list("clip__clip_id", flat=True)) == {outside.clip_id}
    assert options_errors("emotion_choice", {"attention_checks": {"answer": "sad", "clip": ""}})


def test_no_rated_clip_even_when_the_section_was_saved_without_the_admin(catalogue):
    """A section stored without full_clean (a script, an old row) gets fewer checks, never a rated clip."""
    study = create_study_from_preset("demo", "d", plan="test", status="open")
    for section in study.sections.all():
        section.options = {**section.options, "attention_checks": {"answer": "1" if "theme" in
                                                                   section.section_type else "sad"}}
        if section.section_type in ("affect_likert", "naturalness", "theme_inversion"):
            section.options["attention_checks"] = {"answer": "2" if section.section_type != "theme_inversion"
                                                   else "0"}
        if section.section_type == "neutral_validation":
            section.options["attention_checks"] = {"answer": "happy"}
        if section.section_type == "gesture_emotion":
            section.options["attention_checks"] = {"answer": "proud"}
        section.save()
    assert _checks_never_rated(study, 6) > 0


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_presets_ship_what_their_checks_need(catalogue, preset):
    study = create_study_from_preset(preset, f"p-{preset}", plan="test")
    for section in study.sections.all():
        assert section_form_errors(section) == {}      # the admin refuses checks that would find no clip
    if any((s.options or {}).get("attention_checks") for s in study.sections.all()):
        study.status = Study.Status.OPEN
        study.save()
        assert _checks_never_rated(study, 4) > 0
