"""Quality flags in the study app: Clip.qa/qa_flag from records, flagged clips out of pools unless a pool
includes them, the admin filter, generate_clips' summary, and rendering on a Dask cluster."""
from __future__ import annotations

import dataclasses
import io

import pytest
import yaml
from django.core.management import call_command

from generation.plans.catalogue import read_clips_csv
from protocol.pools import pool_errors
from studyapp.data.catalogue import CatalogueError, pool_queryset, upsert_clips
from studyapp.models import Clip


def rec(clip_id, flag="", **kw):
    base = {"clip_id": clip_id, "modality": "gait", "origin": "generated", "happy": 1.0, "sad": 0, "angry": 0,
            "neutral": 0, "duration_s": 2, "video": f"clips/{clip_id}.mp4", "poster": f"clips/{clip_id}.png",
            "plan": "qa", "metadata": {}, "qa": {"penetration_cm": 4.0 if flag else 0.0, "flag": flag}}
    base.update(kw)
    return base


@pytest.mark.django_db
def test_flagged_clip_stays_out_of_pools_unless_included():
    upsert_clips([rec("good"), rec("sunk", "penetration"), rec("both", "penetration;jerk")])
    sunk = Clip.objects.get(clip_id="sunk")
    assert sunk.qa_flag == "penetration" and sunk.qa == {"penetration_cm": 4.0}
    assert set(pool_queryset({"modality": "gait"}).values_list("clip_id", flat=True)) == {"good"}
    included = pool_queryset({"modality": "gait", "include_flagged": True})
    assert set(included.values_list("clip_id", flat=True)) == {"good", "sunk", "both"}
    assert pool_queryset({"include_flagged": False}).count() == 1
    assert pool_queryset({}, include_flagged=True).count() == 3       # a sub-pool narrows an including pool
    upsert_clips([rec("sunk")])                                         # re-rendered and fixed: back in pools
    assert pool_queryset({}).count() == 2


@pytest.mark.django_db
def test_advisory_realism_flag_keeps_a_clip_in_pools_that_keep_advisory_flags():
    upsert_clips([rec("real_like", "realism"), rec("off_emotion", "observer;realism"), rec("good")])
    assert set(pool_queryset({"modality": "gait"}).values_list("clip_id", flat=True)) == {"good"}
    kept = pool_queryset({"modality": "gait", "keep_advisory": True})
    assert set(kept.values_list("clip_id", flat=True)) == {"real_like", "good"}
    flagged = pool_queryset({"modality": "gait", "include_flagged": True})
    assert set(flagged.values_list("clip_id", flat=True)) == {"real_like", "off_emotion", "good"}


@pytest.mark.django_db
def test_observer_advisory_pool_keeps_observer_flags_but_not_other_failures():
    upsert_clips([rec("off_emotion", "observer"), rec("off_and_real", "observer;realism"),
                  rec("sunk_off", "penetration;observer"), rec("good")])
    plain = pool_queryset({"modality": "gait"})
    assert set(plain.values_list("clip_id", flat=True)) == {"good"}
    candidates = pool_queryset({"modality": "gait", "observer_advisory": True})
    assert set(candidates.values_list("clip_id", flat=True)) == {"off_emotion", "good"}
    both = pool_queryset({"modality": "gait", "observer_advisory": True, "keep_advisory": True})
    assert set(both.values_list("clip_id", flat=True)) == {"off_emotion", "off_and_real", "good"}


def test_include_flagged_and_observer_advisory_are_boolean_pool_switches():
    assert pool_errors({"include_flagged": True, "observer_advisory": False, "modality": "gait"}) == []
    assert any("include_flagged" in e for e in pool_errors({"include_flagged": "yes"}))
    assert any("observer_advisory" in e for e in pool_errors({"observer_advisory": 1}))


@pytest.mark.django_db
def test_unknown_check_in_a_record_is_refused():
    with pytest.raises(CatalogueError, match="qa_flag"):
        upsert_clips([rec("x", "wobbly")])


@pytest.mark.django_db
def test_admin_filter_passed_flagged_and_per_check(rf):
    from django.contrib.admin.sites import site

    from studyapp.admin.clip_qa import QualityFlagFilter, quality_flag

    upsert_clips([rec("good"), rec("sunk", "penetration"), rec("both", "penetration;jerk"), rec("j", "jerk")])
    admin_obj = site._registry[Clip]

    def ids(value):
        f = QualityFlagFilter(rf.get("/"), {"qa": [value]} if value else {}, Clip, admin_obj)
        return set(f.queryset(None, Clip.objects.all()).values_list("clip_id", flat=True))

    assert ids("passed") == {"good"}
    assert ids("flagged") == {"sunk", "both", "j"}
    assert ids("penetration") == {"sunk", "both"}
    assert ids("jerk") == {"both", "j"}
    assert ids(None) == {"good", "sunk", "both", "j"}
    assert quality_flag(Clip.objects.get(clip_id="both")) == "penetration, jerk"
    assert QualityFlagFilter in admin_obj.list_filter


