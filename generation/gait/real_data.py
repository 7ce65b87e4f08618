"""Gait network sequences from the real-capture corpus: windows of captured walks with labels and augmentation.

The corpus is :mod:`generation.mocap.real_corpus` (Bandai Namco Research Motion Dataset, Kobayashi et al. 2023,
arXiv:2306.08861, licence CC BY-NC 4.0), already on our 21-joint gait skeleton at 30 fps. Two stages use it:

- ``pretrain``: the forward locomotion of both datasets (dataset 1 ``walk`` in its 15 styles, dataset 2 ``walk``,
  ``walk-turn-left``, ``walk-turn-right`` in its 7 styles). Styles that map to a gait emotion
  (``protocol.vocabulary.CAPTURE_GAIT_EMOTIONS``: happy, sad, angry, normal = neutral, in either dataset) carry that
  label; every other style (proud, tired, active, feminine, elderly, ...) enters unlabelled, with the uniform
  emotion vector, which is also what emotion guidance uses as "no emotion asked".
- ``finetune``: dataset 1's happy, sad, angry and normal ``walk`` takes with their labels.

Dataset 1's sideways and backward walks (walk-left, walk-right, walk-back) are left out: generation walks forward
along a path and the network has no input saying "walk sideways".

Only takes of the requested split enter (``train`` for training, ``val`` for validation; the corpus holds
takes out by take, :data:`generation.mocap.bandai_namco.SPLIT_RULE`), so held-out takes never reach training.
Augmentation, as in the motion-synthesis literature: left-right mirroring (label kept), time warps of the
capture (speed factors; step length kept, cadence and speed scaled), windows starting every ``stride_frames``
frames and the four subsampling offsets of the 30 fps capture (stepping-phase variation).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from generation.core.digest import file_sha256
from generation.core.motion import Motion
from generation.core.windows import windows
from generation.mocap.real_corpus import DEFAULT_PATH, load_real_corpus
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS

from .config import GaitDataConfig
from .data import GaitSequences, prepare_sequences
from .weights import TrainingData

STAGES = ("pretrain", "finetune")
LOCOMOTION = {"bandai-namco-1": ("walk",), "bandai-namco-2": ("walk", "walk-turn-left", "walk-turn-right")}
"""Corpus contents (per dataset) of forward locomotion used for the gait network."""
FINETUNE_STYLES = tuple(CAPTURE_GAIT_EMOTIONS)   # dataset 1's happy, sad, angry, normal


@dataclass(frozen=True)
class RealAugment:
    """Augmentation of training takes (validation and test takes are used as captured).

    mirror: add the left-right mirrored take (label kept).
    speed_factors: time-warp factors of the capture (1.1 plays the take 10 % faster).
    stride_frames: a window starts every this many frames (and one ends at the take's last frame).
    offsets: first frames of the every-``frame_step``-th-frame subsampling.
    windows_per_clip: when set, each take gives about this many windows (its own stride, at least one frame),
        so that a short take counts as much as a long one (class balance of the four single fine-tuning takes).
    """

    mirror: bool = True
    speed_factors: tuple[float, ...] = (0.9, 1.0, 1.1)
    stride_frames: int = 24
    offsets: tuple[int, ...] = (0, 1, 2, 3)
    windows_per_clip: int | None = None

    def stride_for(self, num_frames: int, need: int) -> int:
        """Window stride of a take of ``num_frames`` frames (windows of ``need`` frames)."""
        if self.windows_per_clip is None:
            return self.stride_frames
        return max(1, -(-(num_frames - need) // max(1, self.windows_per_clip - 1)))   # ceiling division

    @classmethod
    def none(cls) -> RealAugment:
        """Takes as captured: no mirror, no time warp, subsampling from frame 0."""
        return cls(mirror=False, speed_factors=(1.0,), offsets=(0,))


STAGE_AUGMENT = {"pretrain": RealAugment(), "finetune": RealAugment(windows_per_clip=12)}
"""Default augmentation per stage; the four fine-tuning takes get equal weight."""


def emotion_vector(label: str, labelled: bool = True) -> np.ndarray:
    """(4,) one-hot over ``GAIT_EMOTIONS`` for a gait-emotion label, else (or unlabelled) the uniform vector."""
    if labelled and label in GAIT_EMOTIONS:
        return np.eye(len(GAIT_EMOTIONS))[GAIT_EMOTIONS.index(label)]
    return np.full(len(GAIT_EMOTIONS), 1.0 / len(GAIT_EMOTIONS))


def mirror_motion(motion: Motion) -> Motion:
    """The motion mirrored left-right (about the body's x = 0 plane): left and right joints swap, each local
    rotation (w, x, y, z) becomes (w, x, -y, -z) and the root's x is negated. Exact for skeletons whose left and
    right offsets mirror each other (ours), which :func:`check_mirror_symmetric` verifies."""
    check_mirror_symmetric(motion.skeleton)
    swap = motion.skeleton.mirror_map()
    rot = motion.rotations[:, swap] * np.array([1.0, 1.0, -1.0, -1.0])
    root = motion.root_positions * np.array([-1.0, 1.0, 1.0])
    return Motion(motion.skeleton, rot, root, motion.fps, {**motion.metadata, "mirrored": True})


def check_mirror_symmetric(skeleton, tol: float = 1e-6) -> None:
    """ValueError unless each joint's offset is its counterpart's with x negated."""
    swap = skeleton.mirror_map()
    mirrored = skeleton.offsets[swap] * np.array([-1.0, 1.0, 1.0])
    err = float(np.abs(mirrored - skeleton.offsets).max())
    if err > tol:
        raise ValueError(f"skeleton {skeleton.name!r} is not left-right symmetric (offset mismatch {err:.2g} m)")


def time_warp(motion: Motion, factor: float) -> Motion:
    """The motion played ``factor`` times faster, resampled to its own frame rate."""
    if factor <= 0:
        raise ValueError(f"speed factor must be positive, got {factor}")
    if factor == 1.0:
        return motion
    fast = Motion(motion.skeleton, motion.rotations, motion.root_positions, motion.fps * factor, motion.metadata)
    return fast.resample(motion.fps)


def stage_clips(stage: str, split: str, path: str | Path | None = None) -> list:
    """Corpus clips (``CorpusClip``) of a training stage and split (see the module docstring)."""
    if stage not in STAGES:
        raise ValueError(f"unknown stage {stage!r}: use one of {', '.join(STAGES)}")
    contents = sorted({c for cs in LOCOMOTION.values() for c in cs})
    clips = load_real_corpus(path, skeleton="gait", split=split, contents=contents)
    clips = [c for c in clips if c.content in LOCOMOTION.get(c.dataset, ())]
    if stage == "finetune":
        clips = [c for c in clips if c.dataset == "bandai-namco-1" and c.style in FINETUNE_STYLES]
    return clips


def clip_sequences(clips: list, data: GaitDataConfig, augment: RealAugment, labelled: bool = True,
                   emotion_of=None) -> GaitSequences:
    """Network sequences of windows of ``clips`` (each clip's split kept per row). Rows of one window (its mirror,
    time warps and subsampling offsets) share a ``base_index``, so a training epoch visits each window once in
    one random variant. Clips shorter than a window are skipped. ``clip_names`` lists the clip of each base;
    ``training_data`` is None until :func:`load_real_sequences` says which stage and corpus they are.
    ``emotion_of(clip)``: the (4,) emotion input of a clip instead of its label's (soft labels,
    :mod:`generation.gait.soft_labels`)."""
    need = data.frame_step * (data.seq_len - 1) + 1 + max(augment.offsets)
    rot, root, emo, split, skels, base = [], [], [], [], [], []
    names: dict[tuple[str, int], int] = {}   # (clip, window of the captured time line) -> base index
    for clip in clips:
        em = emotion_of(clip) if emotion_of is not None else emotion_vector(clip.label, labelled)
        variants = [clip.motion] + ([mirror_motion(clip.motion)] if augment.mirror else [])
        for v in variants:
            for f in augment.speed_factors:
                m = time_warp(v, f)
                stride = augment.stride_for(m.num_frames, need)
                for s0 in (w.start for w in windows(m.num_frames, need, stride)):
                    key = (clip.name, int(round(s0 * f / stride)))
                    base.append(names.setdefault(key, len(names)))
                    rot.append(m.rotations[s0:s0 + need])
                    root.append(m.root_positions[s0:s0 + need])
                    emo.append(em)
                    split.append(clip.split)
                    skels.append(m.skeleton)
    if not rot:
        raise ValueError(f"no clip has the {need} frames a window of {data.seq_len} steps needs")
    seqs = prepare_sequences(np.stack(rot), np.stack(root), np.stack(emo), np.array(split),
                             np.array([s.height for s in skels]), np.array([s.build for s in skels]),
                             frame_step=data.frame_step, seq_len=data.seq_len, skeletons=skels,
                             offsets=augment.offsets)
    return replace(seqs, base_index=np.tile(np.asarray(base), len(augment.offsets)),
                               clip_names=tuple(name for name, _ in sorted(names, key=names.get)))


def load_real_sequences(stage: str, data: GaitDataConfig, augment: RealAugment | None = None,
                        path: str | Path | None = None) -> GaitSequences:
    """Training ("train" takes, augmented) and validation ("val" takes, as captured) sequences of a stage, with
    their ``training_data`` (real capture of the stage; the corpus path, SHA-256 and augmentation) for the weights
    file's record."""
    augment = augment or STAGE_AUGMENT[stage]
    train = clip_sequences(stage_clips(stage, "train", path), data, augment)
    parts = [train]
    val_clips = stage_clips(stage, "val", path)
    if val_clips:
        val = clip_sequences(val_clips, data, RealAugment.none())
        parts.append(replace(val, base_index=val.base_index + int(train.base_index.max()) + 1))
    corpus = Path(path) if path is not None else DEFAULT_PATH
    training = TrainingData.real(stage, {
        "path": str(corpus), "sha256": file_sha256(corpus), "stage": stage,
        "augment": {"mirror": augment.mirror, "speed_factors": list(augment.speed_factors),
                    "stride_frames": augment.stride_frames, "offsets": list(augment.offsets)}})
    return replace(concat_sequences(parts), training_data=training,
                               clip_names=tuple(name for p in parts for name in p.clip_names))


def concat_sequences(parts: list[GaitSequences]) -> GaitSequences:
    """One GaitSequences of several (same rate and length), rows in order."""
    import torch
    if len(parts) == 1:
        return parts[0]
    kw = {}
    for k in GaitSequences.__dataclass_fields__:
        vals = [getattr(p, k) for p in parts]
        if isinstance(vals[0], torch.Tensor):
            kw[k] = torch.cat(vals)
        elif isinstance(vals[0], np.ndarray):
            kw[k] = np.concatenate(vals)
        else:
            kw[k] = vals[0]
    return GaitSequences(**kw)
