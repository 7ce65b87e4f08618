"""Realism by emotion on render-length windows (benchmarks/bench_realism_by_emotion.py): the per-emotion ranges are
the windows' own percentiles, a generated median is judged against the same emotion's range, and a clip is cut into
render-length windows by the project's slicer."""
from __future__ import annotations

import numpy as np
import pytest

from benchmarks import bench_realism_by_emotion as bench
from generation.core.motion import Motion
from generation.core.skeleton import gait_skeleton
from generation.quality.realism import MEASURES


def test_emotion_ranges_are_the_percentiles_of_each_emotions_own_windows():
    rows = [{"emotion": "happy", "stance_knee_deg": float(v)} for v in np.random.default_rng(0).permutation(101)]
    rows += [{"emotion": "sad", "stance_knee_deg": v} for v in (3.0, None, 1.0, 2.0, float("nan"))]
    ranges = bench.emotion_ranges(rows)
    assert list(ranges) == ["happy", "sad"]
    assert ranges["happy"]["stance_knee_deg"] == pytest.approx(
        {"n": 101, "p5": 5.0, "p50": 50.0, "p95": 95.0, "min": 0.0, "max": 100.0})
    # None and NaN dropped; linear interpolation between the order statistics 1, 2, 3
    assert ranges["sad"]["stance_knee_deg"] == pytest.approx(
        {"n": 3, "p5": 1.1, "p50": 2.0, "p95": 2.9, "min": 1.0, "max": 3.0})
    assert set(ranges["sad"]) == set(MEASURES)
    assert ranges["sad"]["toe_skim"] == {"n": 0}


def test_a_generated_median_is_judged_against_the_same_emotions_range():
    real = {"happy": {m: bench.measure_range([0.0, 10.0, 20.0, 30.0, 40.0]) for m in MEASURES},
            bench.NEUTRAL_D2: {m: bench.measure_range([100.0, 200.0]) for m in MEASURES}}
    gen = {"happy": {m: bench.measure_range([39.0]) for m in MEASURES},
           "neutral": {m: bench.measure_range([150.0]) for m in MEASURES},
           "sad": {m: bench.measure_range([0.0]) for m in MEASURES}}
    comparison = bench.compare(real, gen)
    # happy p5-p95 is 2-38: 39 is outside it but inside the min-max 0-40
    assert comparison["happy"]["toe_skim"] == {"generated_median": 39.0, "generated_n": 1, "p5_p95": False,
                                               "min_max": True}
    # the dataset-2 neutral reference judges the generated neutral walks
    assert comparison[bench.NEUTRAL_D2]["speed_cv"]["p5_p95"] is True
    assert [o["reference"] for o in bench.outside(comparison)] == ["happy"] * len(MEASURES)
    assert bench.inside(None, real["happy"]["toe_skim"]) == {"p5_p95": None, "min_max": None}


def test_a_clip_gives_one_window_per_hop_and_none_when_shorter():
    sk = gait_skeleton()
    q = np.zeros((100, sk.num_joints, 4))
    q[..., 0] = 1.0
    root = np.zeros((100, 3))
    root[:, 0] = np.linspace(0.0, 12.0, 100)                    # 1.2 m/s for 10 s at 10 fps
    root[:, 1] = sk.root_height()
    walk = Motion(sk, q, root, 10.0)
    assert len(bench.window_measures(walk, 6.0, 1.0)) == 5     # starts 0, 1, 2, 3, 4 s
    assert len(bench.window_measures(walk, 8.0, 3.0)) == 2     # starts 0 s and 2 s (the one ending at the last frame)
    assert bench.window_measures(walk, 12.0, 1.0) == []
