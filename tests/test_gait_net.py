"""Tests of the seed 000 gait network: model, losses, data features, training, generation, shipped weights."""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from generation.core.motion import Motion
from generation.core.paths import curved, sharp_turn, straight
from generation.core.rigging import yaw_quat
from generation.formats import bvh
from generation.gait.config import (
    GaitDataConfig,
    GaitLossWeights,
    GaitModelConfig,
    GaitNetConfig,
    GaitTrainConfig,
)
from generation.gait.data import Normalizer, from_heading_frame, prepare_sequences, root_features, to_heading_frame
from generation.gait.generate import (
    LoadedGaitNet,
    emotion_transition,
    generate_gaits,
    load_default_model,
    load_model,
    normalize_emotion,
)
from generation.gait.losses import motion_loss, total_loss
from generation.gait.model import GaitNet
from generation.gait.train import (
    DEFAULT_WEIGHTS,
    fit_normalizer,
    ground_truth_targets,
    load_checkpoint,
    rollout,
    save_checkpoint,
    splice_histories,
    train,
)
from generation.procedural.walk import WalkParams, walk

torch.set_num_threads(1)


@pytest.fixture(scope="module")
def tiny_data():
    """Six short synthetic procedural walks (2 per split) with one-hot emotions."""
    rng = np.random.default_rng(0)
    rots, roots, emo = [], [], []
    for i in range(6):
        params = WalkParams(cadence_spm=rng.uniform(95, 125), stride_m=rng.uniform(1.1, 1.5),
                            torso_pitch_rad=rng.uniform(-0.05, 0.3))
        path = curved(5.0, 0.8) if i % 2 else straight(12.0)
        m = walk(params, path, 240, 30.0, phase=float(rng.random()))
        rots.append(m.rotations)
        roots.append(m.root_positions)
        emo.append(np.eye(4)[i % 4])
    split = np.array(["train", "train", "val", "val", "test", "test"])
    return prepare_sequences(np.stack(rots), np.stack(roots), np.stack(emo), split, np.full(6, 1.75),
                             np.array(["male"] * 6))


@pytest.fixture(scope="module")
def tiny_net(tiny_data):
    torch.manual_seed(0)
    cfg = GaitNetConfig.tiny()
    return LoadedGaitNet(GaitNet(cfg.model), fit_normalizer(tiny_data.subset("train")), "tiny.pt", config=cfg)


def test_model_shapes_and_unit_quaternions():
    net = GaitNet(GaitModelConfig.tiny(residual=False))
    N, L = 3, 5
    out = net(torch.randn(N, L, 21, 4), torch.randn(N, L, 18), torch.randn(N, L, 5), torch.randn(N, L, 3),
              torch.rand(N, L, 4))
    assert out["q"].shape == (N, L, 21, 4)
    assert out["root"].shape == (N, L, 3) and out["omega"].shape == (N, L)
    assert torch.allclose(out["q"].norm(dim=-1), torch.ones(N, L, 21), atol=1e-5)
    one = net.step(torch.randn(N, 21, 4), torch.randn(N, 18), torch.randn(N, 5), torch.randn(N, 3), torch.rand(N, 4))
    assert one["q"].shape == (N, 21, 4)


