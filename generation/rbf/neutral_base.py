"""The neutral base walk of seed 004: several neutral cycles, time-aligned and averaged into one cycle.

Etemad & Arya cut 16 two-step neutral walks from HDM05, aligned them with correlation-optimised time
warping into 100 frames and averaged them, so that no single actor's style survives (section III-C); the
result was perceived as neutral by 75 % of viewers (Table I). We do the same with what we have:

1. Sources: procedural neutral walks (:func:`generation.procedural.walk.walk`, marked synthetic) of
   several body sizes and builds, plus the real captured walks of :func:`generation.mocap.captured.captured_walks`
   when that module is available and they use the gait skeleton.
2. Cutting: a cycle runs from a left heel strike to the next one, with one right heel strike between
   (strikes are the onsets of :func:`generation.core.features.detect_foot_contacts`). Cycles in which a joint
   jumps faster than 10 m/s (a capture or rig glitch) are left out and counted in the metadata.
3. Time normalisation: *contact-based piecewise-linear warping* (not CoTW or DTW): left strike -> frame 0,
   right strike -> frame m/2, next left strike -> frame m, linear in between; positions are interpolated
   linearly at the warped times.
4. Space normalisation: each cycle is expressed in the walker's frame (its stride turned to +z, the mean
   forward progression removed, the lowest foot joint of the cycle on y = 0) and divided by the walker's
   height, so walkers of different sizes can be averaged (the paper normalises by height too, Fig. 5).
5. Averaging joint positions (T, J, 3) frame by frame, closing the loop (the end-to-start mismatch is
   removed linearly), scaling to the target skeleton's height and putting the positions back onto the
   skeleton with :func:`generation.core.ik.inverse_kinematics` (directions kept, bone lengths exact).

The result is one periodic cycle of ``m`` frames (default 100) walking along +z, whose metadata carries
``stride_m`` (the root advance per cycle) for :func:`generation.rbf.stylise.stylise`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generation.core.features import detect_foot_contacts, foot_joints
from generation.core.ik import inverse_kinematics
from generation.core.motion import Motion
from generation.core.skeleton import GAIT_JOINTS, Skeleton, gait_skeleton
from generation.mocap.captured import captured_walks, chain_clip_repeats
from generation.procedural.walk import WalkParams, walk

TIME_WARPING = "contact-based piecewise-linear (left heel strike -> 0, right -> m/2, next left -> m)"
DEFAULT_BODIES = ((1.58, "female"), (1.66, "female"), (1.74, "female"), (1.70, "male"), (1.78, "male"),
                  (1.86, "male"), (1.94, "male"), (1.62, "female"))
MIN_CYCLE_S, MAX_CYCLE_S = 0.6, 2.5
MAX_JOINT_SPEED_M_S = 10.0  # for a 1.75 m body; faster joints mean a glitch in the source


@dataclass
class NormalisedCycle:
    """One cycle in the walker's frame, divided by the walker's height.

    Attributes:
        positions: (m + 1, J, 3) phase 0..1 inclusive, heights (dimensionless).
        stride: stride length / height (dimensionless), along +z.
        duration_s: seconds from left strike to next left strike.
        source: name of the source motion.
    """

    positions: np.ndarray
    stride: float
    duration_s: float
    source: str


def heel_strikes(positions: np.ndarray, fps: float, skeleton: Skeleton) -> tuple[np.ndarray, np.ndarray]:
    """Frames of left and right heel strikes: onsets of foot contact. positions (T, J, 3) metres."""
    contacts = detect_foot_contacts(positions, fps, skeleton)
    onsets = [np.flatnonzero(contacts[1:, s] & ~contacts[:-1, s]) + 1 for s in range(2)]
    return onsets[0], onsets[1]


def cut_cycles(left: np.ndarray, right: np.ndarray, fps: float) -> list[tuple[int, int, int]]:
    """(left strike, right strike, next left strike) triples with exactly one right strike in between."""
    out = []
    for l0, l1 in zip(left[:-1], left[1:]):
        r = right[(right > l0) & (right < l1)]
        if len(r) == 1 and MIN_CYCLE_S <= (l1 - l0) / fps <= MAX_CYCLE_S:
            out.append((int(l0), int(r[0]), int(l1)))
    return out


def _interp_frames(positions: np.ndarray, frames: np.ndarray) -> np.ndarray:
    i0 = np.clip(np.floor(frames).astype(np.int64), 0, len(positions) - 1)
    i1 = np.minimum(i0 + 1, len(positions) - 1)
    f = (frames - i0)[:, None, None]
    return (1 - f) * positions[i0] + f * positions[i1]


def warp_times(l0: float, r: float, l1: float, m: int) -> np.ndarray:
    """(m + 1,) source frame times for phases k/m, k = 0..m: piecewise linear through the three strikes."""
    phase = np.arange(m + 1) / m
    return np.where(phase <= 0.5, l0 + (r - l0) * phase * 2.0, r + (l1 - r) * (phase - 0.5) * 2.0)


def normalise_cycle(positions: np.ndarray, skeleton: Skeleton, fps: float, strikes: tuple[int, int, int],
                    m: int = 100, source: str = "") -> NormalisedCycle:
    """Time-normalise one cycle to m + 1 samples and express it in the walker's frame in heights.

    Args:
        positions: (T, J, 3) global positions of the whole walk, metres.
        skeleton: its skeleton (height used for the normalisation, foot joints for the floor).
        fps: frame rate of ``positions``.
        strikes: (left, right, next left) strike frames.
        m: frames per normalised cycle.
    """
    l0, r, l1 = strikes
    P = _interp_frames(positions, warp_times(l0, r, l1, m))  # (m + 1, J, 3)
    start, end = P[0, 0].copy(), P[-1, 0].copy()
    stride_vec = end - start
    stride_vec[1] = 0.0
    yaw = np.arctan2(stride_vec[0], stride_vec[2])  # heading about +y; 0 = walking along +z
    c, s = np.cos(-yaw), np.sin(-yaw)
    rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])  # rotation about y by -yaw
    P = (P - np.array([start[0], 0.0, start[2]])) @ rot.T
    stride = float(np.hypot(stride_vec[0], stride_vec[2]))
    P[:, :, 2] -= (np.arange(m + 1) / m * stride)[:, None]
    left, right = foot_joints(skeleton)
    P[:, :, 1] -= P[:, left + right, 1].min()
    h = skeleton.height
    return NormalisedCycle(P / h, stride / h, (l1 - l0) / fps, source)


def motion_cycles(motion: Motion, m: int = 100, source: str = "") -> tuple[list[NormalisedCycle], int]:
    """All complete cycles of a walk, normalised, and how many were rejected as glitches.

    A cycle is rejected when a joint moves faster than :data:`MAX_JOINT_SPEED_M_S` between two frames (a
    capture or rig glitch; walking peaks at about 6 m/s at the feet).
    """
    if tuple(motion.skeleton.joints) != GAIT_JOINTS:
        raise ValueError(f"neutral base needs walks on the 21-joint gait skeleton; {source or 'a motion'} uses "
                         f"{motion.skeleton.name!r} with {motion.skeleton.num_joints} joints")
    positions = motion.positions()
    left, right = heel_strikes(positions, motion.fps, motion.skeleton)
    speed = np.linalg.norm(np.diff(positions, axis=0), axis=-1).max(axis=1) * motion.fps  # (T - 1,)
    out, rejected = [], 0
    for s in cut_cycles(left, right, motion.fps):
        if speed[s[0]:s[2]].max() > MAX_JOINT_SPEED_M_S * motion.skeleton.height / 1.75:
            rejected += 1
            continue
        out.append(normalise_cycle(positions, motion.skeleton, motion.fps, s, m, source))
    return out, rejected


def average_cycles(cycles: list[NormalisedCycle]) -> tuple[np.ndarray, float, float]:
    """Frame-by-frame mean of normalised cycles with the loop closed.

    Returns:
        positions (m, J, 3) in heights (phase k/m, k = 0..m-1, periodic), mean stride / height, mean duration (s).
    """
    if not cycles:
        raise ValueError("no walk cycles to average (need at least one left-right-left heel strike sequence)")
    shape = cycles[0].positions.shape
    for c in cycles:
        if c.positions.shape != shape:
            raise ValueError(f"cycle from {c.source!r} has shape {c.positions.shape}, expected {shape}")
    mean = np.mean([c.positions for c in cycles], axis=0)
    m = shape[0] - 1
    mismatch = mean[-1] - mean[0]
    mean = mean - (np.arange(m + 1) / m)[:, None, None] * mismatch[None]
    return mean[:-1], float(np.mean([c.stride for c in cycles])), float(np.mean([c.duration_s for c in cycles]))


def neutral_cycle_from_motions(motions: list[Motion], skeleton: Skeleton | None = None, m: int = 100,
                               names: list[str] | None = None) -> Motion:
    """Average the cycles of several neutral walks into one periodic cycle on ``skeleton``.

    Args:
        motions: neutral walks on the gait skeleton (any size; straight walks).
        skeleton: target skeleton (default: 1.75 m male gait skeleton).
        m: frames in the cycle (the paper: 100).
        names: a label per motion for the metadata (default: metadata "origin"/"source").

    Returns:
        Motion of m frames at fps = m / mean cycle duration; root advances ``metadata["stride_m"]`` per cycle
        along +z. metadata: origin "generated", generator "neutral_base", synthetic (True if any source is),
        sources, n_cycles, time_warping, ik_error_max_m.
    """
    if m < 20:
        raise ValueError(f"m must be at least 20 frames, got {m}")
    skeleton = skeleton or gait_skeleton()
    names = names or [str(mo.metadata.get("source", mo.metadata.get("origin", f"motion {i}")))
                      for i, mo in enumerate(motions)]
    cycles: list[NormalisedCycle] = []
    used: list[dict] = []
    for motion, name in zip(motions, names):
        found, rejected = motion_cycles(motion, m, name)
        limit = motion.metadata.get("max_cycles")
        found = found[: int(limit)] if limit is not None else found
        cycles += found
        used.append({"name": name, "cycles": len(found), "rejected_cycles": rejected, "height": motion.skeleton.height,
                     "build": motion.skeleton.build, "synthetic": bool(motion.metadata.get("synthetic", False))})
    if not cycles:
        rejected = {u["name"]: u["rejected_cycles"] for u in used if u["rejected_cycles"]}
        raise ValueError("no walk cycles to average: no left-right-left heel strike sequence was found"
                         + (f"; cycles rejected as glitches (a joint faster than {MAX_JOINT_SPEED_M_S} m/s): "
                            f"{rejected}" if rejected else ""))
    mean, stride, duration = average_cycles(cycles)
    metadata = {
        "origin": "generated",
        "generator": "neutral_base",
        "synthetic": any(u["synthetic"] for u in used if u["cycles"]),
        "sources": used,
        "n_cycles": len(cycles),
        "time_warping": TIME_WARPING,
    }
    return cycle_motion(mean, stride, duration, skeleton, metadata)


def cycle_motion(mean: np.ndarray, stride: float, duration: float, skeleton: Skeleton, metadata: dict) -> Motion:
    """Put an averaged cycle onto a skeleton: scale, add the progression, inverse kinematics, ground the feet.

    Args:
        mean: (m, J, 3) periodic positions in heights in the walker's frame (:func:`average_cycles`).
        stride: stride / height; duration: cycle seconds.
        skeleton: target skeleton; metadata: what to record (``cycle_frames``, ``stride_m``,
            ``cycle_duration_s`` and ``ik_error_max_m`` are added).

    Returns:
        Motion of m frames at fps = m / duration whose root advances ``metadata["stride_m"]`` per cycle along +z.
    """

    m = mean.shape[0]
    H = skeleton.height
    positions = mean * H
    stride_m = stride * H
    positions[:, :, 2] += (np.arange(m) / m * stride_m)[:, None]
    motion, report = inverse_kinematics(positions, skeleton, fps=m / duration)
    fitted = motion.positions()
    left, right = foot_joints(skeleton)
    floor = fitted[:, left + right, 1].min()
    root = motion.root_positions - np.array([0.0, floor, 0.0])
    metadata = {**metadata, "cycle_frames": m, "stride_m": [0.0, 0.0, stride_m], "cycle_duration_s": duration,
                "ik_error_max_m": report.max_error_m}
    return Motion(skeleton, motion.rotations, root, m / duration, metadata)


def default_sources(n_frames_s: float = 3.3, fps: float = 100.0, include_captured: bool = True) -> list[Motion]:
    """Neutral walks to average: procedural walks of :data:`DEFAULT_BODIES` and the captured walks if any.

    Each procedural walk is ``n_frames_s`` seconds long (about two full cycles at the neutral cadence) with
    a different footprint-jitter seed. Captured walks are included only when ``generation.mocap.captured`` exists and
    yields gait-skeleton motions.
    """

    sources = []
    for i, (height, build) in enumerate(DEFAULT_BODIES):
        mo = walk(WalkParams.neutral(), None, int(round(n_frames_s * fps)), fps, gait_skeleton(height, build),
                  seed=i)
        mo.metadata["source"] = f"procedural neutral walk {height:.2f} m {build} (synthetic)"
        sources.append(mo)
    if include_captured:
        sources += captured_sources()
    return sources


def _is_straight(motion: Motion, max_turn_deg: float = 20.0) -> bool:
    """True when the root's ground-plane heading changes by less than ``max_turn_deg`` over the clip."""
    root = motion.root_positions[:, [0, 2]]
    half = len(root) // 2
    a, b = root[half] - root[0], root[-1] - root[half]
    if min(np.linalg.norm(a), np.linalg.norm(b)) < 1e-6:
        return False
    cos = float(a @ b / (np.linalg.norm(a) * np.linalg.norm(b)))
    return cos >= np.cos(np.radians(max_turn_deg))


