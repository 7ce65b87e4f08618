"""Training losses of seed 000, equations 8-13.

All terms are means over their elements (the paper writes sums; a mean only rescales the weights and
keeps the terms comparable across batch sizes). Features are standardised by the training-set statistics
before they enter a loss, and positions are measured in units of ``GaitLossWeights.pos_scale_m`` metres, so the
paper's weights of 1.0 give terms of similar size.

Shapes: N batch, L predicted steps, J joints.
"""
from __future__ import annotations

import math

import torch

from generation.core.quaternion import qeuler

from .config import GaitLossWeights

FOOT_JOINTS = (3, 4, 7, 8)  # left heel, left toe, right heel, right toe (gait skeleton)
STD_EPS = 1e-4  # added to variances before the square root of the style statistics: finite gradients at rest


def wrap_angle(a: torch.Tensor) -> torch.Tensor:
    """Wrap radians to (-pi, pi]."""
    return torch.remainder(a + math.pi, 2 * math.pi) - math.pi


def motion_loss(q_pred_raw: torch.Tensor, q_true: torch.Tensor, order: str = "zyx",
                lambda_versor: float = 1.0) -> torch.Tensor:
    """Eq. 8: squared Euler-angle differences plus the unit-norm penalty on the raw predicted versors.

    Args:
        q_pred_raw: (N, L, J, 4) predicted quaternions before normalisation.
        q_true: (N, L, J, 4) ground-truth unit quaternions.
    Angle differences are wrapped to (-pi, pi] so that 359 degrees and 1 degree are 2 degrees apart.
    """
    norm = q_pred_raw.norm(dim=-1)
    q_pred = q_pred_raw / norm.unsqueeze(-1).clamp_min(1e-8)
    diff = wrap_angle(qeuler(q_pred, order) - qeuler(q_true, order))
    return (diff ** 2).mean() + lambda_versor * ((norm - 1.0) ** 2).mean()


def pose_loss(pos_pred: torch.Tensor, pos_true: torch.Tensor, scale_m: float = 0.1) -> torch.Tensor:
    """Eq. 9: squared distance of root-relative joint positions (N, L, J, 3), in units of ``scale_m``."""
    rel_pred = pos_pred[..., 1:, :] - pos_pred[..., :1, :]
    rel_true = pos_true[..., 1:, :] - pos_true[..., :1, :]
    return (((rel_pred - rel_true) / scale_m) ** 2).sum(-1).mean()


def affective_loss(aff_pred: torch.Tensor, aff_true: torch.Tensor) -> torch.Tensor:
    """Eq. 10: squared difference of standardised affective features (N, L, 18)."""
    return ((aff_pred - aff_true) ** 2).sum(-1).mean() / aff_pred.shape[-1]


def root_loss(root_pred: torch.Tensor, root_true: torch.Tensor) -> torch.Tensor:
    """Eq. 11: L1 difference of standardised root features [h, s, delta] (N, L, 3)."""
    return (root_pred - root_true).abs().mean()


def foot_contact_loss(pos_pred: torch.Tensor, pos_true: torch.Tensor, scale_m: float = 0.1) -> torch.Tensor:
    """Eq. 12: L1 difference of heel and toe positions (N, L, J, 3) in units of ``scale_m``.

    The positions carry the root height (prediction: mean height + predicted deviation), so this term
    also keeps the feet on the ground.
    """
    idx = list(FOOT_JOINTS)
    return ((pos_pred[..., idx, :] - pos_true[..., idx, :]) / scale_m).abs().mean()


def phase_loss(omega_pred: torch.Tensor, omega_true: torch.Tensor) -> torch.Tensor:
    """L1 on the standardised step-phase increment (N, L); supervises the extra omega head (model.py)."""
    return (omega_pred - omega_true).abs().mean()


def window_statistics(aff: torch.Tensor, pos: torch.Tensor, scale_m: float = 0.1,
                      mean_scale: torch.Tensor | None = None) -> torch.Tensor:
    """Phase-free style statistics of a window of steps: (N, 2 * 18 + J - 1).

    The mean over time of the standardised affective features (N, L, 18), multiplied by ``mean_scale`` (18,)
    (``Normalizer.style_scale``: walk-to-walk units), their standard deviation over time, and the standard
    deviation over time of each root-relative joint position (N, L, J, 3; in units of ``scale_m``, summed over
    x, y, z): the posture an observer of the whole walk sees and the motion amplitude that free-running
    prediction tends to lose.
    """
    rel = (pos[..., 1:, :] - pos[..., :1, :]) / scale_m
    amp = (rel.var(dim=1, unbiased=False).sum(-1) + STD_EPS).sqrt()
    mean = aff.mean(1) if mean_scale is None else aff.mean(1) * mean_scale
    return torch.cat((mean, (aff.var(1, unbiased=False) + STD_EPS).sqrt(), amp), dim=-1)


def style_loss(pred_windows: list[tuple[torch.Tensor, torch.Tensor]], aff_true: torch.Tensor, pos_true: torch.Tensor,
               scale_m: float = 0.1, mean_scale: torch.Tensor | None = None) -> torch.Tensor:
    """Sequence-level affect term (an addition of this implementation): squared difference of
    :func:`window_statistics` of each predicted window (aff (N, L, 18), pos (N, L, J, 3)) from those of the
    ground-truth window (``aff_true``, ``pos_true``), averaged over statistics and windows.

    Every corpus walk keeps one style throughout, so a window predicted past the end of the ground truth (the
    free-running continuation of :func:`generation.gait.train.rollout`) must keep the statistics of the true
    window: this penalises the drift towards an average, smaller gait that the per-step losses leave free.
    """
    target = window_statistics(aff_true, pos_true, scale_m, mean_scale)
    terms = [((window_statistics(a, p, scale_m, mean_scale) - target) ** 2).mean() for a, p in pred_windows]
    return torch.stack(terms).mean()