def test_config_dicts_round_trip_by_section_and_name_bad_keys():
    odd = GaitNetConfig().with_overrides(gru_hidden=64, lambda_root=0.0, tf_decay=0.5, frame_step=2,
                                         pos_scale_m=0.2, notes={"run": "x"})
    assert odd.model == GaitModelConfig(gru_hidden=64)
    assert odd.loss == GaitLossWeights(root=0.0, pos_scale_m=0.2)
    assert odd.train == GaitTrainConfig(tf_decay=0.5) and odd.data == GaitDataConfig(frame_step=2)
    # The split form round-trips, tuples included.
    assert GaitNetConfig.from_dict(odd.to_dict()) == odd
    assert set(odd.to_dict()) == {"model", "data", "train", "loss", "notes"}
    assert GaitNetConfig.from_dict(GaitNetConfig.tiny().to_dict()).model.enc1_sizes == (8, 8)
    # A field missing from a stored section takes its default.
    partial = GaitNetConfig.tiny().to_dict()
    del partial["loss"]["class_style"]
    assert GaitNetConfig.from_dict(partial).loss.class_style == GaitLossWeights().class_style
    with pytest.raises(ValueError, match="unknown GaitModelConfig fields"):
        GaitNetConfig.from_dict({"model": {"gru_hiden": 3}})
    with pytest.raises(ValueError, match="unknown GaitNetConfig fields"):
        GaitNetConfig.from_dict({"model": {}, "optimiser": {}})
    # A flat dict (not split by section) is not a config.
    with pytest.raises(ValueError, match=r"unknown GaitNetConfig fields \['enc1_sizes'"):
        GaitNetConfig.from_dict({"enc1_sizes": [16, 16, 8], "gru_hidden": 256, "lambda_root": 1.0})
    with pytest.raises(ValueError, match=r"sections \['model'\] must be mappings"):
        GaitNetConfig.from_dict({"model": [1, 2]})


def test_config_overrides_take_flat_and_section_names():
    cfg = GaitNetConfig().with_overrides(gru_hidden=64, lambda_pose=0.5, **{"loss.fctc": 2.0, "train.lr": 0.01,
                                                                           "model.enc2_sizes": [4, 4]})
    assert (cfg.model.gru_hidden, cfg.model.enc2_sizes, cfg.loss.pose, cfg.loss.fctc, cfg.train.lr) == \
        (64, (4, 4), 0.5, 2.0, 0.01)
    assert GaitNetConfig() == GaitNetConfig()   # the default is not changed in place
    with pytest.raises(ValueError, match="unknown GaitNetConfig fields"):
        GaitNetConfig().with_overrides(**{"loss.lambda_pose": 1.0})
    assert GaitNetConfig.paper(epochs=3).train.epochs == 3
    assert GaitNetConfig.paper().model == GaitModelConfig.paper()
    assert GaitNetConfig().prefix_len == GaitDataConfig().prefix_len == 18
    with pytest.raises(TypeError, match="GaitModelConfig"):
        GaitNet(GaitNetConfig.tiny())


def test_emotion_skip_wiring():
    net = GaitNet(GaitModelConfig.tiny(emotion_skip=True))
    q, zeros = torch.randn(2, 3, 21, 4), (torch.zeros(2, 3, 18), torch.zeros(2, 3, 5), torch.zeros(2, 3, 3))
    a = net(q, *zeros, torch.eye(4)[[0, 0]][:, None].expand(2, 3, 4))
    b = net(q, *zeros, torch.eye(4)[[1, 1]][:, None].expand(2, 3, 4))
    assert a["q"].shape == (2, 3, 21, 4) and not torch.allclose(a["hidden"], b["hidden"])


def test_paper_config_has_released_size_and_ablation_drops_affective_branch():
    assert 9.5e6 < GaitNet(GaitNetConfig.paper().model).num_parameters() < 10.5e6
    assert 9.5e6 < GaitNet(GaitModelConfig.paper()).num_parameters() < 10.5e6
    assert GaitNet(GaitNetConfig().model).num_parameters() < 1e6   # the CPU default
    ablated = GaitNet(GaitModelConfig.tiny(use_affective=False))
    assert ablated.fc_enc1 is None
    with pytest.raises(ValueError, match="unknown GaitNetConfig fields"):
        GaitNetConfig.from_dict({"gru_hiden": 3})


def test_motion_loss_is_zero_for_equal_rotations_and_wraps_angles():
    q = torch.nn.functional.normalize(torch.randn(2, 3, 21, 4), dim=-1)
    assert motion_loss(q, q).item() < 1e-8
    assert motion_loss(-q, q).item() < 1e-6       # q and -q are the same rotation
    assert motion_loss(2 * q, q).item() > 0.5      # the unit-norm term of eq. 8


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