def captured_sources() -> list[Motion]:
    """Real captured straight walks on the gait skeleton from :mod:`generation.mocap.captured`.

    Turning clips (described as turning, or turning by more than 20 degrees) are left out: the paper averaged
    straight walks. A loopable clip (``loop == "wrap"``) is
    repeated three times so a full left-right-left cycle can be cut from it; ``max_cycles`` = 1 in the metadata
    tells :func:`neutral_cycle_from_motions` to keep only its first cycle, so the repeat does not count twice.
    """
    out = []
    for mo in captured_walks():
        turning = "turn" in str(mo.metadata.get("description", "")).lower()
        if tuple(mo.skeleton.joints) != GAIT_JOINTS or turning or not _is_straight(mo):
            continue
        name = str(mo.metadata.get("source", "captured walk"))
        if mo.metadata.get("loop") == "wrap":
            mo = chain_clip_repeats(mo, 3)
            mo.metadata["max_cycles"] = 1
        mo.metadata["source"] = name + " (captured)"
        out.append(mo)
    return out


def neutral_cycle(skeleton: Skeleton | None = None, m: int = 100, include_captured: bool = True) -> Motion:
    """The project's neutral base cycle: :func:`default_sources` averaged by :func:`neutral_cycle_from_motions`."""
    return neutral_cycle_from_motions(default_sources(include_captured=include_captured), skeleton, m)
