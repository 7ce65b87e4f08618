"""Real captured gestures seated on the chair, the statistics that compare them with generated ones, the real-range
training loss and the real-capture gesture observer's held-out evaluation."""
from __future__ import annotations

import functools

import numpy as np
import pytest
import torch

from generation.core.motion import Motion
from generation.core.quaternion import np_qangle, np_qmul
from generation.core.rigging import yaw_quat
from generation.core.skeleton import gait_skeleton, gesture_skeleton
from generation.gesture.real_range import LOSS_STATS, load_ranges, range_arrays, real_range_loss, sequence_stats
from generation.gesture.real_stats import STAT_NAMES, gesture_stats
from generation.mocap import ImportOptions, import_file
from generation.mocap.seated_gesture import ARM_JOINTS, J, SeatingError, heading_of, seat_gesture
from generation.plans.schema import PlanError, load_plan, validate_plan
from generation.procedural.gesture import seated_rest_pose
from generation.quality.real_gesture_observer import gate_ready, held_out_accuracy
from protocol.vocabulary import CAPTURE_GESTURE_EMOTIONS, GESTURE_EMOTIONS, capture_gesture_emotion

SHIPPED = "generation/data/mocap/bandai-namco/Bandai-Namco-Research-Motiondataset-1/data"


@functools.cache
def captured(style: str) -> Motion:
    result = import_file(f"{SHIPPED}/dataset-1_bye_{style}_001.bvh", ImportOptions(skeleton="gesture", fps=30))
    assert result.motion is not None, result.row
    return result.motion


def test_mapping_names_only_honest_gesture_emotions():
    assert set(CAPTURE_GESTURE_EMOTIONS.values()) <= set(GESTURE_EMOTIONS)
    assert capture_gesture_emotion("happy") == "joyous" and capture_gesture_emotion("normal") == "neutral"
    assert capture_gesture_emotion("not-confident") is None and capture_gesture_emotion("tired") is None


@pytest.mark.parametrize("style", ["sad", "proud"])
def test_seated_capture_keeps_trunk_and_raised_arm_legs_stay_seated(style):
    src = captured(style)
    seated = seat_gesture(src)
    rest, root = seated_rest_pose(seated.skeleton)
    assert seated.num_frames == src.num_frames and seated.fps == src.fps
    np.testing.assert_allclose(seated.root_positions, np.repeat(root[None], src.num_frames, 0))
    for leg in ("left_hip", "left_knee", "left_ankle", "right_hip", "right_knee", "right_toe"):
        assert np.degrees(np_qangle(seated.rotations[:, J[leg]], rest[J[leg]])).max() < 1e-3
    # the trunk's world orientation is the capture's, turned by the capture's mean heading only
    unturn = yaw_quat(-heading_of(src.rotations[:, 0]))
    want = np_qmul(np.broadcast_to(unturn, (src.num_frames, 4)), np_qmul(src.rotations[:, 0], src.rotations[:, 1]))
    got = np_qmul(seated.rotations[:, 0], seated.rotations[:, 1])
    assert np.degrees(np_qangle(got, want)).max() < 1e-3
    for name in ("neck", "head"):
        assert np.degrees(np_qangle(seated.rotations[:, J[name]], src.rotations[:, J[name]])).max() < 1e-3
    # the waving (right) hand goes well above the lap (the rest wrist), and where it is highest the arm is the
    # captured one
    P = seated.positions()
    top = int(np.argmax(P[:, J["right_wrist"], 1]))
    assert P[top, J["right_wrist"], 1] > P[0, J["root"], 1] + 0.2
    arm = [J[n] for n in ARM_JOINTS["right"]]
    assert np.degrees(np_qangle(seated.rotations[top, arm], src.rotations[top, arm])).max() < 1.0
    info = seated.metadata["seating"]
    assert seated.metadata["seated"] is True and info["min_clearance_m"] >= 0.0


def test_hanging_hand_goes_to_the_lap():
    src = captured("sad")
    seated = seat_gesture(src)
    rest, _ = seated_rest_pose(seated.skeleton)
    # the left hand hangs at the side for the whole take: it is the seated rest arm (hand on the thigh)
    P, R = seated.positions(), Motion(seated.skeleton, rest[None], seated.root_positions[:1], 30.0, {}).positions()
    assert np.linalg.norm(P[:, J["left_wrist"]] - R[0, J["left_wrist"]], axis=-1).max() < 0.05
    assert seated.metadata["seating"]["arm_capture_share"]["left"] == 0.0


def test_seating_refuses_other_skeletons():
    sk = gait_skeleton()
    with pytest.raises(SeatingError, match="gesture skeleton"):
        seat_gesture(Motion(sk, np.tile([1.0, 0, 0, 0], (5, sk.num_joints, 1)), np.zeros((5, 3)), 30.0, {}))


def test_plan_entry_seated_only_for_gestures():
    base = {"id": "r", "generator": "captured_file", "origin": "source",
            "file": f"{SHIPPED}/dataset-1_bye_sad_001.bvh", "seated": True}
    with pytest.raises(PlanError, match="seated"):
        validate_plan({"name": "t", "clips": [base]})                       # gait modality by default
    with pytest.raises(PlanError, match="seated"):
        validate_plan({"name": "t", "clips": [dict(base, modality="gesture", seated="yes")]})
    entry = validate_plan({"name": "t", "clips": [dict(base, modality="gesture", emotion_label="sad")]}).entries[0]
    assert entry.inputs["seated"] is True and entry.inputs["emotion_label"] == "sad"


