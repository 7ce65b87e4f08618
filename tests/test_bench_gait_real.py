"""The seed000 plan read for what each clip asks (benchmarks/bench_gait_real.py): pure and mixed clips whole,
transitions by their first and last seconds, ties scored by their components."""
from __future__ import annotations

import numpy as np
import pytest

from benchmarks import bench_gait_real as bench
from generation.core.motion import Motion
from generation.core.skeleton import gait_skeleton


def _walk(labels: list[int], fps: float = 10.0) -> Motion:
    """A motion whose root x holds, per frame, the index of the emotion a fake observer should read there."""
    sk = gait_skeleton()
    q = np.zeros((len(labels), sk.num_joints, 4))
    q[..., 0] = 1.0
    root = np.zeros((len(labels), 3))
    root[:, 0] = labels
    return Motion(sk, q, root, fps)


class MajorityObserver:
    """Reads the emotion most frames of the motion carry (p 0.7 for it, 0.1 for the others)."""

    def proba(self, motion: Motion) -> np.ndarray:
        k = np.bincount(motion.root_positions[:, 0].astype(int), minlength=4).argmax()
        return np.where(np.arange(4) == k, 0.7, 0.1)


def test_dominant_and_clip_kind():
    assert bench.dominant([0.6, 0, 0, 0.4]) == "happy"
    assert bench.dominant([0.5, 0, 0.5, 0]) is None
    assert bench.clip_kind([[0, 1, 0, 0]]) == "pure"
    assert bench.clip_kind([[0, 0.7, 0, 0.3]]) == "mixture"
    assert bench.clip_kind([[1, 0, 0, 0], [0, 1, 0, 0]]) == "transition"


def test_a_transition_is_read_by_its_first_and_last_seconds_and_a_tie_by_its_components():
    # 10 s at 10 fps: sad for 6 s, then happy; a whole-clip reading would say sad
    transition = {"seed": "t", "motion": _walk([1] * 60 + [0] * 40),
                  "vectors": [[0, 0.8, 0, 0.2], [0.8, 0, 0, 0.2]]}
    tie = {"seed": "m", "motion": _walk([2] * 50), "vectors": [[0.5, 0, 0.5, 0]]}
    pure = {"seed": "p", "motion": _walk([3] * 50), "vectors": [[0, 0, 0, 1]]}
    parts = bench.plan_readings([transition, tie, pure], window_s=4.0)
    assert [(p["clip"], p["part"], p["asked"], p["motion"].num_frames) for p in parts] == [
        ("t", "first 4 s", "sad", 40), ("t", "last 4 s", "happy", 40), ("m", "whole", None, 50),
        ("p", "whole", "neutral", 50)]
    rec = bench.plan_recognition(MajorityObserver(), [transition, tie, pure], window_s=4.0)
    assert rec["by_kind"] == {"pure": {"n": 1, "read_as_asked": 1.0}, "mixture": {"n": 1, "read_as_asked": 1.0},
                              "transition": {"n": 2, "read_as_asked": 1.0}}
    assert rec["per_class"]["happy"]["n"] == 1 and rec["per_class"]["angry"]["n"] == 0   # the tie is left out
    assert [p["read"] for p in rec["parts"]] == ["sad", "happy", "angry", "neutral"]
    assert all("motion" not in p for p in rec["parts"])


def test_a_transition_that_never_arrives_is_a_miss():
    stuck = {"seed": "t", "motion": _walk([1] * 100), "vectors": [[0, 1, 0, 0], [1, 0, 0, 0]]}
    rec = bench.plan_recognition(MajorityObserver(), [stuck], window_s=4.0)
    assert rec["by_kind"]["transition"]["read_as_asked"] == pytest.approx(0.5)
    assert rec["per_class"]["happy"]["own"] == 0.0


class ConstantObserver:
    """Reads every walk happy 0.4, sad 0.1, angry 0.2, neutral 0.3."""

    def proba(self, motion: Motion) -> np.ndarray:
        return np.array([0.4, 0.1, 0.2, 0.3])


def test_mixture_response_asks_each_share_of_each_emotion_on_both_paths():
    from generation.gait.generate import load_default_model

    out = bench.mixture_response(load_default_model(weights="real"), ConstantObserver(), steps=20,
                                 shares=(0.0, 1.0))
    assert set(out) == {"happy", "sad", "angry"} and set(out["sad"]) == {"0", "1"}
    assert out["happy"]["1"] == {"n": 2, "p_emotion": 0.4, "p_neutral": 0.3, "as_emotion": 1.0, "as_neutral": 0.0}
    assert out["sad"]["0"]["as_emotion"] == 0.0 and out["sad"]["0"]["p_emotion"] == pytest.approx(0.1)
