"""Choosing a gait weights file's emotion-guidance scale (generation.quality.gait_guidance)."""
from __future__ import annotations

import numpy as np
import torch

from generation.gait.generate import load_model
from generation.gait.train import save_checkpoint
from generation.gait.weights import TrainingData

torch.set_num_threads(1)
pytest_plugins = ("gait_fixtures",)   # the tiny_data and tiny_net fixtures


def test_guidance_scale_choice_and_storage(tiny_net, tmp_path):
    from generation.quality.gait_guidance import choose_scale, lowest_class, write_guidance

    def result(lo):
        return {"val_walk_seeds": {"happy": 0.9, "sad": lo}, "unseen_mixtures": {"happy": 1.0, "sad": 0.95}}
    results = {0.0: result(0.7), 1.0: result(0.85), 2.0: result(0.85), 3.0: result(0.6)}
    assert lowest_class(results[1.0]) == 0.85
    assert choose_scale(results) == 1.0   # the best lowest class; the smaller scale on a tie
    path = tmp_path / "w.pt"
    save_checkpoint(path, tiny_net.model, tiny_net.normalizer, tiny_net.config, training_data=TrainingData.procedural())
    assert load_model(path).emotion_guidance == 0.0
    write_guidance(path, 1.0, results, "abc")
    loaded = load_model(path)
    assert loaded.emotion_guidance == 1.0 and loaded.config == tiny_net.config
    assert torch.load(path, weights_only=False)["emotion_guidance_selection"]["split"] == "val"


def test_single_dominant_leaves_out_tied_labels():
    from generation.quality.gait_guidance import single_dominant
    labels = np.array([[0.4, 0.0, 0.4, 0.2], [0.6, 0.0, 0.0, 0.4], [0.3, 0.3, 0.3, 0.1], [1.0, 0, 0, 0]])
    assert single_dominant(labels).tolist() == [False, True, False, True]