def test_tiny_network_overfits_a_tiny_batch(tiny_data):
    torch.manual_seed(0)
    # Without the style term: its walk-to-walk scale (Normalizer.aff_style_std) means nothing for two walks.
    cfg = GaitNetConfig.tiny(gru_hidden=64, versor_hidden=64, lambda_style=0.0)
    net = GaitNet(cfg.model)
    data = tiny_data.subset("train")
    norm = fit_normalizer(data)
    batch = data.batch([0, 1])
    target = ground_truth_targets(batch, norm)
    opt = torch.optim.Adam(net.parameters(), lr=3e-3)
    losses = []
    for _ in range(40):
        loss, _ = total_loss(rollout(net, norm, batch, 1.0, cfg.prefix_len), target, cfg.loss)
        opt.zero_grad()
        loss.backward()
        opt.step()
        losses.append(loss.item())
    assert losses[-1] < 0.6 * losses[0], losses[::10]


def test_splice_histories_switches_history_and_emotion(tiny_data):
    batch = tiny_data.batch(np.arange(6))
    P = GaitNetConfig().prefix_len
    out = splice_histories(batch, P, 1.0, np.random.default_rng(0))
    em = out["emotion"]
    assert em.shape == (6, batch["q"].shape[1], 4)
    assert torch.equal(em[:, P - 1:], batch["emotion"][:, None].expand(-1, em.shape[1] - P + 1, -1))
    dom = batch["emotion"].argmax(-1)
    for b in range(6):
        # The prefix comes from a walk with another dominant emotion, whose label it carries; the rest is b's own.
        src = next(i for i in range(6) if torch.equal(out["q"][b, :P], batch["q"][i, :P]))
        assert dom[src] != dom[b] and torch.equal(em[b, 0], batch["emotion"][src])
        assert torch.equal(out["q"][b, P:], batch["q"][b, P:])
        assert torch.equal(out["theta"][b, P:], batch["theta"][b, P:])
    none = splice_histories(batch, P, 0.0, np.random.default_rng(0))
    assert torch.equal(none["q"], batch["q"]) and torch.equal(none["emotion"][:, 0], batch["emotion"])
    # Per-step emotions go through the rollout.
    cfg = GaitNetConfig.tiny()
    pred = rollout(GaitNet(cfg.model), fit_normalizer(tiny_data.subset("train")), out, 0.5, P)
    assert pred["q"].shape == batch["q"][:, 1:].shape


def test_uniform_labels_replace_a_fraction_of_the_emotion_inputs(tiny_data):
    from generation.gait.train import uniform_labels
    batch = splice_histories(tiny_data.batch(np.arange(len(tiny_data))), 18, 0.0, np.random.default_rng(0))
    none = uniform_labels(batch, 0.0, np.random.default_rng(0))
    assert torch.equal(none["emotion"], batch["emotion"])
    every = uniform_labels(batch, 1.0, np.random.default_rng(0))
    assert torch.allclose(every["emotion"], torch.full_like(batch["emotion"], 0.25))
    assert torch.equal(every["q"], batch["q"])   # only the emotion input changes
    some = uniform_labels(batch, 0.5, np.random.default_rng(3))["emotion"]
    dropped = (some == 0.25).all(-1).all(-1)
    assert dropped.any() and not dropped.all()
    assert torch.equal(some[~dropped], batch["emotion"][~dropped])


def test_training_writes_checkpoint_and_resumes(tiny_data, tmp_path):
    cfg = GaitNetConfig.tiny(epochs=1, batch_size=2)
    out = tmp_path / "w.pt"
    ckpt = tmp_path / "state.ckpt"
    train(cfg, tiny_data, out, ckpt, progress=False, log=lambda *_: None)
    assert out.exists() and ckpt.exists()
    cfg2 = GaitNetConfig.tiny(epochs=2, batch_size=2)
    res = train(cfg2, tiny_data, out, ckpt, resume=True, progress=False, log=lambda *_: None)
    assert [h["epoch"] for h in res["history"]] == [1, 2]
    model, norm, payload = load_checkpoint(out)
    assert payload["trained_on"] == "synthetic procedural corpus" and payload["format"] == "gait_net/2"
    assert GaitNetConfig.from_dict(payload["config"]) == cfg2 and model.config == cfg2.model
    bad = tmp_path / "bad.pt"
    bad.write_bytes(b"not a checkpoint")
    with pytest.raises(ValueError, match="bad.pt"):
        load_checkpoint(bad)


