"""The gait network's forward pass: shapes, unit quaternions, the emotion skip wiring."""
from __future__ import annotations

import torch

from generation.gait.config import GaitModelConfig
from generation.gait.model import GaitNet

torch.set_num_threads(1)


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


def test_emotion_skip_wiring():
    net = GaitNet(GaitModelConfig.tiny(emotion_skip=True))
    q, zeros = torch.randn(2, 3, 21, 4), (torch.zeros(2, 3, 18), torch.zeros(2, 3, 5), torch.zeros(2, 3, 3))
    a = net(q, *zeros, torch.eye(4)[[0, 0]][:, None].expand(2, 3, 4))
    b = net(q, *zeros, torch.eye(4)[[1, 1]][:, None].expand(2, 3, 4))
    assert a["q"].shape == (2, 3, 21, 4) and not torch.allclose(a["hidden"], b["hidden"])
