"""Realism measures on constructed gait motions with known answers; realism bounds, plan overrides and clips.csv."""
from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from generation.core.features import foot_skate
from generation.core.motion import Motion
from generation.core.skeleton import gait_skeleton
from generation.plans.catalogue import read_clips_csv, write_clips_csv
from generation.plans.schema import PlanError, validate_plan
from generation.quality import QAThresholdError, evaluate, failed_checks, gait_observer_kind, resolve_thresholds
from generation.quality.realism import MEASURES, foot_floor, knee_flexion_deg, realism_measures
from generation.quality.realism_ranges import (
    compute_ranges,
    out_of_range,
    realism_thresholds,
    threshold_keys,
)
from protocol.vocabulary import CLIP_COLUMNS, QA_COLUMNS, QA_REALISM_COLUMNS

FPS = 30.0
SK = gait_skeleton()


def standing(T: int, root_xz=None, knee_deg: float = 0.0, root_y=None) -> Motion:
    """The rest pose (toes on y = 0) for T frames; the root moves along ``root_xz`` (T, 2) and ``root_y`` (T,)
    (offsets from standing height); both knees bent by ``knee_deg`` about the x axis."""
    rot = np.zeros((T, SK.num_joints, 4))
    rot[..., 0] = 1.0
    if knee_deg:
        half = math.radians(knee_deg) / 2
        for name in ("left_knee", "right_knee"):
            rot[:, SK.index(name)] = [math.cos(half), math.sin(half), 0.0, 0.0]
    root = np.zeros((T, 3))
    if root_xz is not None:
        root[:, [0, 2]] = root_xz
    m = Motion(SK, rot, root, FPS, {})
    lift = -m.positions()[..., 1].min()                      # put the lowest joint on the floor
    root[:, 1] += lift + (0.0 if root_y is None else root_y)
    return Motion(SK, rot, root, FPS, {})


def sliding(speed_m_s: float, T: int = 90) -> Motion:
    """The whole body (feet on the floor) gliding along +z at ``speed_m_s``."""
    z = np.arange(T) * speed_m_s / FPS
    return standing(T, np.stack([np.zeros(T), z], -1))


def test_a_foot_sliding_on_the_floor_is_in_contact_and_skates_at_its_speed():
    slow = realism_measures(sliding(0.3))
    assert slow["skate_cm_s"] == pytest.approx(30.0, rel=1e-6)
    assert slow["toe_skim"] == 0.0 and slow["skate_ratio"] == 0.0      # 0.3 m/s is below the 0.5 m/s skim speed
    fast_motion = sliding(0.8)
    fast = realism_measures(fast_motion)
    assert fast["skate_cm_s"] == pytest.approx(80.0, rel=1e-6)
    assert fast["toe_skim"] == 1.0 and fast["skate_ratio"] == 1.0
    _, _, near = foot_floor(fast_motion.positions(), FPS, SK)
    assert near.all()                                                     # sliding, and on the floor all along
    # the speed-gated stance detector behind qa_foot_skate_cm_s sees no contact at all: it misses the slide
    old = foot_skate(fast_motion.positions(), FPS, SK)
    assert old["n_contact_frames"] == 0 and old["mean_m_s"] == 0.0


