"""Per-clip quality record: measures, thresholds, plan `qa:` blocks, clips.csv columns, old files."""
from __future__ import annotations

import csv
import dataclasses

import numpy as np
import pytest

from generation.pipeline.plan_qa import summary_line
from generation.plans.catalogue import read_clips_csv, write_clips_csv
from generation.plans.schema import PlanError, validate_plan
from generation.quality import QAThresholdError, evaluate, failed_checks, motion_metrics, resolve_thresholds
from generation.quality.metrics import bone_error_mm, mean_jerk
from generation.quality.observer import GaitObserver
from protocol.vocabulary import CLIP_BODY_COLUMNS, CLIP_COLUMNS, CLIP_PROVENANCE_COLUMNS, QA_COLUMNS, QA_THRESHOLDS
from tests.test_render import seated, swinging_walk


def sunk(motion, depth_m: float):
    """The same motion lowered by ``depth_m`` (feet through the floor)."""
    return dataclasses.replace(motion, root_positions=motion.root_positions - [0.0, depth_m, 0.0])


def test_walk_on_the_floor_passes_and_sunk_walk_is_flagged():
    walk = swinging_walk(T=40, fps=30.0)
    floor = walk.positions()[..., 1].min()
    walk = sunk(walk, floor)                      # lowest joint exactly on y = 0
    ok = evaluate(walk, figure_height_frac=0.7)
    assert ok.values["penetration_cm"] == pytest.approx(0.0, abs=1e-6)
    assert "penetration" not in ok.flags
    bad = evaluate(sunk(walk, 0.05), figure_height_frac=0.7)
    assert bad.values["penetration_cm"] == pytest.approx(5.0, abs=1e-3)
    assert "penetration" in bad.flags and bad.flag.split(";") == bad.flags


def test_jerk_grows_with_jitter_and_bone_error_sees_stretched_bones():
    walk = swinging_walk(T=60, fps=30.0)
    P = walk.positions()
    smooth = mean_jerk(P, 30.0)
    jitter = P + np.random.default_rng(0).normal(0, 0.005, P.shape)
    assert mean_jerk(jitter, 30.0) > smooth + 300
    assert bone_error_mm(P, walk.skeleton) < 1e-6
    stretched = P.copy()
    stretched[:, walk.skeleton.index("left_knee")] += [0.0, -0.02, 0.0]   # thigh 2 cm longer
    assert bone_error_mm(stretched, walk.skeleton) > 5.0
    assert set(motion_metrics(walk)) == {"foot_skate_cm_s", "penetration_cm", "jerk", "bone_error_mm"}


def test_figure_height_threshold_depends_on_seated():
    walk = swinging_walk(T=20, fps=30.0)
    walk = sunk(walk, walk.positions()[..., 1].min())
    assert "figure_height" in evaluate(walk, figure_height_frac=0.45).flags
    assert "figure_height" not in evaluate(walk, figure_height_frac=0.55).flags
    sit = seated(T=20, fps=30.0)
    assert "figure_height" in evaluate(sit, figure_height_frac=0.55, seated=True).flags
    assert "figure_height" not in evaluate(walk, figure_height_frac=None).flags   # not rendered: not checked


class _FakeObserver(GaitObserver):
    """A gait observer with a fixed reading (the real one's reads/read, no training)."""

    def __init__(self, label, p):
        self.label, self.p = label, p

    def observe(self, motion):
        return self.label, self.p


def test_observer_mismatch_only_when_confident_and_intended():
    walk = swinging_walk(T=20, fps=30.0)
    walk = sunk(walk, walk.positions()[..., 1].min())
    happy = [1.0, 0.0, 0.0, 0.0]
    res = evaluate(walk, intended=happy, observer=_FakeObserver("sad", 0.95))
    assert res.values["observed"] == "sad" and res.values["observed_p"] == 0.95
    assert "observer" in res.flags
    assert "observer" not in evaluate(walk, intended=happy, observer=_FakeObserver("sad", 0.6)).flags
    assert "observer" not in evaluate(walk, intended=happy, observer=_FakeObserver("happy", 0.99)).flags
    assert "observer" not in evaluate(walk, intended=None, observer=_FakeObserver("sad", 0.99)).flags
    mixed = [0.4, 0.3, 0.3, 0.0]                                            # no dominant emotion
    assert "observer" not in evaluate(walk, intended=mixed, observer=_FakeObserver("sad", 0.99)).flags


