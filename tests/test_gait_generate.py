"""Generating gaits: transitions, several agents, emotion input and guidance, planted feet, bad input, BVH, the shipped
weights."""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from generation.core.motion import Motion
from generation.core.paths import curved, sharp_turn, straight
from generation.formats import bvh
from generation.gait.config import GaitNetConfig
from generation.gait.generate import (
    LoadedGaitNet,
    emotion_transition,
    generate_gaits,
    load_model,
    normalize_emotion,
)
from generation.gait.train import DEFAULT_WEIGHTS
from generation.procedural.walk import WalkParams, walk

torch.set_num_threads(1)
pytest_plugins = ("gait_fixtures",)   # the tiny_data and tiny_net fixtures


def test_emotion_transition_interpolates_and_normalises():
    tr = emotion_transition([1, 0, 0, 0], [0, 2, 0, 0], 11)
    assert tr.shape == (11, 4)
    assert np.allclose(tr.sum(-1), 1.0)
    assert np.allclose(tr[0], [1, 0, 0, 0]) and np.allclose(tr[-1], [0, 1, 0, 0])
    assert np.allclose(tr[5], [0.5, 0.5, 0, 0])
    assert np.all(np.diff(tr[:, 1]) > 0)
    with pytest.raises(ValueError):
        normalize_emotion([0, 0, 0, 0])


def test_generation_two_agents_twenty_steps(tiny_net):
    seed = walk(WalkParams(), straight(10.0), 80, 30.0)
    emotions = np.stack([emotion_transition([1, 0, 0, 0], [0, 1, 0, 0], 20), np.tile([0, 0, 1, 0], (20, 1))])
    paths = [curved(4.0, 1.2, 12.0), sharp_turn(1.0, 10.0)]
    motions = generate_gaits([seed, seed], paths, emotions, steps=20, fps_out=30.0, model=tiny_net)
    assert len(motions) == 2
    for m in motions:
        assert isinstance(m, Motion) and m.fps == 30.0 and m.num_frames == 19 * 4 + 1
        assert np.allclose(np.linalg.norm(m.rotations, axis=-1), 1.0, atol=1e-6)
        assert m.metadata["origin"] == "generated" and m.metadata["generator"] == "gait_net"
        assert m.metadata["trained_on"] == "synthetic procedural corpus"
    assert motions[0].metadata["final_emotion"] == [0.0, 1.0, 0.0, 0.0]
    assert motions[1].metadata["final_emotion"] is None
    # The generated walk starts at the path start.
    assert np.linalg.norm(motions[0].root_positions[0, [0, 2]]) < 0.5


def test_generation_uses_the_emotion_input(tiny_net):
    seed = walk(WalkParams(), straight(10.0), 80, 30.0)
    a, b = generate_gaits([seed, seed], [straight(10.0)] * 2, np.array([[1, 0, 0, 0], [0, 1, 0, 0]]), steps=10,
                          model=tiny_net)
    assert not np.allclose(a.rotations, b.rotations)


def test_emotion_guidance_extrapolates_from_the_uniform_emotion(tiny_net):
    """Scale 0 is the plain network; a positive scale moves each step away from the uniform-emotion prediction
    (for the uniform emotion itself it changes nothing); the scale stored with the weights is the default."""
    from generation.gait.generate import _guided

    seed = walk(WalkParams(), straight(10.0), 80, 30.0)
    args = ([seed], [straight(10.0)], np.array([[0.7, 0.1, 0.1, 0.1]]))
    (plain,) = generate_gaits(*args, steps=12, model=tiny_net, foot_cleanup=False)
    (zero,) = generate_gaits(*args, steps=12, model=tiny_net, foot_cleanup=False, emotion_guidance=0.0)
    (guided,) = generate_gaits(*args, steps=12, model=tiny_net, foot_cleanup=False, emotion_guidance=1.0)
    np.testing.assert_array_equal(plain.rotations, zero.rotations)
    assert not np.allclose(plain.rotations, guided.rotations)
    assert np.allclose(np.linalg.norm(guided.rotations, axis=-1), 1.0, atol=1e-6)
    uniform = ([seed], [straight(10.0)], np.full((1, 4), 0.25))
    (u0,) = generate_gaits(*uniform, steps=12, model=tiny_net, foot_cleanup=False)
    (u1,) = generate_gaits(*uniform, steps=12, model=tiny_net, foot_cleanup=False, emotion_guidance=2.0)
    np.testing.assert_allclose(u0.rotations, u1.rotations, atol=1e-5)
    # p + w (p - p0) on every output, rotations re-normalised.
    cond = {"q_raw": torch.tensor([[[2.0, 0, 0, 0]]]), "root": torch.ones(1, 3), "omega": torch.ones(1)}
    base = {"q_raw": torch.tensor([[[1.0, 1, 0, 0]]]), "root": torch.zeros(1, 3), "omega": torch.zeros(1)}
    out = _guided(cond, base, 0.5)
    assert torch.allclose(out["root"], torch.full((1, 3), 1.5)) and torch.allclose(out["omega"], torch.tensor([1.5]))
    assert torch.allclose(out["q"], torch.tensor([[[2.5, -0.5, 0, 0]]]) / math.hypot(2.5, 0.5))
    stored = LoadedGaitNet(tiny_net.model, tiny_net.normalizer, "g.pt", {"emotion_guidance": 1.0}, tiny_net.config)
    (by_default,) = generate_gaits(*args, steps=12, model=stored, foot_cleanup=False)
    np.testing.assert_array_equal(by_default.rotations, guided.rotations)
    with pytest.raises(ValueError, match="emotion_guidance"):
        generate_gaits(*args, steps=5, model=tiny_net, emotion_guidance=-1.0)


