"""Loss terms of the gait network: motion, style and class-style losses."""
from __future__ import annotations

import math

import pytest
import torch

from generation.gait.losses import motion_loss

torch.set_num_threads(1)


def test_motion_loss_is_zero_for_equal_rotations_and_wraps_angles():
    q = torch.nn.functional.normalize(torch.randn(2, 3, 21, 4), dim=-1)
    assert motion_loss(q, q).item() < 1e-8
    assert motion_loss(-q, q).item() < 1e-6       # q and -q are the same rotation
    assert motion_loss(2 * q, q).item() > 0.5      # the unit-norm term of eq. 8


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


def test_bounce_loss_sees_the_root_height_amplitude_not_its_phase():
    from generation.gait.losses import bounce_loss, root_bounce, style_loss
    t = torch.linspace(0, 4 * math.pi, 40)
    pos = torch.zeros(2, 40, 21, 3)
    pos[..., 1] = 0.9 + 0.05 * torch.sin(2 * t)[None, :, None]          # the whole body bounces 5 cm
    assert root_bounce(pos).tolist() == pytest.approx([0.05 / math.sqrt(2) / 0.1] * 2, rel=5e-2)
    damped = pos.clone()
    damped[..., 1] = 0.9 + 0.02 * torch.sin(2 * t)[None, :, None]
    aff = torch.zeros(2, 40, 18)
    assert style_loss([(aff, damped)], aff, pos).item() < 1e-6           # root-relative statistics are blind to it
    assert bounce_loss([pos.roll(7, 1)], pos).item() < 1e-4              # the same bounce at another phase
    assert bounce_loss([damped], pos).item() == pytest.approx((0.03 / math.sqrt(2) / 0.1) ** 2, rel=0.05)
