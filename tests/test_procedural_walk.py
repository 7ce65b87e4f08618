"""Procedural walks: path following, planted feet (foot skate), plausible legs, parameters."""
import dataclasses

import numpy as np
import pytest

from generation.core import paths
from generation.core.features import foot_skate
from generation.core.quaternion import np_qrot
from generation.core.skeleton import gait_skeleton, gesture_skeleton
from generation.procedural.walk import WalkParams, planted_foot_slide, walk, walk_with_contacts

PATHS = {
    "straight": lambda: paths.straight(15.0),
    "curved": lambda: paths.curved(3.0, np.radians(140), 15.0),
    "sharp_turn": lambda: paths.sharp_turn(np.radians(-90), 15.0, 0.4),
}


@pytest.fixture(scope="module")
def walks():
    return {k: walk_with_contacts(WalkParams.neutral(), make(), 240, 30.0, phase=0.3, seed=1)
            for k, make in PATHS.items()}


def test_neutral_walk_is_a_marked_synthetic_motion():
    m = walk(WalkParams.neutral(), n_frames=60)
    assert m.rotations.shape == (60, 21, 4)
    assert m.root_positions.shape == (60, 3)
    np.testing.assert_allclose(np.linalg.norm(m.rotations, axis=-1), 1.0, atol=1e-9)
    assert m.metadata["origin"] == "procedural" and m.metadata["synthetic"] is True
    assert m.metadata["params"]["cadence_spm"] == pytest.approx(110.0)


@pytest.mark.parametrize("kind", list(PATHS))
def test_feet_do_not_skate_while_planted(walks, kind):
    res = walks[kind]
    pos = res.motion.positions()
    slide = planted_foot_slide(pos, res.heel_contact, res.toe_contact)
    assert slide["n_pairs"] > 200
    assert slide["max_mm_per_frame"] < 0.01
    # the independent detector (height + speed thresholds) also sees almost no slide
    detected = foot_skate(pos, 30.0, res.motion.skeleton)
    assert detected["mean_m_s"] * 1000 / 30.0 < 2.0
    assert detected["contact_share"] > 0.4


@pytest.mark.parametrize("kind", list(PATHS))
def test_walk_follows_the_path(walks, kind):
    res = walks[kind]
    path = PATHS[kind]()
    root = res.motion.root_positions[:, [0, 2]]
    dense = path.point_at(np.linspace(0, path.length, 3000))
    dist = np.min(np.linalg.norm(root[:, None] - dense[None], axis=-1), axis=1)
    assert dist.max() < (0.35 if kind == "sharp_turn" else 0.1)
    travelled = np.linalg.norm(np.diff(root, axis=0), axis=1).sum()
    assert travelled == pytest.approx(WalkParams.neutral().speed_mps * 239 / 30.0, rel=0.1)
    # at the end the body faces along the path
    s_end = WalkParams.neutral().speed_mps * 239 / 30.0
    fwd = np_qrot(res.motion.rotations[-1, 0], np.array([0.0, 0.0, 1.0]))   # root facing direction
    heading = np.arctan2(fwd[0], fwd[2])
    expected = path.heading_at(min(s_end, path.length - 1e-6))
    assert abs(np.angle(np.exp(1j * (heading - expected)))) < np.radians(25)


def test_footprints_alternate_and_sit_either_side_of_the_path(walks):
    res = walks["straight"]
    left, right = res.footprints
    assert np.all(left[:, 0] > 0.03) and np.all(right[:, 0] < -0.03)      # left = +x side
    steps = np.diff(left[:, 1])
    np.testing.assert_allclose(steps, WalkParams.neutral().stride_m, rtol=0.05)


