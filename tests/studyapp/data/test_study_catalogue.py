"""Clip catalogue: idempotent upsert with clear errors, pool filters by catalogue fields."""
from __future__ import annotations

import pytest

from studyapp.data.catalogue import CatalogueError, pool_queryset, retire_superseded, upsert_clips
from studyapp.models import Clip

pytestmark = pytest.mark.django_db


def rec(**kw):
    base = {"clip_id": "c1", "modality": "gait", "origin": "generated", "happy": 0.5, "sad": "", "angry": None,
            "neutral": 0.5, "final_happy": "", "emotion_label": "", "theme": "", "weight": "", "n_features": "",
            "duration_s": 10, "video": "clips/abc.mp4", "webm": "", "poster": "clips/abc.png", "plan": "demo",
            "loop": True, "metadata": {"synthetic": True}}
    base.update(kw)
    return base


def test_upsert_is_idempotent_and_updates():
    assert upsert_clips([rec(), rec(clip_id="c2")]) == 2
    assert upsert_clips([rec(happy=0.25)]) == 1
    assert Clip.objects.count() == 2
    c = Clip.objects.get(clip_id="c1")
    assert c.happy == 0.25 and c.sad is None and c.loop and c.metadata == {"synthetic": True}
    assert c.final_happy is None and c.n_features is None and not c.is_transition


def test_source_clip_id_from_metadata():
    upsert_clips([rec(modality="gesture", metadata={"source_clip_id": "src7"})])
    assert Clip.objects.get().source_clip_id == "src7"


@pytest.mark.parametrize("bad,field", [({"modality": "dance"}, "modality"), ({"origin": ""}, "origin"),
                                       ({"happy": "lots"}, "happy"), ({"video": ""}, "video"),
                                       ({"video": "../x.mp4"}, "video"), ({"clip_id": ""}, "clip_id"),
                                       ({"n_features": "ten"}, "n_features")])
def test_bad_records_name_the_field_and_write_nothing(bad, field):
    with pytest.raises(CatalogueError, match=field):
        upsert_clips([rec(clip_id="ok"), rec(clip_id="bad", **bad) if "clip_id" not in bad else rec(**bad)])
    assert not Clip.objects.exists()


def test_pool_filters():
    upsert_clips([rec(clip_id="g1"), rec(clip_id="t1", final_happy=1, final_sad=0, final_angry=0, final_neutral=0),
                  rec(clip_id="r1", theme="sad", weight=0.7, n_features=4),
                  rec(clip_id="r2", theme="sad", weight=-0.7, n_features=10),
                  rec(clip_id="s1", origin="source")])
    ids = lambda pool: sorted(pool_queryset(pool).values_list("clip_id", flat=True))   # noqa: E731
    assert ids({"transition": True}) == ["t1"]
    assert ids({"origin": "generated", "transition": False, "rbf": False}) == ["g1"]
    assert ids({"rbf": True, "weight__lt": 0}) == ["r2"]
    assert ids({"n_features": [4, 10]}) == ["r1", "r2"]
    assert ids({"origin": "source"}) == ["s1"]
    with pytest.raises(CatalogueError, match="video"):
        pool_queryset({"video": "x"})


def test_pair_and_section_hints():
    upsert_clips([rec(clip_id="gen1", modality="gesture", pair="src1", sections=["gesture_emotion", "naturalness"]),
                  rec(clip_id="gen2", modality="gesture", metadata={"pair": "src2", "sections": "naturalness"})])
    a, b = Clip.objects.order_by("clip_id")
    assert (a.source_clip_id, b.source_clip_id) == ("src1", "src2")
    assert sorted(pool_queryset({"sections__contains": "gesture_emotion"}).values_list("clip_id", flat=True)) == [
        "gen1"]


def test_superseded_renders_are_retired_and_left_out_of_pools():
    """A generator change re-renders an entry under a new clip id: the old clip stays (answers refer to it) but
    no new participant is assigned it."""
    upsert_clips([rec(clip_id="old_a", metadata={"entry_id": "a"}), rec(clip_id="old_b", metadata={"entry_id": "b"}),
                  rec(clip_id="other_plan", plan="seed000", metadata={"entry_id": "a"})])
    upsert_clips([rec(clip_id="new_a", metadata={"entry_id": "a"})])
    # A partial run (one entry) retires only that entry's older render.
    assert retire_superseded("demo", {"new_a"}, entry_ids={"a"}) == 1
    assert set(pool_queryset({"modality": "gait"}).values_list("clip_id", flat=True)) == {
        "new_a", "old_b", "other_plan"}
    # A complete run retires every clip of the plan it did not produce, and nothing of other plans.
    assert retire_superseded("demo", {"new_a"}) == 1
    assert set(Clip.objects.filter(retired=True).values_list("clip_id", flat=True)) == {"old_a", "old_b"}
    # Rendering an entry again brings its clip back.
    upsert_clips([rec(clip_id="old_b", metadata={"entry_id": "b"})])
    assert not Clip.objects.get(clip_id="old_b").retired


def test_presets_draw_clips_of_their_own_plan_only():
    """A demo clip in the same catalogue never enters a paper preset's pools, and the demo keeps to its own."""
    from studyapp.staff.presets import PRESET_PLANS, PRESETS, create_study_from_preset

    assert set(PRESET_PLANS) == set(PRESETS)
    upsert_clips([rec(clip_id="demo_walk", plan="demo"), rec(clip_id="paper_walk", plan="seed000"),
                  rec(clip_id="demo_src", plan="demo", origin="source"),
                  rec(clip_id="paper_src", plan="seed000", origin="source")])
    for preset, plan in PRESET_PLANS.items():
        study = create_study_from_preset(preset, f"s-{preset}")
        for section in study.sections.filter(reuse_section__isnull=True):
            assert section.pool["plan"] == plan, (preset, section.section_type)
            pooled = set(pool_queryset(section.pool).values_list("plan", flat=True))
            assert pooled <= {plan}, (preset, section.section_type, pooled)
    paper = create_study_from_preset("gait_ismar2020", "paper").sections.get(section_type="emotion_choice")
    demo = create_study_from_preset("demo", "demo").sections.get(section_type="emotion_choice")
    assert set(pool_queryset(paper.pool).values_list("clip_id", flat=True)) == {"paper_walk"}
    assert set(pool_queryset(demo.pool).values_list("clip_id", flat=True)) == {"demo_walk"}