def test_builtin_plans_show_real_seated_gestures():
    for name, n in (("seed003", 5), ("demo", 2)):
        real = [e for e in load_plan(name).entries if e.generator == "captured_file" and e.modality == "gesture"]
        assert len(real) == n
        for e in real:
            assert e.origin == "source" and e.inputs["seated"] is True
            assert set(e.sections) == {"naturalness", "gesture_emotion"}
            style = e.inputs["file"].rsplit("_", 2)[-2]
            assert e.inputs["emotion_label"] == CAPTURE_GESTURE_EMOTIONS[style]


def _still_body(T: int = 20) -> np.ndarray:
    sk = gesture_skeleton()
    rest, root = seated_rest_pose(sk)
    return Motion(sk, np.repeat(rest[None], T, 0), np.repeat(root[None], T, 0), 10.0, {}).positions()


def test_statistics_of_known_motion():
    P = _still_body()
    s = gesture_stats(P, 10.0)
    assert s["wrist_mean"] == 0.0 and s["hold_share"] == 1.0 and s["head_speed"] == 0.0 and s["lean_mean"] < 1.0
    moving = P.copy()
    moving[:, 14, 0] -= 0.03 * np.arange(len(P))        # right wrist: 0.3 m/s outwards (-x, its side) at 10 fps
    s = gesture_stats(moving, 10.0)
    assert s["wrist_mean"] == pytest.approx(0.3) and s["hold_share"] == 0.0
    assert s["reach_p90"] > gesture_stats(P, 10.0)["reach_p90"] + 0.3
    with pytest.raises(ValueError):
        gesture_stats(P[:2], 10.0)


def test_loss_statistics_match_the_measured_ones_and_loss_is_zero_in_range():
    rng = np.random.default_rng(0)
    P = _still_body(30) + np.cumsum(rng.normal(0, 0.01, (30, 23, 3)), axis=0)
    ref = gesture_stats(P, 10.0)
    Pt = torch.tensor(P[None], requires_grad=True)
    mask = torch.ones(1, 30, dtype=torch.bool)
    got = sequence_stats(Pt, mask, 10.0)[0].detach().numpy()
    for k, v in zip(LOSS_STATS, got):
        if k != "hold_share":                                           # the loss's hold share is a soft count
            assert v == pytest.approx(ref[k], rel=1e-3, abs=1e-4), k
    x = torch.tensor(got[None])
    assert float(real_range_loss(Pt, mask, 10.0, x * 0.9, x * 1.1 + 1e-3).detach()) == 0.0
    loss = real_range_loss(Pt, mask, 10.0, x * 2 + 0.1, x * 3 + 0.2)    # everything too small: pushed up
    loss.backward()
    assert float(loss.detach()) > 0 and torch.isfinite(Pt.grad).all() and Pt.grad.abs().sum() > 0


def test_shipped_ranges_are_per_emotion_with_all_for_the_rest():
    data = load_ranges()
    assert set(CAPTURE_GESTURE_EMOTIONS.values()) | {"all"} == set(data["ranges"])
    assert set(STAT_NAMES) == set(data["ranges"]["all"]) and "2306.08861" in data["citation"]
    lo, hi = range_arrays(["sad", "afraid"], data)
    assert lo.shape == (2, len(LOSS_STATS)) and (lo <= hi).all()
    sad, every = data["ranges"]["sad"], data["ranges"]["all"]
    assert hi[0, 0] == pytest.approx(sad["wrist_mean"][1]) and hi[1, 0] == pytest.approx(every["wrist_mean"][1])


def test_held_out_evaluation_leaves_whole_groups_out():
    rng = np.random.default_rng(1)
    y = np.repeat(["a", "b"], 8)
    X = rng.normal(0, 1, (16, 3)) + np.where(y == "a", 3.0, -3.0)[:, None]
    groups = np.tile(np.arange(4), 4)
    ev = held_out_accuracy(X, y, groups)
    assert ev["accuracy"] == 1.0 and ev["n"] == 16 and set(ev["per_group"]) == {"0", "1", "2", "3"}
    assert gate_ready(ev) and not gate_ready({"accuracy": 0.45})
    noise = held_out_accuracy(rng.normal(0, 1, (16, 3)), y, groups)
    assert np.asarray(noise["confusion"]).sum() == 16 and noise["accuracy"] < 1.0


def test_clips_of_the_shipped_weights_credit_the_real_capture_behind_their_statistics():
    from generation.gesture import config
    from generation.gesture.generate import generate_gesture, load_model
    net = load_model(config.DEFAULT_WEIGHTS)
    assert net.real_statistics and net.real_statistics["licence"] == "CC BY-NC 4.0"
    meta = generate_gesture("Look at that!", emotion="sad", model=net, fps=10.0).metadata
    assert meta["real_statistics_licence"] == "CC BY-NC 4.0" and "2306.08861" in meta["real_statistics_citation"]
    assert meta["trained_on"].lower().startswith("synthetic")
