"""Seated rest pose and procedural seated gestures."""
import dataclasses

import numpy as np
import pytest

from generation.core.kinematics import np_forward_kinematics
from generation.core.quaternion import np_qangle
from generation.core.skeleton import gait_skeleton, gesture_skeleton
from generation.procedural.emotion import gesture_params_for_vad
from generation.procedural.gesture import GestureParams, seat_height, seated_gesture, seated_rest_pose

J = {n: i for i, n in enumerate(gesture_skeleton().joints)}


def _angle(a, b, c):
    u, v = a - b, c - b
    return np.degrees(np.arccos(np.dot(u, v) / np.linalg.norm(u) / np.linalg.norm(v)))


@pytest.mark.parametrize("height, build", [(1.75, "male"), (1.60, "female")])
def test_rest_pose_is_seated(height, build):
    sk = gesture_skeleton(height, build)
    rot, root = seated_rest_pose(sk)
    assert rot.shape == (23, 4) and root.shape == (3,)
    p = np_forward_kinematics(rot, root, sk)
    for side in ("left_", "right_"):
        hip, knee, ankle, toe = (p[J[side + n]] for n in ("hip", "knee", "ankle", "toe"))
        assert _angle(p[J["chest2"]], hip, knee) == pytest.approx(90, abs=8)     # hip flexed ~90
        assert _angle(hip, knee, ankle) == pytest.approx(90, abs=8)              # knee flexed ~90
        assert toe[1] == pytest.approx(0.0, abs=0.01)                             # foot on the floor
        assert hip[1] > seat_height(sk)                                           # sitting on the seat
        # wrist resting on the thigh: above it, near its middle
        wrist = p[J[side + "wrist"]]
        mid = 0.5 * (hip + knee)
        assert np.linalg.norm((wrist - mid)[[0, 2]]) < 0.08
        assert 0.0 < wrist[1] - mid[1] < 0.12
    assert p[:, 1].min() > -0.005
    assert p[J["head"], 1] - p[J["root"], 1] > 0.55                               # upright trunk
    assert 0.33 < seat_height(gesture_skeleton()) < 0.45


def test_gesture_starts_and_ends_at_rest_and_is_smooth():
    rest, root = seated_rest_pose()
    params = [GestureParams(kind=k) for k in ("descriptive", "pointing", "beat")]
    m = seated_gesture(params, n_frames=150, seed=2)
    assert m.rotations.shape == (150, 23, 4)
    assert m.metadata["synthetic"] is True and m.metadata["origin"] == "procedural"
    assert np_qangle(m.rotations[0], rest).max() < 1e-6
    assert np_qangle(m.rotations[-1], rest).max() < 1e-6
    np.testing.assert_allclose(m.root_positions, np.broadcast_to(root, (150, 3)))
    # angular speed of every joint stays below 6 rad/s (0.2 rad per frame at 30 fps) and eases at the ends
    step = np_qangle(m.rotations[1:], m.rotations[:-1])
    assert step.max() < 0.2
    assert step[:3].max() < 0.01 and step[-3:].max() < 0.01
    p = m.positions()
    assert np.abs(p[1:] - p[:-1]).max() < 0.12                 # no joint jumps more than 12 cm a frame
    assert p[..., 1].min() > -0.005


@pytest.mark.parametrize("kind", ["beat", "pointing"])
@pytest.mark.parametrize("hand", ["left", "right"])
def test_one_handed_gestures_use_the_handedness_hand(kind, hand):
    m = seated_gesture(GestureParams(kind=kind, handedness=hand, amplitude=1.2), n_frames=90, seed=1)
    p = m.positions()
    lead, other = (J["left_wrist"], J["right_wrist"]) if hand == "left" else (J["right_wrist"], J["left_wrist"])
    path_lead = np.linalg.norm(np.diff(p[:, lead], axis=0), axis=-1).sum()
    path_other = np.linalg.norm(np.diff(p[:, other], axis=0), axis=-1).sum()
    assert path_lead > 1.5 * path_other


def test_arousal_speeds_up_and_dominance_expands():
    def run(v, a, d):
        m = seated_gesture([gesture_params_for_vad(v, a, d, None, kind=k) for k in ("beat", "descriptive")],
                           n_frames=120, seed=0)
        p = m.positions()
        speed = np.linalg.norm(np.diff(p[:, J["right_wrist"]], axis=0), axis=-1).mean() * 30
        spread = np.linalg.norm(p[:, J["left_wrist"]] - p[:, J["right_wrist"]], axis=-1)[30:90].mean()
        head_forward = (p[:, J["head"], 2] - p[:, J["root"], 2])[30:90].mean()
        return speed, spread, head_forward

    low_a = run(0.5, 0.15, 0.5)
    high_a = run(0.5, 0.9, 0.5)
    assert high_a[0] > 1.5 * low_a[0]
    low_d = run(0.5, 0.5, 0.1)
    high_d = run(0.5, 0.5, 0.9)
    assert high_d[1] > low_d[1] + 0.05
    assert low_d[2] > high_d[2] + 0.1                           # collapsed trunk, head forward at low dominance


def test_hands_stay_out_of_the_thighs():
    for hand in ("left", "right"):
        for k in ("beat", "pointing", "descriptive"):
            p = seated_gesture(GestureParams(kind=k, handedness=hand, expansion=-1.0, amplitude=1.6),
                               n_frames=60).positions()
            thigh_top = p[:, J["left_hip"], 1]
            assert (p[:, J["left_wrist"], 1] - thigh_top).min() > 0.0
            assert (p[:, J["right_wrist"], 1] - thigh_top).min() > 0.0


def test_bad_input_names_the_problem():
    with pytest.raises(ValueError, match="kind"):
        seated_gesture(GestureParams(kind="wave"))
    with pytest.raises(ValueError, match="handedness"):
        seated_gesture(GestureParams(handedness="both"))
    with pytest.raises(ValueError, match="speed"):
        seated_gesture(dataclasses.replace(GestureParams(), speed=9.0))
    with pytest.raises(ValueError, match="23-joint"):
        seated_gesture(GestureParams(), skeleton=gait_skeleton())
    with pytest.raises(ValueError, match="at least one"):
        seated_gesture([])
    with pytest.raises(ValueError, match="n_frames"):
        seated_gesture(GestureParams(), n_frames=3)
