"""Fitting a gesture's amplitude into the real captured range of the closest emotion (on SYNTHETIC procedural
gestures and the shipped real ranges)."""
from __future__ import annotations

import numpy as np
import pytest

from generation.gesture import range_fit as RF
from generation.gesture.range_fit import RANGE_STATS, closest_captured, fit_to_range, scale_amplitude
from generation.gesture.real_stats import WRISTS, motion_stats
from generation.procedural.gesture import GestureParams, seated_gesture


@pytest.fixture(scope="module")
def synthetic_gesture():
    return seated_gesture(GestureParams(kind="descriptive"), n_frames=120, fps=30.0, seed=1)


def test_closest_captured_emotion():
    captured = ("joyous", "sad", "angry", "proud", "neutral")
    assert closest_captured("sad", captured) == "sad"
    assert closest_captured("afraid", captured) == "angry"
    assert closest_captured("ashamed", captured) == "sad"
    with pytest.raises(ValueError, match="unknown gesture emotion"):
        closest_captured("bored", captured)


def test_amplitude_factor_scales_wrist_speed(synthetic_gesture):
    same = scale_amplitude(synthetic_gesture, 1.0)
    np.testing.assert_allclose(same.positions(), synthetic_gesture.positions(), atol=1e-9)
    base = motion_stats(synthetic_gesture)["wrist_mean"]
    half = motion_stats(scale_amplitude(synthetic_gesture, 0.5))["wrist_mean"]
    double = motion_stats(scale_amplitude(synthetic_gesture, 2.0))["wrist_mean"]
    assert half < 0.7 * base < base < double
    with pytest.raises(ValueError, match="positive"):
        scale_amplitude(synthetic_gesture, 0.0)


def test_fit_reaches_a_range_it_can_and_leaves_the_gesture_where_it_cannot(synthetic_gesture):
    before = motion_stats(synthetic_gesture)
    slower = {k: [0.3 * before[k], 0.6 * before[k]] if k.startswith("wrist") else [0.0, 10.0] for k in RANGE_STATS}
    out, rec = fit_to_range(synthetic_gesture, slower)
    assert rec["inside"] and rec["factor"] < 1.0
    after = motion_stats(out)
    assert all(slower[k][0] <= after[k] <= slower[k][1] for k in RANGE_STATS)
    impossible = {k: [100.0, 200.0] for k in RANGE_STATS}
    same, rec = fit_to_range(synthetic_gesture, impossible)
    assert same is synthetic_gesture and rec == {"factor": 1.0, "shoulder_flexion_deg": 0.0, "inside": False,
                                                 "before": rec["before"], "after": rec["before"]}


def test_fit_closest_range_records_what_it_did(synthetic_gesture):
    out = RF.fit_closest_range(synthetic_gesture, "ashamed")
    rec = out.metadata["real_range"]
    assert rec["reference_emotion"] == "sad" and rec["licence"] == "CC BY-NC 4.0"
    assert "real_range" not in synthetic_gesture.metadata


def test_plan_field_real_range():
    from generation.plans.generators.fields import FieldError
    from generation.plans.generators.gesture_net import GestureNetInputs

    raw = {"sentence": "It rained all day.", "task": "narration", "emotion_label": "sad"}
    assert GestureNetInputs.parse(raw, None).real_range == "closest"
    assert GestureNetInputs.parse({**raw, "real_range": "off"}, None).real_range == "off"
    with pytest.raises(FieldError):
        GestureNetInputs.parse({**raw, "real_range": "loud"}, None)


def test_shoulder_flexion_swings_the_hands_forward_and_back(synthetic_gesture):
    same = RF.flex_shoulders(synthetic_gesture, 0.0)
    assert same is synthetic_gesture
    P = synthetic_gesture.positions()
    facing = (P[:, list(RF.KNEES)] - P[:, list(RF.HIPS)]).mean((0, 1))
    facing /= np.linalg.norm(facing)

    def wrists_ahead(motion) -> float:
        Q = motion.positions()
        return float(((Q[:, list(WRISTS)] - Q[:, list(RF.SHOULDERS)]) @ facing).mean())

    forward, back = RF.flex_shoulders(synthetic_gesture, 30.0), RF.flex_shoulders(synthetic_gesture, -30.0)
    assert wrists_ahead(back) < wrists_ahead(synthetic_gesture) < wrists_ahead(forward)
    Q = forward.positions()
    untouched = [j for j in range(P.shape[1]) if j not in (8, 9, 10, 12, 13, 14)]
    np.testing.assert_allclose(Q[:, untouched], P[:, untouched], atol=1e-9)
    # the arm keeps its length and its elbow bend: only the shoulder's rotation changed
    np.testing.assert_allclose(forward.rotations[:, [9, 13]], synthetic_gesture.rotations[:, [9, 13]], atol=1e-6)
    with pytest.raises(ValueError, match="finite"):
        RF.flex_shoulders(synthetic_gesture, float("nan"))


def test_fit_swings_the_arms_when_amplitude_alone_cannot_reach(synthetic_gesture):
    before = motion_stats(synthetic_gesture)
    farther = {k: [before[k] + 0.06, before[k] + 0.25] if k.startswith("reach") else [0.0, 10.0]
               for k in RANGE_STATS}
    out, rec = fit_to_range(synthetic_gesture, farther)
    assert rec["inside"] and rec["shoulder_flexion_deg"] != 0.0
    after = motion_stats(out)
    assert all(farther[k][0] <= after[k] <= farther[k][1] for k in RANGE_STATS)
