"""Keeping the epoch whose generated validation gestures stay closest to the real captured range.

The default rule of :mod:`generation.gesture.train` keeps the epoch with the lowest rollout pose error x liveliness
(:func:`generation.gesture.metrics.selection_score`). The real-range rule (``--select real-range``) also generates
every validation sentence with each emotion the real capture has (the emotions of the shipped ranges,
``generation/data/gesture_real_ranges.json``; Bandai Namco Research Motion Dataset, Kobayashi et al. 2023,
arXiv:2306.08861, CC BY-NC 4.0), measures the statistics of :mod:`generation.gesture.real_stats` on each gesture and
keeps, among the epochs whose rollout pose error is at most a bound (and, optionally, whose r(peak wrist speed,
arousal) on the validation gestures is at least a bound), the one with the largest share of (emotion, statistic,
gesture) cells inside the real range; when no epoch is within the bounds, the one with the lowest pose error.
"""
from __future__ import annotations

import numpy as np

from .data import GestureDataset, with_emotions
from .generate import decode_examples
from .metrics import positions
from .real_range import load_ranges
from .real_stats import gesture_stats, in_range_shares, mean_share


def captured_emotions(ranges: dict) -> tuple[str, ...]:
    """The emotions with a real range of their own (``ranges`` = {emotion or "all": {stat: [min, max]}})."""
    return tuple(sorted(k for k in ranges if k != "all"))


def real_range_rollout(net, data: GestureDataset, idx, ranges: dict | None = None) -> dict:
    """Generate each example of ``idx`` with each captured emotion and measure them against the real ranges.

    Returns {"share": share of all (emotion, statistic, gesture) cells inside the real range (the number
    ``bench_gesture_real.py`` reports on the test split), "per_emotion": {emotion: share over its statistics},
    "n": gestures generated}.
    """
    ranges = ranges if ranges is not None else load_ranges()["ranges"]
    fake = with_emotions(data, idx, captured_emotions(ranges))
    gen = decode_examples(net, fake, np.arange(len(fake)))
    rows = [{"emotion": str(fake.emotion[n]), **gesture_stats(positions(g, str(fake.gender[n]), fake.root[n]),
                                                              fake.fps)} for n, g in enumerate(gen)]
    shares = in_range_shares(rows, ranges)
    return {"share": mean_share(shares), "per_emotion": {e: float(np.mean(list(v.values())))
                                                         for e, v in shares.items()}, "n": len(rows)}


def real_range_score(pose_error: float, share: float, max_pose_error: float, r: float = float("nan"),
                     min_r: float | None = None) -> float:
    """The number the real-range rule minimises: -share when ``pose_error`` <= ``max_pose_error`` and (with
    ``min_r``) the arousal correlation ``r`` >= ``min_r`` (in [-1, 0]), else ``pose_error`` (> 0), so any epoch within
    the bounds beats every epoch outside them, the largest share wins within the bounds and the lowest pose error
    outside them."""
    if not np.isfinite(share):
        share = 0.0
    within = pose_error <= max_pose_error and (min_r is None or (np.isfinite(r) and r >= min_r))
    return -float(share) if within else float(pose_error)


def history_score(entry: dict, max_pose_error: float, min_r: float | None = None) -> float | None:
    """:func:`real_range_score` of one training-history entry (None when it has no real-range rollout)."""
    if "val_real_range" not in entry:
        return None
    roll = entry["val_rollout"]
    return real_range_score(roll["pose_error"], entry["val_real_range"]["share"], max_pose_error,
                            roll.get("r_peak_arousal", float("nan")), min_r)


def chosen_epoch(history: list[dict], max_pose_error: float, min_r: float | None = None) -> int:
    """The epoch the real-range rule keeps from a run's ``history`` (entries with "val_rollout" and
    "val_real_range"; the first of equal scores, as training keeps it), or -1 when none was measured."""
    best, best_epoch = float("inf"), -1
    for h in history:
        score = history_score(h, max_pose_error, min_r)
        if score is not None and score < best:
            best, best_epoch = score, h["epoch"]
    return best_epoch
