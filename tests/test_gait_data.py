"""Gait network sequences: root features, the heading frame, prepared sequences, the normaliser."""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from generation.core.paths import straight
from generation.core.rigging import yaw_quat
from generation.gait.data import Normalizer, from_heading_frame, prepare_sequences, root_features, to_heading_frame
from generation.procedural.walk import WalkParams, walk

torch.set_num_threads(1)
pytest_plugins = ("gait_fixtures",)   # the tiny_data and tiny_net fixtures


def test_root_features_of_a_straight_walk():
    params = WalkParams()
    m = walk(params, straight(20.0, heading=0.7), 240, 30.0)
    rot, root = m.rotations[::4], m.root_positions[::4]
    rf = root_features(root, rot[:, 0])
    speed_per_step = params.speed_mps / 7.5
    assert abs(np.median(rf["s"]) - speed_per_step) < 0.1 * speed_per_step
    assert np.allclose(rf["ref"][5:-5], 0.7, atol=0.05)
    assert np.abs(rf["delta"]).mean() < 0.3
    back = from_heading_frame(to_heading_frame(rot, rf["ref"]), rf["ref"])
    assert np.allclose(np.abs((back * rot).sum(-1)), 1.0, atol=1e-9)


def test_heading_frame_uses_the_yaw_about_plus_y():
    yaw = np.linspace(-7.0, 7.0, 301).reshape(7, 43)
    q = yaw_quat(yaw)
    assert np.allclose(q, np.stack((np.cos(yaw / 2), 0 * yaw, np.sin(yaw / 2), 0 * yaw), -1), atol=1e-15)
    rot = np.tile([1.0, 0.0, 0.0, 0.0], (7, 43, 21, 1))
    assert np.array_equal(from_heading_frame(rot, yaw)[..., 0, :], q)


def test_prepared_sequences(tiny_data):
    d = tiny_data
    assert d.q.shape == (6, 60, 21, 4) and d.aff.shape == (6, 60, 18) and d.fps == 7.5
    assert torch.allclose(d.q.norm(dim=-1), torch.ones(6, 60, 21), atol=1e-5)
    assert float(d.theta.min()) >= 0 and float(d.theta.max()) < 2 * math.pi
    # Walks take a step every ~0.55 s: omega near 2 pi / (2 * 0.55 s * 7.5 steps/s) rad per step.
    assert 0.5 < float(d.omega.median()) < 1.2
    with pytest.raises(ValueError, match="frames"):
        prepare_sequences(np.zeros((1, 100, 21, 4)), np.zeros((1, 100, 3)), np.ones((1, 4)), np.array(["train"]),
                          np.array([1.75]), np.array(["male"]))


def test_normalizer_round_trip():
    rng = np.random.default_rng(1)
    n = Normalizer.fit(rng.normal(size=(50, 18)), rng.normal(size=(50, 3)), rng.normal(size=(50, 3)))
    n2 = Normalizer.from_dict(n.to_dict())
    r = torch.randn(4, 3)
    assert torch.allclose(n2.root_inv(n2.root(r)), r, atol=1e-5)