def test_generation_plants_feet_by_default(tiny_net):
    """generate_gaits runs the foot clean-up unless told not to; it only changes the legs and the root height."""
    from generation.core.features import foot_joints, foot_skate

    seed = walk(WalkParams(), straight(10.0), 80, 30.0)
    args = ([seed], [straight(10.0)], np.array([[1.0, 0, 0, 0]]))
    (raw,) = generate_gaits(*args, steps=30, model=tiny_net, foot_cleanup=False)
    (clean,) = generate_gaits(*args, steps=30, model=tiny_net)
    assert "foot_cleanup" not in raw.metadata and clean.metadata["foot_cleanup"]["method"]
    np.testing.assert_allclose(clean.root_positions[:, [0, 2]], raw.root_positions[:, [0, 2]])
    upper = [clean.skeleton.index(n) for n in ("lower_back", "spine", "neck", "head", "left_elbow", "right_hand")]
    np.testing.assert_allclose(clean.rotations[:, upper], raw.rotations[:, upper])
    P = clean.positions()
    left, right = foot_joints(clean.skeleton)
    assert P[:, left + right, 1].min() > -0.01
    assert foot_skate(P, clean.fps, clean.skeleton)["mean_m_s"] <= foot_skate(
        raw.positions(), raw.fps, raw.skeleton)["mean_m_s"] + 1e-9


def test_generation_rejects_short_seed_and_bad_emotions(tiny_net):
    short = walk(WalkParams(), straight(5.0), 40, 30.0)
    with pytest.raises(ValueError, match="seed gait 0"):
        generate_gaits([short], [straight(5.0)], np.array([[1, 0, 0, 0]]), steps=5, model=tiny_net)
    seed = walk(WalkParams(), straight(10.0), 80, 30.0)
    with pytest.raises(ValueError, match="emotions must be"):
        generate_gaits([seed], [straight(5.0)], np.ones((2, 4)), steps=5, model=tiny_net)


def test_generated_motion_exports_to_bvh(tiny_net, tmp_path):
    seed = walk(WalkParams(), straight(10.0), 80, 30.0)
    (m,) = generate_gaits([seed], [straight(10.0)], np.array([[0, 0, 0, 1.0]]), steps=8, model=tiny_net)
    bvh.write_bvh(m, tmp_path / "g.bvh")
    back = bvh.read_bvh(tmp_path / "g.bvh")
    assert back.num_frames == m.num_frames


def test_shipped_weights_walk_with_the_asked_emotion():
    """The shipped (procedural-corpus) weights are in the repository, load, and generate walks whose speed follows
    the emotion asked for: sad slower than happy and angry, from the same seed walk and path."""
    assert DEFAULT_WEIGHTS.is_file(), f"shipped weights missing: {DEFAULT_WEIGHTS}"
    assert DEFAULT_WEIGHTS.stat().st_size < 10 * 2 ** 20
    net = load_model(DEFAULT_WEIGHTS)
    # Fine-tuned from the previous weights with the style term (docs/benchmarks/gait.md).
    assert net.config.model == GaitNetConfig().model and net.fps == 7.5
    assert net.config.loss.style > 0 and net.config.train.extra_steps > 0
    assert net.info["trained_on"] == "synthetic procedural corpus" and net.device.type == "cpu"
    seed = walk(WalkParams(), straight(10.0), 80, 30.0)
    (m,) = generate_gaits([seed], [curved(5.0, 1.0, 15.0)], np.array([[0.7, 0.1, 0.1, 0.1]]), steps=30, model=net)
    assert m.num_frames == 29 * 4 + 1
    ms = generate_gaits([seed] * 3, [straight(30.0)] * 3, np.eye(4)[:3] * 0.7 + 0.075, steps=60, model=net,
                        rng_seed=0)
    happy, sad, angry = (np.linalg.norm(m.root_positions[-1, [0, 2]] - m.root_positions[0, [0, 2]]) / m.duration
                         for m in ms)
    assert sad < happy - 0.03 and sad < angry - 0.03 and sad > 0.8, (happy, sad, angry)