def root_bounce(pos: torch.Tensor, scale_m: float = 0.1) -> torch.Tensor:
    """(N,) standard deviation over time of the root height in a window of positions (N, L, J, 3; root = joint 0,
    y up), in units of ``scale_m``: the pelvis bounce that root-relative statistics cannot see."""
    return ((pos[..., 0, 1] / scale_m).var(dim=1, unbiased=False) + STD_EPS).sqrt()


def bounce_loss(pred_pos: list[torch.Tensor], pos_true: torch.Tensor, scale_m: float = 0.1) -> torch.Tensor:
    """Phase-free pelvis-bounce term (an addition of this implementation): squared difference of
    :func:`root_bounce` of each predicted window (N, L, J, 3) from the ground-truth window's, averaged over windows.

    A per-step height loss is minimised by a damped bounce when the step phase is uncertain (free-running
    prediction); the amplitude, compared over the window, is not.
    """
    target = root_bounce(pos_true, scale_m)
    return torch.stack([((root_bounce(p, scale_m) - target) ** 2).mean() for p in pred_pos]).mean()


def class_style_loss(pred_aff: list[torch.Tensor], aff_true: torch.Tensor, emotion: torch.Tensor,
                     mean_scale: torch.Tensor | None = None) -> torch.Tensor:
    """Per-emotion offset of the time-mean affective features (an addition of this implementation).

    ``pred_aff``: predicted windows (N, L, 18) of standardised features; ``aff_true`` (N, L, 18) the ground
    truth's; ``emotion`` (N, C) each walk's label vector, used as soft class membership; ``mean_scale`` (18,)
    puts the means in walk-to-walk units. For each class c the membership-weighted mean over walks of
    (predicted - true time mean) is a shared offset (C, 18); the loss is its mean square, averaged over windows.
    Classes absent from the batch contribute 0.
    """
    target = aff_true.mean(1) if mean_scale is None else aff_true.mean(1) * mean_scale
    share = emotion / emotion.sum(0, keepdim=True).clamp_min(1e-6)   # (N, C): each column sums to 1 (or 0)
    terms = []
    for a in pred_aff:
        mean = a.mean(1) if mean_scale is None else a.mean(1) * mean_scale
        terms.append(((share.T @ (mean - target)) ** 2).mean())
    return torch.stack(terms).mean()


def total_loss(pred: dict, true: dict, weights: GaitLossWeights, use_affective: bool = True, style_from: int = 0
               ) -> tuple[torch.Tensor, dict]:
    """Eq. 13 plus the phase term and the optional style term.

    ``pred`` and ``true`` hold ``q`` ((N, L, J, 4); ``pred["q_raw"]`` unnormalised), ``pos`` (N, L, J, 3) with
    root height, ``aff`` (N, L, 18), ``root`` (N, L, 3) and ``omega`` (N, L), all for the same target steps.
    ``use_affective`` (``GaitModelConfig.use_affective``) adds L_aff. With ``weights.style`` > 0, L_style
    (:func:`style_loss`) compares the windows ``[style_from:]`` of ``pred`` and ``true`` and, when ``pred`` has
    ``ext_aff`` / ``ext_pos`` (steps predicted past the ground truth), that continuation too (and so does
    :func:`bounce_loss` with ``weights.bounce`` > 0); ``true`` may carry
    ``aff_style_scale`` (18,) for the feature means (:meth:`generation.gait.data.Normalizer.style_scale`).
    With ``weights.class_style`` > 0, ``true["emotion"]`` (N, C) gives the classes of :func:`class_style_loss`
    over the same windows. Terms with weight 0 are left out of the total. Returns the weighted total and a dict
    of floats per term.
    """
    w = weights
    terms = {
        "motion": motion_loss(pred["q_raw"], true["q"], w.euler_order, w.versor),
        "pose": pose_loss(pred["pos"], true["pos"], w.pos_scale_m),
        "root": root_loss(pred["root"], true["root"]),
        "fctc": foot_contact_loss(pred["pos"], true["pos"], w.pos_scale_m),
        "phase": phase_loss(pred["omega"], true["omega"]),
    }
    if use_affective:
        terms["aff"] = affective_loss(pred["aff"], true["aff"])
    windows = [(pred["aff"][:, style_from:], pred["pos"][:, style_from:])]
    if pred.get("ext_aff") is not None:
        windows.append((pred["ext_aff"], pred["ext_pos"]))
    if w.style != 0.0:
        terms["style"] = style_loss(windows, true["aff"][:, style_from:], true["pos"][:, style_from:],
                                    w.pos_scale_m, true.get("aff_style_scale"))
    if w.bounce != 0.0:
        terms["bounce"] = bounce_loss([pos for _, pos in windows], true["pos"][:, style_from:], w.pos_scale_m)
    if w.class_style != 0.0:
        terms["class_style"] = class_style_loss([aff for aff, _ in windows], true["aff"][:, style_from:],
                                                true["emotion"], true.get("aff_style_scale"))
    total = sum(getattr(w, k) * v for k, v in terms.items() if getattr(w, k) != 0.0)
    return total, {k: float(v.detach()) for k, v in terms.items()}