def test_thresholds_from_the_plan_override_and_switch_off():
    th = resolve_thresholds({"penetration_cm": 10, "jerk": None})
    assert th["penetration_cm"] == 10.0 and th["jerk"] is None
    assert th["foot_skate_cm_s"] == QA_THRESHOLDS["foot_skate_cm_s"]
    values = {"penetration_cm": 5.0, "jerk": 1e6, "foot_skate_cm_s": 0.0, "bone_error_mm": 0.0}
    assert failed_checks(values, th) == []
    assert failed_checks(values) == ["penetration", "jerk"]
    with pytest.raises(QAThresholdError, match="qa.skate"):
        resolve_thresholds({"skate": 1})
    with pytest.raises(QAThresholdError, match="qa.jerk"):
        resolve_thresholds({"jerk": "high"})


def test_plan_qa_block_is_validated():
    clip = {"id": "a", "generator": "neutral_walk"}
    plan = validate_plan({"name": "p", "qa": {"jerk": 900}, "clips": [clip]})
    assert plan.qa == {"jerk": 900}
    with pytest.raises(PlanError, match="qa.wobble"):
        validate_plan({"name": "p", "qa": {"wobble": 1}, "clips": [clip]})


def _record(clip_id, flag="", skate=0.5):
    rec = {c: None for c in CLIP_COLUMNS}
    rec.update(clip_id=clip_id, modality="gait", origin="generated", happy=1.0, sad=0.0, angry=0.0, neutral=0.0,
               duration_s=2.0)
    rec["qa"] = {"foot_skate_cm_s": skate, "penetration_cm": 0.0, "jerk": 100.0, "bone_error_mm": 0.0,
                 "figure_height_frac": 0.6, "observed": "happy", "observed_p": 0.8, "flag": flag}
    return rec


def test_clips_csv_has_qa_columns_after_the_public_ones(tmp_path):
    path = tmp_path / "clips.csv"
    write_clips_csv([_record("a"), _record("b", "foot_skate", 9.0)], path)
    header = path.read_text().splitlines()[0].split(",")
    assert tuple(header) == (*CLIP_COLUMNS, *QA_COLUMNS, *CLIP_PROVENANCE_COLUMNS, *CLIP_BODY_COLUMNS)
    rows = {r["clip_id"]: r for r in read_clips_csv(path)}
    assert rows["b"]["qa_flag"] == "foot_skate" and rows["b"]["qa_foot_skate_cm_s"] == 9.0
    assert rows["a"]["qa_flag"] == "" and rows["a"]["qa_observed"] == "happy"
    write_clips_csv([_record("c")], path)            # merging keeps the old rows' qa cells
    rows = {r["clip_id"]: r for r in read_clips_csv(path)}
    assert rows["b"]["qa_flag"] == "foot_skate" and set(rows) == {"a", "b", "c"}


def _old_csv(path):
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(CLIP_COLUMNS)
        rec = _record("old")
        w.writerow(["" if rec[c] is None else rec[c] for c in CLIP_COLUMNS])
    return path


def test_old_clips_csv_without_qa_columns_still_reads(tmp_path):
    from analysis.io import read_clips

    path = _old_csv(tmp_path / "clips.csv")
    rows = read_clips_csv(path)
    assert rows[0]["clip_id"] == "old" and rows[0]["qa_flag"] == "" and rows[0]["qa_jerk"] is None
    df = read_clips(path)
    assert "old" in df.index and "qa_flag" not in df.columns
    new = tmp_path / "new.csv"
    write_clips_csv([_record("b", "foot_skate", 9.0)], new)
    df = read_clips(new)
    assert df.loc["b", "qa_flag"] == "foot_skate" and df.loc["b", "qa_foot_skate_cm_s"] == 9.0
    assert df.attrs["ignored_columns"] == []          # the provenance columns are known (and not needed)


def test_summary_line_counts_clips_per_flag():
    line = summary_line(["", "", "penetration", "penetration;jerk"])
    assert line == "QA: 2 passed, 2 flagged (penetration 2, jerk 1)"


def test_unread_line_says_which_clips_got_no_observer_reading():
    from generation.pipeline.plan_qa import unread_line

    read = [{"modality": "gait", "qa": {"observed": "sad"}}, {"modality": "gesture", "qa": {"observed": "proud"}},
            {"modality": "rbf", "qa": {}}]
    assert unread_line(read) == ""
    unread = read + [{"modality": "gait", "qa": {"observed": None}}, {"modality": "gait"},
                     {"modality": "gesture", "qa": {"observed": None}}]
    line = unread_line(unread, "synthetic")
    assert line.startswith("QA: no observer reading")
    assert "2 gait clip(s)" in line and "build_corpus" in line and "1 gesture clip(s)" in line
    real = unread_line(unread)                       # the real-capture observer is the default
    assert "2 gait clip(s) (no real-capture observer" in real and "generation/data/mocap/bandai-namco" in real
    perceived = unread_line(unread, "real-perceived")
    assert "2 gait clip(s) (the perceived-label observer needs both real corpora" in perceived
    assert "build_corpus" not in perceived
