"""Fine-tuning data from both real corpora: looped BML clips lengthened, acted and soft emotion vectors."""
from __future__ import annotations

import numpy as np
import pytest

from generation.gait.bml_data import emotion_for, extend_loop
from generation.mocap.real_corpus import CorpusClip
from generation.procedural.emotion import gait_params_for_emotion
from generation.procedural.walk import walk


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
