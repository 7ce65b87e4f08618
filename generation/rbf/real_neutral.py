"""The paper's averaged neutral walk from real capture: steady normal-walk cycles, DTW-aligned, averaged, looped.

Etemad & Arya (section III-C) cut 16 two-step neutral walks from captured data, aligned them with correlation
optimised time warping and averaged them "to eliminate the personal walking styles of the actors". We do the
same with the real normal walks of the Bandai Namco corpus (Kobayashi et al. 2023, arXiv:2306.08861,
CC BY-NC 4.0), train split only:

1. Cycles: left heel strike to the next, one right strike between (:func:`generation.rbf.neutral_base.motion_cycles`);
   only steady ones (duration and stride within 10 % of the take's medians: start and stop cycles fall out), at
   most ``per_take`` per take. Each is contact-warped to m + 1 samples, expressed in the walker's frame
   and divided by the walker's height (:class:`generation.rbf.neutral_base.NormalisedCycle`).
2. Alignment: multidimensional dynamic time warping (Sakoe & Chiba 1978) of each cycle's joint trajectories
   onto a reference, with the C implementation of ``dtaidistance`` (Meert et al., DTAIDistance,
   doi:10.5281/zenodo.1202378) in a Sakoe-Chiba band, iterated as DTW barycenter averaging (Petitjean et al.
   2011): the reference starts as the contact-warped mean and becomes the mean of the warped cycles. The path
   is pinned at both ends (the strikes), so the loop point stays a left heel strike.
3. Averaging joint positions (heights) frame by frame, closing the loop, scaling to the target skeleton and
   re-fitting the skeleton by inverse kinematics (:func:`generation.rbf.neutral_base.cycle_motion`), the
   "positions with an IK re-fit" route: bone lengths exact, rotations valid by construction.

The result ships as a small ``.npz`` (:data:`SHIPPED_PATH`, with the dataset's licence and citation in its
metadata) so a fresh clone renders seed 004 without the corpus; :func:`build_real_neutral` rebuilds it.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from generation.core.skeleton import Skeleton, gait_skeleton
from generation.mocap.real_corpus import DEFAULT_PATH, load_real_corpus

from .neutral_base import NormalisedCycle, average_cycles, cycle_motion, motion_cycles

SHIPPED_PATH = Path(__file__).resolve().parents[1] / "data" / "rbf" / "neutral_real.npz"
TIME_WARPING = ("multidimensional DTW (Sakoe & Chiba 1978; dtaidistance, Meert et al.) in a Sakoe-Chiba band, "
                "iterated as DTW barycenter averaging (Petitjean et al. 2011), after contact-based "
                "piecewise-linear warping (left strike -> 0, right -> m/2, next left -> m)")
DTW_WINDOW = 0.10  # Sakoe-Chiba band, share of the cycle
DBA_ITERATIONS = 3
STEADY_TOLERANCE = 0.10  # a steady cycle's duration and stride lie within 10 % of the take's medians
TIME_MAP_SMOOTHING = 5  # frames, moving average of the DTW time map (removes the path's stair steps)


def steady_cycles(motion: Motion, m: int = 100, name: str = "", per_take: int | None = None) -> list[NormalisedCycle]:
    """A take's steady cycles, normalised: duration and stride within :data:`STEADY_TOLERANCE` of the take's medians.

    Start and stop cycles (slower, shorter) fall out; at most ``per_take`` cycles are kept, from the start.
    """
    cycles, _ = motion_cycles(motion, m, name)
    if not cycles:
        return []
    duration = np.median([c.duration_s for c in cycles])
    stride = np.median([c.stride for c in cycles])
    steady = [c for c in cycles if abs(c.duration_s / duration - 1) <= STEADY_TOLERANCE
              and abs(c.stride / stride - 1) <= STEADY_TOLERANCE]
    return steady[:per_take] if per_take is not None else steady


def _dtw_time_map(series: np.ndarray, reference: np.ndarray, window: int) -> np.ndarray:
    """(n,) fractional frame of ``series`` matched to each reference frame: DTW path, averaged, smoothed, monotone."""
    from dtaidistance import dtw_ndim

    path = dtw_ndim.warping_path(np.ascontiguousarray(series, dtype=np.float64),
                                 np.ascontiguousarray(reference, dtype=np.float64), window=window, use_c=True)
    n = len(reference)
    sums, counts = np.zeros(n), np.zeros(n)
    for i, j in path:
        sums[j] += i
        counts[j] += 1
    t = sums / np.maximum(counts, 1)
    k = TIME_MAP_SMOOTHING
    if k > 1:
        padded = np.concatenate([np.full(k, t[0]), t, np.full(k, t[-1])])
        t = np.convolve(padded, np.ones(k) / k, mode="same")[k:-k]
    t[0], t[-1] = 0.0, len(series) - 1.0
    return np.maximum.accumulate(np.clip(t, 0.0, len(series) - 1.0))


def _resample(positions: np.ndarray, t: np.ndarray) -> np.ndarray:
    """positions (n, J, 3) linearly interpolated at fractional frames t (n,)."""
    i0 = np.clip(np.floor(t).astype(np.int64), 0, len(positions) - 1)
    i1 = np.minimum(i0 + 1, len(positions) - 1)
    f = (t - i0)[:, None, None]
    return (1 - f) * positions[i0] + f * positions[i1]


def dtw_align(cycles: list[NormalisedCycle], iterations: int = DBA_ITERATIONS,
              window: float = DTW_WINDOW) -> tuple[list[NormalisedCycle], dict]:
    """Align cycles to their DTW barycenter; returns the warped cycles and the spread before and after.

    Spread: the mean over frames and joints of the per-frame standard deviation across cycles (heights), a
    measure of how well the cycles line up (lower is better).
    """
    if len(cycles) < 2:
        raise ValueError(f"DTW alignment needs at least two cycles, got {len(cycles)}")
    originals = [c.positions for c in cycles]
    n = originals[0].shape[0]
    band = max(2, int(round(window * n)))
    reference = np.mean(originals, axis=0)
    warped = originals
    for _ in range(iterations):
        flat_ref = reference.reshape(n, -1)
        warped = [_resample(p, _dtw_time_map(p.reshape(n, -1), flat_ref, band)) for p in originals]
        reference = np.mean(warped, axis=0)
    spread = {"before": float(np.std(originals, axis=0).mean()), "after": float(np.std(warped, axis=0).mean())}
    out = [NormalisedCycle(w, c.stride, c.duration_s, c.source) for w, c in zip(warped, cycles)]
    return out, spread


def real_neutral_from_clips(clips: list, skeleton: Skeleton | None = None, m: int = 100, per_take: int | None = 4,
                            align: bool = True) -> Motion:
    """Average the steady cycles of real normal walks (``CorpusClip``s) into one looping neutral cycle.

    Args:
        clips: :class:`generation.mocap.real_corpus.CorpusClip` of normal walks on the gait skeleton.
        skeleton: target skeleton (default 1.75 m male gait skeleton).
        m: frames per cycle (the paper: 100).
        per_take: at most this many steady cycles per take (balances takes); None keeps all.
        align: DTW-align the cycles (else contact-based warping only, for comparison).

    Returns:
        Motion of m frames (see :func:`generation.rbf.neutral_base.cycle_motion`) whose metadata also holds
        ``captured_sources`` (name, dataset, take, cycles per take), ``n_cycles``, ``time_warping``,
        ``dtw_spread`` (before/after), ``licence`` and ``citation``; ``synthetic`` False.
    """
    cycles, used = [], []
    for clip in clips:
        found = steady_cycles(clip.motion, m, clip.name, per_take)
        cycles += found
        used.append({"name": clip.name, "dataset": clip.dataset, "take": clip.take, "split": clip.split,
                     "cycles": len(found)})
    if len(cycles) < 2:
        raise ValueError(f"need at least two steady cycles from the normal walks, found {len(cycles)} "
                         f"in {len(clips)} takes")
    spread = None
    if align:
        cycles, spread = dtw_align(cycles)
    mean, stride, duration = average_cycles(cycles)
    first = clips[0].motion.metadata
    metadata = {
        "origin": "generated", "generator": "neutral_base", "synthetic": False, "captured_base": True,
        "captured_sources": used, "n_cycles": len(cycles), "n_takes": sum(1 for u in used if u["cycles"]),
        "time_warping": TIME_WARPING if align else "contact-based piecewise-linear", "dtw_spread": spread,
        "licence": first.get("licence", "CC BY-NC 4.0"), "citation": first.get("citation", ""),
        "dataset_url": first.get("source_url", ""),
    }
    return cycle_motion(mean, stride, duration, skeleton or gait_skeleton(), metadata)


def corpus_normal_walks(corpus_path: str | Path | None = None, split: str = "train") -> list:
    """Straight normal walks (content ``walk``, style ``normal``) of the real corpus, both datasets."""

    return load_real_corpus(corpus_path or DEFAULT_PATH, skeleton="gait", split=split, contents=["walk"],
                            styles=["normal"])


def build_real_neutral(corpus_path: str | Path | None = None, out: str | Path = SHIPPED_PATH) -> Motion:
    """Build the averaged neutral cycle from the corpus's train-split normal walks and save it to ``out``."""
    cycle = real_neutral_from_clips(corpus_normal_walks(corpus_path))
    save_cycle(cycle, out)
    return cycle