def test_keep_epochs_writes_the_weights_of_every_epoch(tiny_data, tmp_path):
    out = tmp_path / "run.pt"
    train(GaitNetConfig.tiny(epochs=2, batch_size=2), tiny_data, out, tmp_path / "run.ckpt", progress=False,
          log=lambda *_: None, keep_epochs=True)
    assert sorted(p.name for p in tmp_path.glob("run_e*.pt")) == ["run_e01.pt", "run_e02.pt"]
    _, _, first = load_checkpoint(tmp_path / "run_e01.pt")
    _, _, last = load_checkpoint(tmp_path / "run_e02.pt")
    assert [h["epoch"] for h in first["history"]] == [1] and [h["epoch"] for h in last["history"]] == [1, 2]
    assert first["trained_on"] == "synthetic procedural corpus"


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


def test_guidance_scale_choice_and_storage(tiny_net, tmp_path):
    from generation.quality.gait_guidance import choose_scale, lowest_class, write_guidance

    def result(lo):
        return {"val_walk_seeds": {"happy": 0.9, "sad": lo}, "unseen_mixtures": {"happy": 1.0, "sad": 0.95}}
    results = {0.0: result(0.7), 1.0: result(0.85), 2.0: result(0.85), 3.0: result(0.6)}
    assert lowest_class(results[1.0]) == 0.85
    assert choose_scale(results) == 1.0   # the best lowest class; the smaller scale on a tie
    path = tmp_path / "w.pt"
    save_checkpoint(path, tiny_net.model, tiny_net.normalizer, tiny_net.config)
    assert load_model(path).emotion_guidance == 0.0
    write_guidance(path, 1.0, results, "abc")
    loaded = load_model(path)
    assert loaded.emotion_guidance == 1.0 and loaded.config == tiny_net.config
    assert torch.load(path, weights_only=False)["emotion_guidance_selection"]["split"] == "val"


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


def test_normalizer_round_trip():
    rng = np.random.default_rng(1)
    n = Normalizer.fit(rng.normal(size=(50, 18)), rng.normal(size=(50, 3)), rng.normal(size=(50, 3)))
    n2 = Normalizer.from_dict(n.to_dict())
    r = torch.randn(4, 3)
    assert torch.allclose(n2.root_inv(n2.root(r)), r, atol=1e-5)


def test_save_and_load_model(tiny_net, tmp_path):
    path = tmp_path / "m.pt"
    save_checkpoint(path, tiny_net.model, tiny_net.normalizer, tiny_net.config)
    loaded = load_model(path)
    for p, q in zip(loaded.model.parameters(), tiny_net.model.parameters()):
        assert torch.equal(p, q)
    assert loaded.config == tiny_net.config
    # A file of another format is refused, naming the format.
    payload = torch.load(path, weights_only=False)
    other = tmp_path / "other.pt"
    torch.save({**payload, "format": "gait_net/1"}, other)
    with pytest.raises(ValueError, match="checkpoint format 'gait_net/1', expected 'gait_net/2'"):
        load_model(other)


