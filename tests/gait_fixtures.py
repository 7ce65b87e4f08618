"""Shared fixtures of the gait network tests: six tiny synthetic walks and a network trained on them."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from generation.core.paths import curved, straight
from generation.gait.config import GaitNetConfig
from generation.gait.data import prepare_sequences
from generation.gait.generate import LoadedGaitNet
from generation.gait.model import GaitNet
from generation.gait.train import fit_normalizer
from generation.gait.weights import TrainingData
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
                             np.array(["male"] * 6), training_data=TrainingData.procedural())


@pytest.fixture(scope="module")
def tiny_net(tiny_data):
    torch.manual_seed(0)
    cfg = GaitNetConfig.tiny()
    return LoadedGaitNet(GaitNet(cfg.model), fit_normalizer(tiny_data.subset("train")), "tiny.pt", config=cfg)