@pytest.mark.django_db
def test_admin_observer_column_shows_label_probability_and_gesture_arousal():
    from django.contrib.admin.sites import site

    from studyapp.admin.clip_qa import observer_reading

    gait, gesture, blank = Clip(qa={"observed": "sad", "observed_p": 0.8123}), Clip(
        qa={"observed": "afraid", "observed_p": 0.55, "observed_arousal": 0.712}), Clip(qa={"observed": None})
    assert observer_reading(gait) == "sad 0.81"
    assert observer_reading(gesture) == "afraid 0.55, arousal 0.71"
    assert observer_reading(blank) == "" and observer_reading(Clip()) == ""
    assert observer_reading in site._registry[Clip].list_display


TINY = {"width": 160, "height": 120, "fps": 10, "duration_s": 1.0}
PLAN_CLIPS = [
    {"id": "walk_ok", "generator": "procedural_walk", "emotion": [0, 0, 0, 1],
     "trajectory": {"kind": "straight", "length_m": 3}, "seed": 1},
    {"id": "walk_sunk", "generator": "procedural_walk", "emotion": [0, 0, 0, 1],
     "trajectory": {"kind": "straight", "length_m": 3}, "seed": 2},
]


def _sink_entry(monkeypatch, entry_id: str, depth_m: float = 0.05):
    """Make ``entry_id``'s motion go ``depth_m`` through the floor (the generator's output, lowered), where the
    plan runner calls it."""
    from generation.pipeline import runner

    original = runner.make_motion

    def make_motion(entry, *args, **kwargs):
        motion = original(entry, *args, **kwargs)
        if entry.id == entry_id:
            motion = dataclasses.replace(motion, root_positions=motion.root_positions - [0.0, depth_m, 0.0])
        return motion

    monkeypatch.setattr(runner, "make_motion", make_motion)


@pytest.mark.django_db
def test_generate_clips_flags_feet_through_the_floor_and_prints_a_summary(settings, tmp_path, monkeypatch):
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.DATA_DIR = tmp_path / "data"
    plan = tmp_path / "qa.yaml"
    from generation.quality.realism_ranges import threshold_keys

    no_realism = {k: None for k in threshold_keys()}    # this test is about the floor: procedural walks crouch
    plan.write_text(yaml.safe_dump({"name": "qa", "render": TINY, "clips": PLAN_CLIPS, "qa": no_realism}))
    _sink_entry(monkeypatch, "walk_sunk")
    out = io.StringIO()
    call_command("generate_clips", "--plan", str(plan), "--no-progress", stdout=out, stderr=io.StringIO())
    assert "QA: 1 passed, 1 flagged (penetration 1)" in out.getvalue()
    rows = {r["qa_flag"]: r for r in read_clips_csv(tmp_path / "media" / "clips.csv")}
    assert set(rows) == {"", "penetration"}
    assert rows["penetration"]["qa_penetration_cm"] == pytest.approx(5.0, abs=0.6)
    assert rows[""]["qa_observed"] in ("happy", "sad", "angry", "neutral", "")
    sunk = Clip.objects.get(qa_flag="penetration")
    assert sunk.metadata["entry_id"] == "walk_sunk" and sunk.qa["penetration_cm"] > 4
    assert list(pool_queryset({"plan": "qa"}).values_list("metadata__entry_id", flat=True)) == ["walk_ok"]
    # A rerun renders nothing; a plan threshold that tolerates the depth re-checks the stored record.
    plan.write_text(yaml.safe_dump({"name": "qa", "render": TINY, "clips": PLAN_CLIPS,
                                    "qa": {"penetration_cm": 10, **no_realism}}))
    out = io.StringIO()
    call_command("generate_clips", "--plan", str(plan), "--no-progress", stdout=out, stderr=io.StringIO())
    assert "0 rendered, 2 already done" in out.getvalue() and "QA: 2 passed, 0 flagged" in out.getvalue()
    assert Clip.objects.filter(plan="qa").exclude(qa_flag="").count() == 0


def test_run_plan_on_a_dask_cluster_then_resumes_locally(tmp_path):
    from distributed import Client, LocalCluster

    from generation.pipeline.runner import run_plan
    from generation.plans.schema import validate_plan

    plan = validate_plan({"name": "dask", "render": TINY, "clips": [
        PLAN_CLIPS[0], {"id": "sit", "generator": "procedural_gesture", "origin": "source", "emotion_label": "sad",
                        "duration_s": 1.0, "seed": 3}]})
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        result = run_plan(plan, tmp_path / "clips", tmp_path / "records", scheduler=client)
    assert not result.failed and len(result.rendered) == 2
    assert sorted(p.suffix for p in (tmp_path / "clips").iterdir()) == [".mp4", ".mp4", ".png", ".png"]
    assert all("qa" in r and r["duration_s"] > 0 for r in result.records)
    again = run_plan(plan, tmp_path / "clips", tmp_path / "records")          # resumable across back-ends
    assert again.rendered == [] and len(again.skipped) == 2


def test_contact_sheet_caption_names_failed_checks():
    from studyapp.data.catalogue import clip_label

    meta = {"entry_id": "walk_sunk", "generator": "procedural_walk"}
    assert clip_label({"clip_id": "x", "origin": "generated", "metadata": meta, "qa_flag": "penetration;jerk"}) == \
        "walk_sunk | generated | procedural_walk | QA: penetration, jerk"
    assert clip_label({"clip_id": "x", "origin": "generated", "metadata": meta}) == \
        "walk_sunk | generated | procedural_walk"
