"""Walk measures of seed 000's happy-vs-neutral comparison, on a procedural (SYNTHETIC) walk and a shipped real take."""
from __future__ import annotations

import numpy as np
import pytest

from generation.core.motion import Motion
from generation.gait.affect_measures import MEASURES, difference, mean_measures, walk_measures
from generation.procedural.walk import WalkParams, walk


@pytest.fixture(scope="module")
def synthetic_walk() -> Motion:
    return walk(WalkParams(), n_frames=120, fps=30.0)


def test_measures_of_a_synthetic_walk_are_plausible(synthetic_walk):
    m = walk_measures(synthetic_walk)
    assert set(m) == set(MEASURES)
    assert 0.3 < m["speed"] < 1.5 and 0.0 < m["arm_swing"] < 0.6 and 90 < m["elbow_deg"] <= 180
    assert -45 < m["head_pitch_deg"] < 45 and 0.0 < m["bounce"] < 0.1


def test_measures_do_not_depend_on_the_heading(synthetic_walk):
    """A walk turned 90 degrees about the vertical measures the same (the heading comes from the pelvis)."""
    from generation.core.quaternion import np_qmul

    q = np.array([np.cos(np.pi / 4), 0.0, np.sin(np.pi / 4), 0.0])
    rot = synthetic_walk.rotations.copy()
    rot[:, 0] = np_qmul(np.broadcast_to(q, rot[:, 0].shape), rot[:, 0])
    root = synthetic_walk.root_positions[:, [2, 1, 0]] * np.array([1.0, 1.0, -1.0])
    turned = Motion(synthetic_walk.skeleton, rot, root, synthetic_walk.fps, {})
    a, b = walk_measures(synthetic_walk), walk_measures(turned)
    for k in MEASURES:
        assert a[k] == pytest.approx(b[k], abs=0.05 if k.endswith("deg") else 1e-3), k


def test_a_slower_walk_measures_slower(synthetic_walk):
    slow = Motion(synthetic_walk.skeleton, synthetic_walk.rotations, synthetic_walk.root_positions,
                  synthetic_walk.fps / 2, {})
    d = difference(walk_measures(slow), walk_measures(synthetic_walk))
    assert d["speed"] == pytest.approx(-walk_measures(synthetic_walk)["speed"] / 2, rel=1e-6)
    assert mean_measures([slow, synthetic_walk])["speed"] == pytest.approx(
        0.75 * walk_measures(synthetic_walk)["speed"], rel=1e-6)


def test_bad_input_is_an_error(synthetic_walk):
    with pytest.raises(ValueError, match="0.5 s"):
        walk_measures(synthetic_walk.slice(0, 5))
    with pytest.raises(ValueError, match="at least one"):
        mean_measures([])
