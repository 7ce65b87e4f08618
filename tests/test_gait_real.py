"""The gait network on real capture: corpus windows, labels, augmentation, named weights and real seeds.

The small corpora here are SYNTHETIC stand-ins (procedural walks saved in the real-corpus file format); the shipped
real walks (Bandai Namco Research Motion Dataset, Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0) serve the
seed and shipped-weights tests.
"""
from __future__ import annotations

import numpy as np
import pytest
import torch

from generation.core.paths import curved, straight
from generation.core.skeleton import gait_skeleton
from generation.core.windows import windows
from generation.gait.config import GaitDataConfig, GaitNetConfig
from generation.gait.real_data import (
    RealAugment,
    clip_sequences,
    emotion_vector,
    load_real_sequences,
    mirror_motion,
    stage_clips,
    time_warp,
)
from generation.gait.weights import NAMED_WEIGHTS, weights_path
from generation.mocap.real_corpus import CorpusClip, save_real_corpus
from generation.procedural.walk import WalkParams, walk
from protocol.vocabulary import GAIT_EMOTIONS

DATA = GaitDataConfig(seq_len=12)     # windows of 45 frames (+3 offsets)


def _walk(frames: int):
    return walk(WalkParams(), straight(40.0), frames, 30.0)


def _clip(name, dataset, content, style, label, take, split, frames=90):
    return CorpusClip(name, dataset, content, style, label, take, split, "gait", _walk(frames))


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    clips = [
        _clip("dataset-1_walk_happy_001", "bandai-namco-1", "walk", "happy", "happy", 1, "train"),
        _clip("dataset-1_walk_happy_002", "bandai-namco-1", "walk", "happy", "happy", 2, "test"),
        _clip("dataset-1_walk_sad_001", "bandai-namco-1", "walk", "sad", "sad", 1, "train", frames=60),
        _clip("dataset-1_walk_proud_001", "bandai-namco-1", "walk", "proud", "proud", 1, "train"),
        _clip("dataset-1_walk-back_happy_001", "bandai-namco-1", "walk-back", "happy", "happy", 1, "train"),
        _clip("dataset-2_walk_normal_001", "bandai-namco-2", "walk", "normal", "neutral", 1, "train"),
        _clip("dataset-2_walk-turn-left_elderly_003", "bandai-namco-2", "walk-turn-left", "elderly", "elderly", 3,
              "val"),
        _clip("dataset-2_walk_active_005", "bandai-namco-2", "walk", "active", "energetic", 5, "test"),
        _clip("dataset-2_walk_normal_002", "bandai-namco-2", "walk", "normal", "neutral", 2, "train", frames=30),
    ]
    return save_real_corpus(tmp_path_factory.mktemp("c") / "corpus.npz", clips, {"split_rule": "synthetic"})


def test_mirror_swaps_sides_and_negates_x():
    m = _walk(40)
    mm = mirror_motion(m)
    p, q = m.positions(), mm.positions()
    swap = m.skeleton.mirror_map()
    assert np.allclose(q[:, swap] * [-1, 1, 1], p, atol=1e-9)
    assert np.allclose(mirror_motion(mm).rotations, m.rotations) and mm.metadata["mirrored"]
    lopsided = gait_skeleton().with_offsets(gait_skeleton().offsets + np.eye(21, 3, k=0) * 0.01)
    with pytest.raises(ValueError, match="symmetric"):
        mirror_motion(type(m)(lopsided, m.rotations, m.root_positions, 30.0))


def test_time_warp_keeps_the_path_and_changes_the_duration():
    m = _walk(91)
    fast = time_warp(m, 1.5)
    assert fast.fps == 30.0 and fast.num_frames == 61
    assert np.allclose(fast.root_positions[-1], m.root_positions[-1], atol=1e-6)
    assert time_warp(m, 1.0) is m
    with pytest.raises(ValueError):
        time_warp(m, 0.0)


