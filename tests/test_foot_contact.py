"""Contact-aware foot clean-up (generation.core.foot_contact): planted feet, no penetration, exact bones, no pops."""
from __future__ import annotations

import numpy as np
import pytest

from generation.core.features import foot_joints, foot_skate
from generation.core.foot_contact import detect_contacts_hysteresis, legs, plant_feet
from generation.core.motion import Motion
from generation.core.paths import curved, straight
from generation.procedural.walk import WalkParams, walk

SKATE_LIMIT_M_S = 0.03


def sliding_walk(path=None, slide: float = 0.2, sink_m: float = 0.03) -> Motion:
    """A procedural walk whose root runs ``slide`` faster than its steps (feet slide while planted) and sits
    ``sink_m`` too low (feet go below the floor)."""
    m = walk(WalkParams(), path or straight(20.0), 180, 30.0, phase=0.2)
    root = m.root_positions.copy()
    root[:, [0, 2]] = root[0, [0, 2]] + (1.0 + slide) * (root[:, [0, 2]] - root[0, [0, 2]])
    root[:, 1] -= sink_m
    return Motion(m.skeleton, m.rotations, root, m.fps, dict(m.metadata))


def _speeds(m: Motion) -> np.ndarray:
    return np.linalg.norm(np.diff(m.positions(), axis=0), axis=-1) * m.fps      # (T-1, J)


@pytest.mark.parametrize("path", [straight(20.0), curved(3.0, 2.0, 20.0)], ids=["straight", "curved"])
def test_cleanup_plants_sliding_feet(path):
    raw = sliding_walk(path)
    P0 = raw.positions()
    before = foot_skate(P0, raw.fps, raw.skeleton)["mean_m_s"]
    assert before > 0.10                                  # the test walk really slides
    left, right = foot_joints(raw.skeleton)
    assert P0[:, left + right, 1].min() < -0.02           # and sinks into the floor

    clean = plant_feet(raw)
    P = clean.positions()
    assert foot_skate(P, clean.fps, clean.skeleton)["mean_m_s"] < SKATE_LIMIT_M_S
    assert P[:, left + right, 1].min() > -0.01            # at most 1 cm below the floor (here: none)
    # rotations only: every bone keeps its length
    parents = list(clean.skeleton.parents[1:])
    lengths = np.linalg.norm(P[:, 1:] - P[:, parents], axis=-1)
    np.testing.assert_allclose(lengths, np.broadcast_to(clean.skeleton.bone_lengths()[1:], lengths.shape),
                               atol=1e-9)
    # no pop: no joint moves much faster than the fastest joint of the input, nor jumps between frames
    assert _speeds(clean).max() < 1.25 * _speeds(raw).max()
    acc = np.linalg.norm(np.diff(P, 2, axis=0), axis=-1).max() * clean.fps ** 2
    acc0 = np.linalg.norm(np.diff(P0, 2, axis=0), axis=-1).max() * raw.fps ** 2
    assert acc < 2.0 * acc0 + 20.0                        # m/s^2
    # the upper body is untouched
    leg_joints = {j for leg in legs(raw.skeleton) for j in (leg.hip, leg.knee, leg.ankle, leg.toe)}
    upper = [j for j in range(raw.skeleton.num_joints) if j not in leg_joints and j != 0]
    np.testing.assert_allclose(clean.rotations[:, upper], raw.rotations[:, upper])
    assert clean.metadata["foot_cleanup"]["method"]


def test_strides_beyond_reach_need_the_pelvis_lowered():
    """With the root running 35 % ahead of the steps the planted feet are out of the legs' reach at the ends of
    the stance: the ankles stop short unless the pelvis may go down."""
    raw = sliding_walk(slide=0.35)
    short = plant_feet(raw)
    lowered = plant_feet(raw, lower_pelvis=True)
    assert lowered.metadata["foot_cleanup"]["pelvis_drop_max_m"] > 0
    skate = [foot_skate(m.positions(), m.fps, m.skeleton)["mean_m_s"] for m in (raw, short, lowered)]
    assert skate[2] < SKATE_LIMIT_M_S and skate[1] < skate[0] / 3


def test_planted_walk_stays_close_and_contacts_alternate():
    """A walk that is already planted changes little, and both feet get contacts."""
    m = walk(WalkParams(), straight(20.0), 180, 30.0, phase=0.2)
    c = detect_contacts_hysteresis(m.positions(), m.fps, m.skeleton)
    assert c[:, 0].any() and c[:, 1].any() and c.any(axis=1).mean() > 0.9
    clean = plant_feet(m)
    assert np.abs(clean.positions() - m.positions()).max() < 0.05
    assert foot_skate(clean.positions(), clean.fps, clean.skeleton)["mean_m_s"] < SKATE_LIMIT_M_S


def test_given_contacts_and_gesture_skeleton():
    from generation.core.skeleton import gesture_skeleton

    assert len(legs(gesture_skeleton())) == 2            # ankle-named legs work too
    raw = sliding_walk()
    none = plant_feet(raw, contacts=np.zeros((raw.num_frames, 2), dtype=bool))
    # without contacts only the floor clamp acts: feet lifted onto the floor
    left, right = foot_joints(raw.skeleton)
    assert none.positions()[:, left + right, 1].min() > -1e-6