def test_shipped_weights_load_and_generate():
    if not DEFAULT_WEIGHTS.exists():
        pytest.skip(f"shipped weights absent: {DEFAULT_WEIGHTS} (train with `python -m generation.gait.train`)")
    assert DEFAULT_WEIGHTS.stat().st_size < 10 * 2 ** 20
    net = load_default_model()
    # Fine-tuned from the previous weights with the style term (docs/benchmarks/gait.md).
    assert net.config.model == GaitNetConfig().model and net.fps == 7.5
    assert net.config.loss.style > 0 and net.config.train.extra_steps > 0
    assert net.info["trained_on"] == "synthetic procedural corpus" and net.device.type == "cpu"
    seed = walk(WalkParams(), straight(10.0), 80, 30.0)
    (m,) = generate_gaits([seed], [curved(5.0, 1.0, 15.0)], np.array([[0.7, 0.1, 0.1, 0.1]]), steps=30, model=net)
    assert m.num_frames == 29 * 4 + 1
    # It walks: the root covers ground.
    assert np.linalg.norm(m.root_positions[-1, [0, 2]] - m.root_positions[0, [0, 2]]) > 1.0


def test_training_is_deterministic_for_a_seed(tiny_data, tmp_path):
    cfg = GaitNetConfig.tiny(epochs=1, batch_size=2, tf_decay=0.5)
    a = train(cfg, tiny_data, tmp_path / "a.pt", tmp_path / "a.ckpt", progress=False, log=lambda *_: None)
    b = train(cfg, tiny_data, tmp_path / "b.pt", tmp_path / "b.ckpt", progress=False, log=lambda *_: None)
    for p, q in zip(a["model"].parameters(), b["model"].parameters()):
        assert torch.equal(p, q)


def test_command_line_options_build_the_config():
    from generation.gait.train import build_parser, config_from_args
    args = build_parser().parse_args(["--no-root-loss", "--no-affective", "--epochs", "3",
                                      "--set", "gru_hidden=64", "--set", "enc1_sizes=[4, 4]"])
    cfg = config_from_args(args)
    assert cfg.loss.root == 0.0 and not cfg.model.use_affective and cfg.train.epochs == 3
    assert cfg.model.gru_hidden == 64 and cfg.model.enc1_sizes == (4, 4)
    assert cfg.loss == GaitLossWeights(root=0.0) and cfg.data == GaitDataConfig()
    dotted = config_from_args(build_parser().parse_args(["--set", "loss.pose=0.5", "--set", "splice_frac=0",
                                                         "--set", "emotion_skip=false", "--seed", "2"]))
    assert dotted.loss.pose == 0.5 and dotted.train.splice_frac == 0 and not dotted.model.emotion_skip
    assert dotted.train.seed == 2
    paper = config_from_args(build_parser().parse_args(["--paper-size", "--epochs", "5"]))
    assert paper.model == GaitModelConfig.paper() and paper.train.epochs == 5
    with pytest.raises(SystemExit):
        config_from_args(build_parser().parse_args(["--set", "no_such_field=1"]))


def test_style_loss_is_phase_free_and_penalises_lost_amplitude():
    from generation.gait.losses import style_loss, window_statistics
    t = torch.linspace(0, 4 * math.pi, 40)
    rng = torch.Generator().manual_seed(0)
    base_pos = torch.randn(3, 1, 21, 3, generator=rng)
    wave = torch.sin(t)[None, :, None, None] * torch.randn(3, 1, 21, 3, generator=rng) * 0.2
    pos = base_pos + wave                                                    # (3, 40, 21, 3) a periodic motion
    aff = torch.sin(t)[None, :, None] * torch.randn(3, 1, 18, generator=rng) + torch.randn(3, 1, 18, generator=rng)
    assert window_statistics(aff, pos).shape == (3, 2 * 18 + 20)
    assert style_loss([(aff, pos)], aff, pos).item() < 1e-6
    half = len(t) // 2   # the same motion half a cycle later: same statistics
    shifted = style_loss([(aff.roll(half, 1), pos.roll(half, 1))], aff, pos).item()
    frozen = style_loss([(aff.mean(1, keepdim=True).expand_as(aff), pos.mean(1, keepdim=True).expand_as(pos))],
                        aff, pos).item()
    assert shifted < 1e-3 < 0.1 < frozen   # a frozen (mean) pose loses the amplitude and is penalised


