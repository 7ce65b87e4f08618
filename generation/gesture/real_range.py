"""A training loss that keeps generated gestures within the real captured range of their emotion.

The range of each statistic per gesture emotion (min and max over the real takes of that emotion, seated; see
:mod:`generation.gesture.real_stats`) is shipped in ``generation/data/gesture_real_ranges.json`` (written by
``python -m generation.quality.real_gestures --write-ranges``), so training needs no real corpus. Emotions the capture
does not have (afraid, amused, ...) get the range over all real takes ("all").

:func:`sequence_stats` computes, differentiably, per sequence: the faster wrist's mean and 90th-percentile speed,
the faster elbow's mean speed, the 90th percentile of the farther wrist's distance from the trunk axis, the share of
held frames (both wrists slower than 0.1 m/s; a sigmoid of width 0.02 m/s so it has a gradient) and the head's mean
angular speed. :func:`real_range_loss` is the mean over sequences and statistics of the squared log excess of each
statistic outside its [min, max] (0 inside the range), with a floor added to both sides of each ratio.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch

from generation.core.digest import file_sha256

from .real_stats import ELBOWS, HEAD, HOLD_SPEED, NECK, RANGES_FILE, ROOT, WRISTS

#: The statistics the loss keeps in range, in the order of :func:`sequence_stats`'s columns.
LOSS_STATS = ("wrist_mean", "wrist_p90", "elbow_mean", "reach_p90", "hold_share", "head_speed")
#: Added to both sides of each log ratio (m/s, m/s, m/s, m, share, deg/s), so near-zero values do not dominate.
FLOORS = (0.05, 0.05, 0.05, 0.05, 0.05, 2.0)
HOLD_WIDTH = 0.02  # m/s, width of the soft hold threshold


def load_ranges(path: str | Path = RANGES_FILE) -> dict:
    """The shipped ranges: {"ranges": {emotion or "all": {stat: [min, max]}}, "source": ..., ...}."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no real gesture ranges (write them with `python -m "
                                "generation.quality.real_gestures --write-ranges`, which needs the real corpus)")
    data = json.loads(path.read_text(encoding="utf-8"))
    if "ranges" not in data or "all" not in data["ranges"]:
        raise ValueError(f"{path}: expected an object with 'ranges' holding at least 'all'")
    return data


def provenance(path: str | Path = RANGES_FILE) -> dict:
    """What a weights file trained or selected with the real ranges records about them: {"file", "sha256", "source",
    "licence", "citation"} (the ranges are statistics of real capture and keep its licence)."""
    path = Path(path)
    data = load_ranges(path)
    return {"file": path.name, "sha256": file_sha256(path),
            **{k: data.get(k) for k in ("source", "licence", "citation")}}


def range_arrays(emotions, ranges: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(N, len(LOSS_STATS)) lower and upper bounds for examples of ``emotions`` (N,) (their emotion's real range,
    else "all")."""
    ranges = (ranges or load_ranges())["ranges"]
    lo = np.array([[ranges.get(str(e), ranges["all"])[k][0] for k in LOSS_STATS] for e in emotions], np.float32)
    hi = np.array([[ranges.get(str(e), ranges["all"])[k][1] for k in LOSS_STATS] for e in emotions], np.float32)
    return lo, hi


def _masked_quantile(values: torch.Tensor, valid: torch.Tensor, q: float) -> torch.Tensor:
    """(B,) ``q`` quantile over the valid entries of values (B, N) (linear interpolation, as np.percentile)."""
    n = valid.sum(1)
    ordered = torch.where(valid, values, values.new_full((), -1e9)).sort(dim=1, descending=True).values
    k = (1.0 - q) * (n - 1).clamp_min(0).to(values.dtype)
    lo = k.floor().long()
    hi = (lo + 1).clamp_max((n - 1).clamp_min(0))
    frac = k - lo.to(values.dtype)
    return ordered.gather(1, lo[:, None])[:, 0] * (1 - frac) + ordered.gather(1, hi[:, None])[:, 0] * frac


def _trunk_distance(P: torch.Tensor, joint: int) -> torch.Tensor:
    a, b, p = P[:, :, ROOT], P[:, :, NECK], P[:, :, joint]
    ab = b - a
    t = (((p - a) * ab).sum(-1) / (ab * ab).sum(-1).clamp_min(1e-12)).clamp(0.0, 1.0)
    return ((p - (a + t[..., None] * ab)) ** 2).sum(-1).add(1e-10).sqrt()


def sequence_stats(P: torch.Tensor, mask: torch.Tensor, fps: float) -> torch.Tensor:
    """Per sequence, the LOSS_STATS: P (B, T, 23, 3) metres, mask (B, T) bool -> (B, 6)."""
    pair = mask[:, 1:] & mask[:, :-1]
    n = pair.sum(1).clamp_min(1).to(P.dtype)

    def speeds(joints):
        d = P[:, 1:, list(joints)] - P[:, :-1, list(joints)]
        return ((d ** 2).sum(-1) + 1e-10).sqrt().amax(-1) * fps  # (B, T-1), the faster joint

    wrist, elbow = speeds(WRISTS), speeds(ELBOWS)
    reach = torch.maximum(_trunk_distance(P, WRISTS[0]), _trunk_distance(P, WRISTS[1]))
    head = P[:, :, HEAD] - P[:, :, NECK]
    head = head / head.norm(dim=-1, keepdim=True).clamp_min(1e-8)
    chord = ((head[:, 1:] - head[:, :-1]) ** 2).sum(-1).add(1e-10).sqrt()  # angle = 2 asin(chord / 2)
    head_speed = 2.0 * torch.asin((chord / 2).clamp(max=1.0 - 1e-6)) * fps * (180.0 / np.pi)
    held = torch.sigmoid((HOLD_SPEED - wrist) / HOLD_WIDTH)
    return torch.stack(((wrist * pair).sum(1) / n, _masked_quantile(wrist, pair, 0.9), (elbow * pair).sum(1) / n,
                        _masked_quantile(reach, mask, 0.9), (held * pair).sum(1) / n,
                        (head_speed * pair).sum(1) / n), dim=-1)


def real_range_loss(P: torch.Tensor, mask: torch.Tensor, fps: float, lo: torch.Tensor,
                    hi: torch.Tensor) -> torch.Tensor:
    """Mean squared log excess of :func:`sequence_stats` outside [lo, hi] (each (B, 6)); 0 when all are inside."""
    x = sequence_stats(P, mask, fps)
    f = x.new_tensor(FLOORS)
    below = torch.relu(torch.log((lo + f) / (x + f)))
    above = torch.relu(torch.log((x + f) / (hi + f)))
    return ((below + above) ** 2).mean()
