"""Training losses of seed 003 section 4 (eqs. 8-11).

All take predicted and ground-truth local rotations (B, T, J, 4) unit quaternions and a frame mask (B, T) bool
(True = a real frame, False = padding), and return a scalar: the paper's sums, divided by the number of valid
frames (and joints) so the value does not grow with batch or sequence length.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import torch

from generation.core.kinematics import forward_kinematics
from generation.core.quaternion import qeuler

EULER_ORDER = "zyx"


def _wrap(angle: torch.Tensor) -> torch.Tensor:
    """Angles to (-pi, pi] (differentiable)."""
    return torch.remainder(angle + math.pi, 2 * math.pi) - math.pi


def align_signs(pred: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Flip predicted quaternions (..., 4) onto the target's hemisphere (q and -q are the same rotation)."""
    sign = torch.where((pred * target).sum(-1, keepdim=True) < 0, -1.0, 1.0)
    return pred * sign


def _masked_mean(values: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """values (B, T) summed over valid frames / number of valid frames."""
    mask = mask.to(values.dtype)
    return (values * mask).sum() / mask.sum().clamp_min(1.0)


def angle_loss(pred: torch.Tensor, target: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Eq. 8: squared Euler-angle differences plus squared differences of their frame-to-frame derivatives.

    pred, target (B, T, J, 4); mask (B, T). Angle differences are wrapped to (-pi, pi]. Per frame, the sum over
    joints and axes is divided by J.
    """
    J = pred.shape[-2]
    diff = _wrap(qeuler(target, EULER_ORDER) - qeuler(align_signs(pred, target), EULER_ORDER))  # (B, T, J, 3)
    absolute = (diff ** 2).sum((-1, -2)) / J
    # (Eul q_t - Eul q_{t-1}) - (Eul q^_t - Eul q^_{t-1}) = diff_t - diff_{t-1}
    derivative = (_wrap(diff[:, 1:] - diff[:, :-1]) ** 2).sum((-1, -2)) / J
    return _masked_mean(absolute, mask) + _masked_mean(derivative, mask[:, 1:] & mask[:, :-1])


def _positions(rotations: torch.Tensor, offsets: torch.Tensor, parents) -> torch.Tensor:
    """(B, T, J, 4), offsets (B, J, 3) -> (B, T, J, 3), root at the origin (the seated root does not move)."""
    root = rotations.new_zeros(rotations.shape[:-2] + (3,))
    return forward_kinematics(rotations, root, offsets[:, None].to(rotations.dtype), parents)


def pose_loss(pred: torch.Tensor, target: torch.Tensor, mask: torch.Tensor, offsets: torch.Tensor,
              parents) -> torch.Tensor:
    """Eq. 9: squared distances (m^2) between FK joint positions, summed over joints / J, mean over frames.

    offsets (B, J, 3) metres (each sample's body build); parents the J parent indices.
    """
    J = pred.shape[-2]
    err = ((_positions(pred, offsets, parents) - _positions(target, offsets, parents)) ** 2).sum((-1, -2)) / J
    return _masked_mean(err, mask)


def affective_loss(pred: torch.Tensor, target: torch.Tensor, mask: torch.Tensor, offsets: torch.Tensor,
                   parents) -> torch.Tensor:
    """Eq. 10: squared distance between the 15 gesture affective features of predicted and true poses."""
    from generation.core.features import gesture_affective_features

    a_pred = gesture_affective_features(_positions(pred, offsets, parents))
    a_true = gesture_affective_features(_positions(target, offsets, parents))
    return _masked_mean(((a_pred - a_true) ** 2).sum(-1), mask)


@dataclass
class LossWeights:
    """Weights of eq. 11's terms; 0 removes a term (the ablations of seed 003 Table 1).

    The paper sums the terms with weight 1; here the terms have different units (rad^2, m^2, feature units), so
    they are weighted to contribute about equally during training.
    Weight decay (lambda ||W||) is the optimiser's ``weight_decay``.
    """

    angle: float = 1.0
    pose: float = 100.0
    affective: float = 0.5


def total_loss(pred, target, mask, offsets, parents, weights: LossWeights) -> tuple[torch.Tensor, dict]:
    """Weighted sum of eqs. 8-10 -> (scalar, {"angle", "pose", "affective": float}) (terms with weight 0 skipped)."""
    parts: dict[str, torch.Tensor] = {}
    if weights.angle:
        parts["angle"] = angle_loss(pred, target, mask)
    if weights.pose:
        parts["pose"] = pose_loss(pred, target, mask, offsets, parents)
    if weights.affective:
        parts["affective"] = affective_loss(pred, target, mask, offsets, parents)
    if not parts:
        raise ValueError("all loss weights are zero")
    total = sum(getattr(weights, k) * v for k, v in parts.items())
    return total, {k: float(v.detach()) for k, v in parts.items()}