def test_training_windows_cover_the_take():
    assert [w.start for w in windows(100, 40, 25)] == [0, 25, 50, 60]
    assert [w.start for w in windows(40, 40, 25)] == [0]
    assert windows(39, 40, 25) == []


def test_labels_one_hot_or_uniform():
    assert emotion_vector("angry").tolist() == [0, 0, 1, 0]
    assert np.allclose(emotion_vector("proud"), 0.25) and np.allclose(emotion_vector("sad", labelled=False), 0.25)
    assert GAIT_EMOTIONS[int(np.argmax(emotion_vector("neutral")))] == "neutral"


def test_stages_take_forward_walks_of_the_split_only(corpus):
    pre = {c.name for c in stage_clips("pretrain", "train", corpus)}
    assert pre == {"dataset-1_walk_happy_001", "dataset-1_walk_sad_001", "dataset-1_walk_proud_001",
                   "dataset-2_walk_normal_001", "dataset-2_walk_normal_002"}      # no walk-back, no test takes
    fine = {c.name for c in stage_clips("finetune", "train", corpus)}
    assert fine == {"dataset-1_walk_happy_001", "dataset-1_walk_sad_001"}
    assert {c.name for c in stage_clips("pretrain", "val", corpus)} == {"dataset-2_walk-turn-left_elderly_003"}
    with pytest.raises(ValueError, match="stage"):
        stage_clips("everything", "train", corpus)


def test_sequences_labels_augmentation_and_split(corpus):
    seqs = load_real_sequences("pretrain", DATA, RealAugment(stride_frames=20), path=corpus)
    assert set(seqs.split) == {"train", "val"}           # test takes never enter
    train = seqs.subset("train")
    labels = {tuple(e) for e in train.emotion.numpy().round(2).tolist()}
    assert labels == {(1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 0, 1), (0.25, 0.25, 0.25, 0.25)}
    # every window appears mirrored at four subsampling offsets (and in up to three speeds)
    assert set(train.offset) == {0, 1, 2, 3} and np.bincount(train.base_index).min() >= 2 * 4
    assert seqs.q.shape[1:] == (DATA.seq_len, 21, 4)
    val = seqs.subset("val")
    assert len(val) == len(np.unique(val.base_index)) and set(val.offset) == {0}   # validation as captured
    assert seqs.training_data.kind == "real" and seqs.training_data.corpus["stage"] == "pretrain"
    assert seqs.training_data.datasets == ("bandai-namco-1", "bandai-namco-2")
    assert "dataset-2_walk_normal_002" not in seqs.clip_names


def test_balanced_windows_per_clip(corpus):
    clips = stage_clips("finetune", "train", corpus)
    seqs = clip_sequences(clips, DATA, RealAugment(mirror=False, speed_factors=(1.0,), offsets=(0,),
                                                   windows_per_clip=5))
    per_label = seqs.emotion.argmax(-1).bincount(minlength=4)
    assert per_label[0] == per_label[1] == 5               # a 90-frame and a 60-frame take, five windows each


def test_training_on_real_windows_records_the_data(corpus, tmp_path):
    from generation.gait.train import build_parser, run
    out = tmp_path / "w.pt"
    args = build_parser().parse_args(["--real", "finetune", "--corpus", str(corpus), "--set", "seq_len=12",
                                      "--set", "gru_hidden=16", "--set", "versor_hidden=16", "--set", "extra_steps=2",
                                      "--epochs", "1", "--batch-size", "8", "--out", str(out), "--quiet",
                                      "--checkpoint", str(tmp_path / "w.ckpt")])
    run(args, log=lambda *_: None)
    payload = torch.load(out, weights_only=False)
    assert payload["trained_on"].startswith("real capture") and payload["corpus"]["stage"] == "finetune"
    assert payload["training_data"]["kind"] == "real" and payload["training_data"]["datasets"] == ["bandai-namco-1"]
    assert GaitNetConfig.from_dict(payload["config"]).data.seq_len == 12