def test_class_style_loss_costs_a_shared_offset_not_walk_noise():
    from generation.gait.losses import class_style_loss
    rng = torch.Generator().manual_seed(1)
    true = torch.randn(8, 20, 18, generator=rng)
    emotion = torch.eye(4).repeat(2, 1)                  # walks 0-3 and 4-7: one of each class twice
    noise = torch.randn(8, 1, 18, generator=rng)
    noise[4:] = -noise[:4]                               # per-walk offsets that cancel within each class
    assert class_style_loss([true + noise], true, emotion).item() < 1e-10
    shared = torch.zeros(8, 1, 18)
    shared[emotion[:, 2] == 1] = 0.5                     # every angry walk moved the same way
    assert class_style_loss([true + shared], true, emotion).item() == pytest.approx(0.25 / 4)
    scale = torch.full((18,), 2.0)
    assert class_style_loss([true + shared], true, emotion, scale).item() == pytest.approx(1.0 / 4)
    absent = torch.tensor([[1.0, 0, 0, 0]] * 8)          # classes absent from the batch add nothing
    assert class_style_loss([true + 0.5], true, absent).item() == pytest.approx(0.25 / 4)


def test_single_dominant_leaves_out_tied_labels():
    from generation.quality.gait_guidance import single_dominant
    labels = np.array([[0.4, 0.0, 0.4, 0.2], [0.6, 0.0, 0.0, 0.4], [0.3, 0.3, 0.3, 0.1], [1.0, 0, 0, 0]])
    assert single_dominant(labels).tolist() == [False, True, False, True]


def test_rollout_continues_free_running_past_the_data(tiny_data):
    cfg = GaitNetConfig.tiny(extra_steps=5)
    net = GaitNet(cfg.model)
    norm = fit_normalizer(tiny_data.subset("train"))
    batch = tiny_data.batch([0, 1])
    pred = rollout(net, norm, batch, 0.5, cfg.prefix_len, extra_steps=5)
    assert pred["ext_aff"].shape == (2, 5, 18) and pred["ext_pos"].shape == (2, 5, 21, 3)
    assert pred["q"].shape == batch["q"][:, 1:].shape
    _, terms = total_loss(pred, ground_truth_targets(batch, norm), cfg.loss, style_from=cfg.prefix_len - 1)
    assert terms["style"] > 0
    _, none = total_loss(pred, ground_truth_targets(batch, norm), GaitLossWeights(style=0.0))
    assert "style" not in none and "class_style" not in terms
    targets = ground_truth_targets(batch, norm)
    assert targets["emotion"].shape == (2, batch["emotion"].shape[-1])
    _, with_class = total_loss(pred, targets, GaitLossWeights(class_style=2.0), style_from=cfg.prefix_len - 1)
    assert with_class["class_style"] >= 0
    assert GaitNetConfig.tiny(tf_start=0.3).train.tf_start == 0.3
    assert GaitNetConfig.tiny(lambda_class_style=4).loss.class_style == 4


def test_fine_tuning_starts_from_a_weights_file(tiny_data, tmp_path):
    cfg = GaitNetConfig.tiny(epochs=1, batch_size=2)
    first = train(cfg, tiny_data, tmp_path / "a.pt", tmp_path / "a.ckpt", progress=False, log=lambda *_: None)
    tuned = train(cfg.with_overrides(tf_start=0.2), tiny_data, tmp_path / "b.pt", tmp_path / "b.ckpt",
                  progress=False, log=lambda *_: None, init=tmp_path / "a.pt")
    assert tuned["history"][0]["tf"] == pytest.approx(0.2)
    assert load_checkpoint(tmp_path / "b.pt")[2]["initialised_from"]["path"] == str(tmp_path / "a.pt")
    assert not all(torch.equal(p, q) for p, q in zip(first["model"].parameters(), tuned["model"].parameters()))
    with pytest.raises(ValueError, match="architecture"):
        train(GaitNetConfig.tiny(epochs=1, gru_hidden=16), tiny_data, tmp_path / "c.pt", tmp_path / "c.ckpt",
              progress=False, log=lambda *_: None, init=tmp_path / "a.pt")