def test_a_planted_foot_does_not_skate_and_a_lifted_one_is_not_near_the_floor():
    still = realism_measures(standing(60))
    assert still["skate_cm_s"] == 0.0 and still["toe_skim"] == 0.0
    T = 60
    m = standing(T)
    P = m.positions().copy()
    left_foot = [SK.index("left_heel"), SK.index("left_toe")]
    P[T // 2:, left_foot, 1] += 0.10                                       # left foot 10 cm up for the second half
    P[T // 2:, left_foot, 2] += np.arange(T - T // 2)[:, None] * 1.0 / FPS   # and swinging at 1 m/s
    _, speed, near = foot_floor(P, FPS, SK)
    assert near[: T // 2 - 1, 0].all() and not near[T // 2:, 0].any() and near[:, 1].all()
    assert speed[T // 2:, 0] == pytest.approx(1.0)


@pytest.mark.parametrize("bend", [0.0, 20.0, 45.0])
def test_stance_knee_flexion_is_the_bend_of_the_knee(bend):
    rest = math.degrees(math.atan2(0.02, 0.41))           # the gait skeleton's shin leans back 2 cm over 41 cm
    m = standing(40, knee_deg=bend)
    assert knee_flexion_deg(m.positions(), SK) == pytest.approx(bend + rest, abs=1e-6)
    assert realism_measures(m)["stance_knee_deg"] == pytest.approx(bend + rest, abs=1e-6)


def test_pelvis_bounce_is_the_peak_to_peak_of_the_step_oscillation():
    T = 180
    t = np.arange(T) / FPS
    drift = 0.05 * t / t[-1]                                   # a slow 5 cm rise over 6 s is trend, not bounce
    m = standing(T, root_y=0.02 * np.sin(2 * np.pi * 2.0 * t) + drift)
    assert realism_measures(m)["pelvis_bounce_cm"] == pytest.approx(4.0, abs=0.15)
    assert realism_measures(standing(T))["pelvis_bounce_cm"] == pytest.approx(0.0, abs=1e-9)


def test_speed_variability_of_constant_and_changing_walking_speed():
    T = 240
    steady = realism_measures(sliding(1.2, T))["speed_cv"]
    assert steady == pytest.approx(0.0, abs=1e-9)
    v = np.where(np.arange(T) < T // 2, 1.0, 2.0)              # 1 m/s for 4 s, then 2 m/s
    z = np.concatenate([[0.0], np.cumsum(v[1:] / FPS)])
    cv = realism_measures(standing(T, np.stack([np.zeros(T), z], -1)))["speed_cv"]
    assert cv == pytest.approx(1 / 3, abs=0.04)               # window means ~1 and ~2: std/mean = 0.5/1.5
    assert realism_measures(standing(T))["speed_cv"] is None    # a body that does not walk has no walking speed


def test_realism_bounds_come_from_one_file_and_plans_override_them():
    th = resolve_thresholds()
    assert set(threshold_keys()) <= set(th) and th == {**th, **realism_thresholds()}
    assert "observer" not in th                                  # the observer kind is no threshold
    values = {"pelvis_bounce_cm": th["pelvis_bounce_cm_max"] + 5, "speed_cv": th["speed_cv_min"] / 2,
              "stance_knee_deg": 170.0}
    assert out_of_range(values, th) == [f"stance_knee_deg>{th['stance_knee_deg_max']:g}",
                                        f"pelvis_bounce_cm>{th['pelvis_bounce_cm_max']:g}",
                                        f"speed_cv<{th['speed_cv_min']:g}"]
    assert "realism" in failed_checks(values, th)
    relaxed = resolve_thresholds({"pelvis_bounce_cm_max": None, "speed_cv_min": 0, "stance_knee_deg_max": None,
                                  "observer": "synthetic"})
    assert "realism" not in failed_checks(values, relaxed) and "observer" not in relaxed
    assert gait_observer_kind({"observer": "synthetic"}) == "synthetic" and gait_observer_kind({}, "real") == "real"
    assert out_of_range(values, resolve_thresholds({"stance_knee_deg_max": 60})) == [
        "stance_knee_deg>60", f"pelvis_bounce_cm>{th['pelvis_bounce_cm_max']:g}", f"speed_cv<{th['speed_cv_min']:g}"]
    with pytest.raises(QAThresholdError, match="qa.observer"):
        resolve_thresholds({"observer": "human"})
    with pytest.raises(QAThresholdError, match="default gait observer"):
        gait_observer_kind(None, "human")
    with pytest.raises(QAThresholdError, match="qa.knee"):
        resolve_thresholds({"knee": 3})
    plan = {"name": "p", "clips": [{"id": "a", "generator": "procedural_walk", "emotion": [1, 0, 0, 0]}]}
    assert validate_plan({**plan, "qa": {"pelvis_bounce_cm_min": 0.5, "observer": "real"}}).qa["observer"] == "real"
    with pytest.raises(PlanError, match="qa.pelvis_bounce_cm_min"):
        validate_plan({**plan, "qa": {"pelvis_bounce_cm_min": "low"}})


def test_compute_ranges_takes_percentiles_of_the_training_takes_and_counts_flagged_test_takes():
    rng = np.random.default_rng(0)
    rows = [{"style": "a" if i % 2 else "b", "split": "train",
             **{m: float(v) for m, v in zip(MEASURES, rng.uniform(1, 2, len(MEASURES)))}} for i in range(200)]
    rows += [{"style": "a", "split": "test", **dict.fromkeys(MEASURES, 10.0)},
             {"style": "a", "split": "test", **dict.fromkeys(MEASURES, 1.5)}]
    out = compute_ranges(rows)
    assert 1.0 <= out["thresholds"]["stance_knee_deg_min"] < 1.05 and 1.95 < out["thresholds"]["skate_cm_s_max"] <= 2
    assert "skate_cm_s_min" not in out["thresholds"] and out["n_train"] == 200
    assert out["test_flagged_share"] == 0.5 and set(out["per_style"]) == {"a", "b"}


def test_quality_record_has_realism_columns_and_old_clips_csv_still_reads(tmp_path):
    res = evaluate(sliding(0.8))
    assert set(MEASURES) <= set(res.values) and res.values["toe_skim"] == 1.0
    assert QA_COLUMNS[-len(QA_REALISM_COLUMNS) - 1:] == (*QA_REALISM_COLUMNS, "qa_observer")
    old = tmp_path / "old.csv"
    with old.open("w", newline="") as f:                 # a catalogue written before the realism columns existed
        w = csv.writer(f)
        w.writerow([*CLIP_COLUMNS, "qa_foot_skate_cm_s", "qa_flag"])
        w.writerow(["c1", "gait", "generated", *[""] * (len(CLIP_COLUMNS) - 3), "1.5", "penetration"])
    row = read_clips_csv(old)[0]
    assert row["qa_foot_skate_cm_s"] == 1.5 and row["qa_skate_ratio"] is None and row["qa_observer"] == ""
    rec = {**{c: None for c in CLIP_COLUMNS}, "clip_id": "c2", "modality": "gait", "origin": "generated",
           "qa": res.as_dict()}
    rows = {r["clip_id"]: r for r in write_clips_csv([rec], old)}
    assert rows["c2"]["qa_toe_skim"] == 1.0 and rows["c1"]["qa_flag"] == "penetration"
    again = {r["clip_id"]: r for r in read_clips_csv(old)}
    assert again["c2"]["qa_skate_cm_s"] == pytest.approx(80.0)
