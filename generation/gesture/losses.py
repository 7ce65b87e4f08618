"""Training losses of seed 003 section 4 (eqs. 8-11), plus the velocity and liveliness terms.

All take predicted and ground-truth local rotations (B, T, J, 4) unit quaternions and a frame mask (B, T) bool
(True = a real frame, False = padding), and return a scalar: the paper's sums, divided by the number of valid
frames (and joints) so the value does not grow with batch or sequence length.

Why the two extra terms: with eqs. 8-10 alone the network regressed to the mean pose: the wrists are
4 of 23 joints in the position and angle sums, and where the beat phase is uncertain the squared error is smallest
for a damped, averaged stroke. Generated gestures moved at about half the corpus' wrist speed and their peak speed
hardly followed arousal. Seed 003 section 4 trains on velocities as well; :func:`velocity_loss` is that term on
joint positions, and :func:`liveliness_loss` compares each sequence's wrist-speed statistics (each wrist's mean and
RMS), which do not depend on the phase, so an averaged, motionless answer is no longer the cheapest one.

``LossWeights.liveliness_form = "log_peak"`` (opt-in, not what the shipped weights were trained with) adds the
faster wrist's clip mean and 90th percentile (the statistics the liveliness benchmark judges) and compares all of
them as squared log ratios, since the goal is a ratio: a squared difference in m/s lets a slow emotion's too-high peak
(neutral: 0.54 vs 0.43 m/s) cost a fifth of a fast one's shortfall. It brought neutral's peak into the goal band but
not joyous' mean (docs/benchmarks/gesture.md, liveliness section).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import torch

from generation.core.features import gesture_affective_features
from generation.core.kinematics import forward_kinematics
from generation.core.quaternion import qeuler

from .real_range import real_range_loss

EULER_ORDER = "zyx"
WRISTS = (10, 14)  # left_wrist, right_wrist on the 23-joint gesture skeleton


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
    return _position_loss(_positions(pred, offsets, parents), _positions(target, offsets, parents), mask)


def _position_loss(p_pred: torch.Tensor, p_true: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    J = p_pred.shape[-2]
    return _masked_mean(((p_pred - p_true) ** 2).sum((-1, -2)) / J, mask)


def velocity_loss(p_pred: torch.Tensor, p_true: torch.Tensor, mask: torch.Tensor, fps: float) -> torch.Tensor:
    """Squared joint-velocity differences ((m/s)^2), summed over joints / J, mean over valid frame pairs.

    p_pred, p_true (B, T, J, 3) joint positions in metres; mask (B, T); fps the frame rate.
    """
    J = p_pred.shape[-2]
    v_pred = (p_pred[:, 1:] - p_pred[:, :-1]) * fps
    v_true = (p_true[:, 1:] - p_true[:, :-1]) * fps
    return _masked_mean(((v_pred - v_true) ** 2).sum((-1, -2)) / J, mask[:, 1:] & mask[:, :-1])


def wrist_speed_statistics(positions: torch.Tensor, mask: torch.Tensor, fps: float) -> torch.Tensor:
    """Per sequence and wrist: mean and RMS speed (m/s) over valid frame pairs.

    positions (B, T, J, 3) metres; mask (B, T) -> (B, 2 wrists, 2 = [mean, rms]).
    """
    w = positions[:, :, list(WRISTS)]
    speed2 = ((w[:, 1:] - w[:, :-1]) ** 2).sum(-1) * fps * fps  # (B, T-1, 2)
    pair = (mask[:, 1:] & mask[:, :-1]).to(speed2.dtype)[..., None]
    n = pair.sum(1).clamp_min(1.0)
    mean = ((speed2 + 1e-8).sqrt() * pair).sum(1) / n
    rms = ((speed2 * pair).sum(1) / n + 1e-8).sqrt()
    return torch.stack((mean, rms), dim=-1)


def peak_wrist_speed(positions: torch.Tensor, mask: torch.Tensor, fps: float, q: float = 0.9) -> torch.Tensor:
    """Per sequence, the faster wrist's speed per frame pair (m/s): its mean and its ``q`` quantile over the valid
    pairs (linear interpolation, as ``np.percentile``), i.e. :func:`generation.gesture.metrics.wrist_speed_of_positions`
    in torch (differentiable).

    positions (B, T, J, 3) metres; mask (B, T) -> (B, 2 = [mean, quantile]).
    """
    w = positions[:, :, list(WRISTS)]
    speed = ((((w[:, 1:] - w[:, :-1]) ** 2).sum(-1) + 1e-8).sqrt() * fps).amax(-1)  # (B, T-1)
    pair = mask[:, 1:] & mask[:, :-1]
    n = pair.sum(1)
    mean = (speed * pair).sum(1) / n.clamp_min(1)
    ordered = torch.where(pair, speed, speed.new_full((), -1.0)).sort(dim=1, descending=True).values
    k = (1.0 - q) * (n - 1).clamp_min(0).to(speed.dtype)  # position of the quantile counted from the top
    lo = k.floor().long()
    hi = (lo + 1).clamp_max((n - 1).clamp_min(0))
    frac = k - lo.to(speed.dtype)
    top = ordered.gather(1, lo[:, None])[:, 0] * (1 - frac) + ordered.gather(1, hi[:, None])[:, 0] * frac
    return torch.stack((mean, torch.where(n > 0, top, torch.zeros_like(top))), dim=-1)


SPEED_FLOOR = 0.05  # m/s added to both speeds of a log ratio, so a near-still clip does not dominate
LIVELINESS_FORMS = ("speed", "log_peak")


def liveliness_loss(p_pred: torch.Tensor, p_true: torch.Tensor, mask: torch.Tensor, fps: float,
                    form: str = "speed") -> torch.Tensor:
    """Phase-independent comparison of per-sequence wrist-speed statistics; mean over sequences and statistics.

    form "speed": squared differences ((m/s)^2) of each wrist's mean and RMS speed (:func:`wrist_speed_statistics`).
    form "log_peak": squared log ratios of those and of the faster wrist's mean and 90th percentile
    (:func:`peak_wrist_speed`), ``SPEED_FLOOR`` added to both speeds (dimensionless).
    """
    if form == "speed":
        return ((wrist_speed_statistics(p_pred, mask, fps) - wrist_speed_statistics(p_true, mask, fps)) ** 2).mean()
    if form != "log_peak":
        raise ValueError(f"liveliness form must be one of {LIVELINESS_FORMS}, got {form!r}")
    pred = torch.cat((wrist_speed_statistics(p_pred, mask, fps).flatten(1), peak_wrist_speed(p_pred, mask, fps)), 1)
    true = torch.cat((wrist_speed_statistics(p_true, mask, fps).flatten(1), peak_wrist_speed(p_true, mask, fps)), 1)
    return (torch.log((pred + SPEED_FLOOR) / (true + SPEED_FLOOR)) ** 2).mean()


def affective_loss(pred: torch.Tensor, target: torch.Tensor, mask: torch.Tensor, offsets: torch.Tensor,
                   parents) -> torch.Tensor:
    """Eq. 10: squared distance between the 15 gesture affective features of predicted and true poses."""
    return _affective_loss(_positions(pred, offsets, parents), _positions(target, offsets, parents), mask)


def _affective_loss(p_pred: torch.Tensor, p_true: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    a_pred = gesture_affective_features(p_pred)
    a_true = gesture_affective_features(p_true)
    return _masked_mean(((a_pred - a_true) ** 2).sum(-1), mask)


@dataclass
class LossWeights:
    """Weights of eq. 11's terms and of the velocity and liveliness terms; 0 removes a term (the ablations of
    seed 003 Table 1).

    The paper sums the terms with weight 1; here the terms have different units (rad^2, m^2, feature units,
    (m/s)^2), so they are weighted to contribute about equally during training.
    Weight decay (lambda ||W||) is the optimiser's ``weight_decay``.
    """

    angle: float = 1.0
    pose: float = 100.0
    affective: float = 0.5
    velocity: float = 1.0
    liveliness: float = 2.0
    liveliness_form: str = "speed"  # or "log_peak" (:func:`liveliness_loss`)
    # keep each sequence's speed, reach, holds and head motion within the real captured range of its emotion
    # (generation.gesture.real_range; off for the weights before it)
    real_range: float = 0.0


def total_loss(pred, target, mask, offsets, parents, weights: LossWeights,
               fps: float = 10.0, real_bounds: tuple | None = None) -> tuple[torch.Tensor, dict]:
    """Weighted sum of the terms -> (scalar, {"angle", "pose", "affective", "velocity", "liveliness",
    "real_range": float}).

    Terms with weight 0 are skipped; forward kinematics runs once for all position-based terms. ``fps`` is the
    frame rate of the sequences (for the velocities). ``real_bounds`` = (lo, hi), each (B, 6), the real captured
    range of each sequence's emotion (:func:`generation.gesture.real_range.range_arrays`), needed when
    ``weights.real_range`` > 0.
    """
    parts: dict[str, torch.Tensor] = {}
    if weights.angle:
        parts["angle"] = angle_loss(pred, target, mask)
    if weights.pose or weights.affective or weights.velocity or weights.liveliness or weights.real_range:
        p_pred, p_true = _positions(pred, offsets, parents), _positions(target, offsets, parents)
        if weights.real_range:
            if real_bounds is None:
                raise ValueError("the real_range loss needs real_bounds (lo, hi) per sequence")
            parts["real_range"] = real_range_loss(p_pred, mask, fps, *real_bounds)
        if weights.pose:
            parts["pose"] = _position_loss(p_pred, p_true, mask)
        if weights.affective:
            parts["affective"] = _affective_loss(p_pred, p_true, mask)
        if weights.velocity:
            parts["velocity"] = velocity_loss(p_pred, p_true, mask, fps)
        if weights.liveliness:
            parts["liveliness"] = liveliness_loss(p_pred, p_true, mask, fps, weights.liveliness_form)
    if not parts:
        raise ValueError("all loss weights are zero")
    total = sum(getattr(weights, k) * v for k, v in parts.items())
    return total, {k: float(v.detach()) for k, v in parts.items()}
