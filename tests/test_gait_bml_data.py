"""Fine-tuning data from both real corpora: looped BML clips lengthened, acted and soft emotion vectors, and the
typed record of what the sequences are, which training needs."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from generation.core.digest import file_sha256
from generation.core.motion import Motion
from generation.gait.bml_data import emotion_for, extend_loop, load_both_sequences
from generation.gait.config import GaitDataConfig, GaitNetConfig
from generation.gait.train import train
from generation.mocap.emotion_gait_bml import DATASET as BML_DATASET
from generation.mocap.real_corpus import CorpusClip, save_real_corpus
from generation.procedural.emotion import gait_params_for_emotion
from generation.procedural.walk import walk
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS


@pytest.fixture(scope="module")
def looped():
    """A procedural walk cut to a 30-frame cycle repeated to 75 frames (as the BML clips are)."""
    m = walk(gait_params_for_emotion(np.eye(4)[0]), n_frames=75, fps=30.0)
    L = 30
    r = np.arange(75) % L
    step = m.root_positions[L] - m.root_positions[0]
    step[1] = 0
    root = m.root_positions[r] + (np.arange(75) // L)[:, None] * step
    m.rotations, m.root_positions = m.rotations[r], root
    m.metadata.update(loop_period_frames=L, acted_label="angry", perceived_label="happy")
    return m


def test_extend_loop_repeats_the_cycle_and_keeps_walking(looped):
    long = extend_loop(looped, 150)
    assert long.num_frames == 150 and long.metadata["extended_from_frames"] == 75
    np.testing.assert_allclose(long.rotations[:75], looped.rotations)
    np.testing.assert_allclose(long.root_positions[:75], looped.root_positions, atol=1e-9)
    np.testing.assert_allclose(long.rotations[120:150], looped.rotations[0:30])
    travel = np.linalg.norm(long.root_positions[-1, [0, 2]] - long.root_positions[0, [0, 2]])
    assert travel > 1.8 * np.linalg.norm(looped.root_positions[-1, [0, 2]] - looped.root_positions[0, [0, 2]])
    assert extend_loop(looped, 50) is looped


def test_emotion_vectors_acted_and_soft(looped):
    clip = CorpusClip("x", "emotion-gait-bml", "walk", "angry", "angry", 1, "train", "gait", looped)
    np.testing.assert_allclose(emotion_for(clip, "acted"), [0, 0, 1, 0])
    np.testing.assert_allclose(emotion_for(clip, "soft"), [0.5, 0, 0.5, 0])
    bandai = CorpusClip("y", "bandai-namco-1", "walk", "normal", "neutral", 1, "train", "gait",
                        walk(gait_params_for_emotion(np.eye(4)[3]), n_frames=40, fps=30.0))
    np.testing.assert_allclose(emotion_for(bandai, "soft"), [0, 0, 0, 1])
    with pytest.raises(ValueError):
        emotion_for(clip, "perceived-only")


def _corpus_clip(name, dataset, style, split, motion):
    return CorpusClip(name, dataset, "walk", style, style, 1, split, "gait", motion)


def _bml_walk(looped, acted: str, perceived: str):
    m = Motion(looped.skeleton, looped.rotations.copy(), looped.root_positions.copy(), looped.fps,
               {**looped.metadata, "acted_label": acted, "perceived_label": perceived})
    return m


@pytest.fixture(scope="module")
def both_corpora(tmp_path_factory, looped):
    """A Bandai-like corpus (dataset 1's four emotion walks, take 1) and a BML-like corpus (looped 75-frame walks of
    train and val performers, acted and perceived labels), each a file as the importers write them."""
    folder = tmp_path_factory.mktemp("both")
    bandai = [_corpus_clip(f"dataset-1_walk_{style}_001", "bandai-namco-1", style, "train",
                           walk(gait_params_for_emotion(np.eye(4)[i]), n_frames=60, fps=30.0))
              for i, style in enumerate(CAPTURE_GAIT_EMOTIONS)]
    bml = [_corpus_clip("BML_aaa_angry", BML_DATASET, "angry", "train", _bml_walk(looped, "angry", "happy")),
           _corpus_clip("BML_aaa_sad", BML_DATASET, "sad", "train", _bml_walk(looped, "sad", "sad")),
           _corpus_clip("BML_bbb_happy", BML_DATASET, "happy", "val", _bml_walk(looped, "happy", "neutral"))]
    split = {"train": ["BML_aaa"], "val": ["BML_bbb"], "test": []}
    return (save_real_corpus(folder / "bandai.npz", bandai, {"split_rule": "synthetic"}),
            save_real_corpus(folder / "bml.npz", bml, {"split_rule": "synthetic", "performer_split": split}))


def test_both_corpora_say_what_they_are_and_train(both_corpora, tmp_path):
    bandai, bml = both_corpora
    data = load_both_sequences(GaitDataConfig(seq_len=12), "soft", bandai_path=bandai, bml_path=bml)
    training = data.training_data
    assert training.kind == "real" and training.datasets == ("bandai-namco-1", BML_DATASET)
    assert "soft emotion labels" in training.description
    assert [d["sha256"] for d in training.corpus["datasets"]] == [file_sha256(bandai), file_sha256(bml)]
    assert len(data.clip_names) == int(data.base_index.max()) + 1
    assert set(data.split) == {"train", "val"}
    out = tmp_path / "both.pt"
    train(GaitNetConfig.tiny(epochs=1, seq_len=12), data, out, tmp_path / "both.ckpt", progress=False,
          log=lambda *_: None, device="cpu")
    payload = torch.load(out, weights_only=False)
    assert payload["training_data"] == training.record() and payload["trained_on"] == training.description
