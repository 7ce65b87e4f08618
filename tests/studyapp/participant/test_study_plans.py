"""Interface check with the renderer: the catalogue records of the built-in stimulus plans (made exactly as
`generate_clips` makes them, without rendering) fill every section of the matching study preset."""
from __future__ import annotations

import pytest

from generation.pipeline import runner as batch
from generation.plans.schema import load_plan
from studyapp.data.catalogue import upsert_clips
from studyapp.participant.assignment import plan_study
from studyapp.staff.presets import create_study_from_preset

pytestmark = pytest.mark.django_db

PAIRS = [("demo", "demo"), ("gait_ismar2020", "seed000"), ("gestures_ieeevr2021", "seed003"),
         ("rbf_thms2016", "seed004")]


def catalogue_plan(name: str) -> int:
    plan = load_plan(name)
    jobs, failures = batch.plan_jobs(plan)
    assert not failures
    pair_ids = {j.entry.id: j.clip_id for j in jobs}
    records = {j.clip_id: batch.base_record(j, plan, pair_ids, "clips/", False) for j in jobs}
    return upsert_clips(list(records.values()))


@pytest.mark.parametrize("preset,plan", PAIRS)
def test_preset_sections_filled_by_plan(preset, plan):
    assert catalogue_plan(plan) > 0
    study = create_study_from_preset(preset, "s", status="open")
    for section in study.sections.all():
        section.pool = dict(section.pool or {}, plan=plan)
        section.save()
    for seed in (1, 2, 3):
        for section, items in plan_study(study, seed):
            expected = section.clips_per_participant or None
            if section.reuse_section_id:
                expected = section.reuse_section.clips_per_participant
            assert items, f"{preset}: section {section.order} ({section.section_type}) got no clips from {plan}"
            if expected:
                assert len(items) == expected, (preset, section.section_type, len(items))
            if section.section_type == "naturalness":
                assert {it.clip.origin for it in items} == {"generated", "source"}