def save_cycle(cycle: Motion, path: str | Path) -> None:
    """Write a neutral cycle (rotations, root, fps, skeleton height/build, metadata JSON) to a ``.npz``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, rotations=cycle.rotations.astype(np.float64),
                        root_positions=cycle.root_positions.astype(np.float64), fps=np.float64(cycle.fps),
                        height=np.float64(cycle.skeleton.height), build=np.str_(cycle.skeleton.build),
                        metadata_json=np.str_(json.dumps(cycle.metadata)))


def load_cycle(path: str | Path = SHIPPED_PATH) -> Motion:
    """Read a neutral cycle written by :func:`save_cycle` (default: the shipped real-capture cycle)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"neutral cycle file {path} not found; build it with "
                                "`python -m generation.rbf neutral --corpus CORPUS --out PATH`")
    with np.load(path) as z:
        missing = {"rotations", "root_positions", "fps", "height", "build", "metadata_json"} - set(z.files)
        if missing:
            raise ValueError(f"{path}: not a neutral cycle file (missing {sorted(missing)})")
        skeleton = gait_skeleton(float(z["height"]), str(z["build"]))
        rotations, root = z["rotations"], z["root_positions"]
        if rotations.shape != (len(root), skeleton.num_joints, 4):
            raise ValueError(f"{path}: rotations {rotations.shape} do not fit root {root.shape} on the gait skeleton")
        return Motion(skeleton, rotations, root, float(z["fps"]), json.loads(str(z["metadata_json"])))