def test_feet_on_the_ground_and_legs_plausible(walks):
    for res in walks.values():
        pos = res.motion.positions()
        assert pos[..., 1].min() > -0.005                      # nothing below the floor
        toes = pos[:, [4, 8], 1]
        assert toes.min(0).max() < 0.005                       # both toes touch the floor
        assert np.all(res.heel_contact.any(1) | res.toe_contact.any(1))  # always at least one foot down
        root_y = res.motion.root_positions[:, 1]
        assert 0.82 < root_y.min() and root_y.max() < 0.95     # 1.75 m body, standing 0.94 m
        # knees bend forward (never backward), at most about 90 degrees in swing
        left_dir = pos[:, 1] - pos[:, 5]
        for hip, knee, heel in ((1, 2, 3), (5, 6, 7)):
            thigh = pos[:, knee] - pos[:, hip]
            shin = pos[:, heel] - pos[:, knee]
            cos = (thigh * shin).sum(-1) / np.linalg.norm(thigh, axis=-1) / np.linalg.norm(shin, axis=-1)
            flex = np.degrees(np.arccos(np.clip(cos, -1, 1)))
            assert flex.max() < 90
            bent = flex > 5
            assert np.all((np.cross(thigh, shin) * left_dir).sum(-1)[bent] > 0)


def test_emotion_like_parameters_change_speed_and_posture():
    slow = dataclasses.replace(WalkParams.neutral(), cadence_spm=85.0, stride_m=1.0, torso_pitch_rad=0.3,
                               head_pitch_rad=0.6)
    fast = dataclasses.replace(WalkParams.neutral(), cadence_spm=125.0, stride_m=1.55, arm_abduction_rad=0.3)
    a, b = walk(slow, n_frames=90), walk(fast, n_frames=90)
    da = np.linalg.norm(a.root_positions[-1] - a.root_positions[0])
    db = np.linalg.norm(b.root_positions[-1] - b.root_positions[0])
    assert db > 1.8 * da
    pa, pb = a.positions(), b.positions()
    # bowed: head ahead of the root; expanded: hands further apart
    assert (pa[:, 12, 2] - pa[:, 0, 2]).mean() > (pb[:, 12, 2] - pb[:, 0, 2]).mean() + 0.05
    assert np.linalg.norm(pb[:, 15] - pb[:, 19], axis=-1).mean() > np.linalg.norm(pa[:, 15] - pa[:, 19],
                                                                                  axis=-1).mean()


def test_body_height_scales_the_walk():
    tall = walk(WalkParams.neutral(), n_frames=61, skeleton=gait_skeleton(1.95, "male"))
    short = walk(WalkParams.neutral(), n_frames=61, skeleton=gait_skeleton(1.55, "female"))
    d_tall = tall.root_positions[-1, 2] - tall.root_positions[0, 2]
    d_short = short.root_positions[-1, 2] - short.root_positions[0, 2]
    assert d_tall / d_short == pytest.approx(1.95 / 1.55, rel=0.02)


def test_deterministic_and_seeded():
    a = walk(WalkParams.neutral(), n_frames=30, seed=5)
    b = walk(WalkParams.neutral(), n_frames=30, seed=5)
    c = walk(WalkParams.neutral(), n_frames=30, seed=6)
    np.testing.assert_array_equal(a.rotations, b.rotations)
    assert not np.allclose(a.rotations, c.rotations)


def test_bad_input_is_rejected_with_the_field_named():
    with pytest.raises(ValueError, match="cadence_spm"):
        walk(dataclasses.replace(WalkParams.neutral(), cadence_spm=500.0))
    with pytest.raises(ValueError, match="stride_m"):
        walk(dataclasses.replace(WalkParams.neutral(), stride_m=float("nan")))
    with pytest.raises(ValueError, match="21-joint"):
        walk(WalkParams.neutral(), skeleton=gesture_skeleton())
    with pytest.raises(ValueError, match="n_frames"):
        walk(WalkParams.neutral(), n_frames=1)
    with pytest.raises(ValueError, match="unknown field"):
        WalkParams.from_dict({"speed": 1.0})


def test_params_round_trip_through_dict():
    p = dataclasses.replace(WalkParams.neutral(), arm_swing_rad=0.5)
    assert WalkParams.from_dict(p.to_dict()) == p