def test_plan_weights_option():
    from generation.plans.generators.gait_net import GAIT_WEIGHTS
    from generation.plans.schema import PlanError, validate_plan
    assert GAIT_WEIGHTS == tuple(NAMED_WEIGHTS)
    entry = {"id": "a", "generator": "gait_net", "origin": "generated", "emotion": [1, 0, 0, 0],
             "trajectory": {"kind": "straight", "length_m": 5}}
    plan = validate_plan({"name": "p", "clips": [{**entry, "weights": "procedural"}]})
    assert plan.entries[0].inputs["weights"] == "procedural"
    assert "weights" not in validate_plan({"name": "p", "clips": [entry]}).entries[0].inputs
    with pytest.raises(PlanError, match="weights"):
        validate_plan({"name": "p", "clips": [{**entry, "weights": "mine"}]})
    with pytest.raises(ValueError, match="unknown gait weights"):
        weights_path("mine")


def test_real_seed_is_a_stretch_of_the_shipped_walk_of_the_emotion():
    from generation.gait.real_seeds import real_seed, shipped_walk
    rng = np.random.default_rng(0)
    seed = real_seed(np.array([0.1, 0.7, 0.1, 0.1]), 40, rng)
    sad = shipped_walk("sad")
    k = seed.metadata["seed_start_frame"]
    assert seed.num_frames == 40 and np.allclose(seed.rotations, sad.rotations[k:k + 40])
    assert seed.metadata["origin"] == "captured" and "sad" in seed.metadata["seed_take"]
    assert seed.metadata["licence"] == "CC BY-NC 4.0"


@pytest.mark.slow
def test_shipped_real_weights_are_the_default_and_generate():
    from generation.gait.generate import emotion_transition, generate_gaits, load_default_model
    if not weights_path("real").exists():
        pytest.fail(f"real-trained weights missing: {weights_path('real')}")
    net = load_default_model()
    assert net.info["trained_on"].startswith("real capture") and net.info["weights_name"] == "real"
    (m,) = generate_gaits(None, [straight(20.0)], np.array([[0, 0, 1.0, 0]]), steps=30, model=net, rng_seed=3)
    meta = m.metadata
    assert meta["weights_name"] == "real" and meta["seed_origin"] == "captured" and "angry" in meta["seed_take"]
    assert meta["training_data_licence"] == "CC BY-NC 4.0"
    assert np.linalg.norm(m.root_positions[-1, [0, 2]] - m.root_positions[0, [0, 2]]) > 1.0   # it walks
    # a 210-step (28 s) transition on a curved path: finite, planted feet, keeps walking to the end
    em = emotion_transition([1, 0, 0, 0], [0, 1, 0, 0], 210)[None]
    (long,) = generate_gaits(None, [curved(5.0, 1.0, 40.0)], em, steps=210, model=net, rng_seed=2)
    assert long.num_frames == 209 * 4 + 1 and np.isfinite(long.rotations).all() and "foot_cleanup" in long.metadata
    assert long.metadata["final_emotion"] == [0.0, 1.0, 0.0, 0.0]
    last = np.linalg.norm(np.diff(long.root_positions[-60:, [0, 2]], axis=0), axis=1).sum()
    assert last > 1.0                                                                   # still walking at the end
    proc = load_default_model(weights="procedural")
    assert proc.info["weights_name"] == "procedural" and proc.info["trained_on"] == "synthetic procedural corpus"
    (p,) = generate_gaits(None, [straight(20.0)], np.array([[0, 0, 1.0, 0]]), steps=10, model=proc)
    assert p.metadata["weights_name"] == "procedural" and p.metadata["seed_origin"] != "captured"
    # the real-trained walks' clean-up may lower the pelvis where a planted foot is out of reach (it does on the
    # angry walk, whose locked stance leg was pulled straight otherwise); the procedural walks' clean-up never does
    assert meta["foot_cleanup"]["pelvis_drop_max_m"] > 0.0
    assert p.metadata["foot_cleanup"]["pelvis_drop_max_m"] == 0.0
