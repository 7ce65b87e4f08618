"""Fine-tuning sequences from both real corpora: Bandai dataset 1's four emotion walks plus the BML walks of thirty
actors, with acted or soft (acted + perceived) emotion vectors, split by performer.

- Bandai Namco Research Motion Dataset (Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0): dataset 1 ``walk``
  happy, sad, angry, normal of the training split (take 1), as the ``finetune`` stage of
  :mod:`generation.gait.real_data` uses them (12 windows per take).
- BML walks with Emotion-Gait labels (Ma, Paterson & Pollick 2006; STEP, Bhattacharya et al. AAAI 2020; research
  use with citation), imported by :mod:`generation.mocap.emotion_gait_bml` (root travel reconstructed from the
  stance foot). Training: the performers of the ``train`` split; validation (choosing the epoch): the ``val``
  performers; the ``test`` performers are never read here.

Every BML clip is one gait cycle repeated (``loop_period_frames`` in its metadata), 75 frames: shorter than a
30-step window (117 frames + the subsampling offsets). :func:`extend_loop` repeats the cycle (the data already
repeats it; the seam between cycles is the capture's own) with the root advancing one cycle's travel per cycle, so
a clip yields windows like the short Bandai takes (:data:`BML_AUGMENT`: a few windows per clip).

Emotion vectors (:func:`emotion_for`): ``acted`` one-hot of the acted label; ``soft``: 0.5 acted + 0.5 perceived
(one-hot when they agree). Bandai takes have no perceived label: acted in both.
"""
from __future__ import annotations

from dataclasses import astuple, replace
from pathlib import Path

import numpy as np

from generation.core.digest import file_sha256
from generation.core.motion import Motion
from generation.mocap.emotion_gait_bml import CITATION as BML_CITATION
from generation.mocap.emotion_gait_bml import DATASET as BML_DATASET
from generation.mocap.emotion_gait_bml import LICENCE as BML_LICENCE
from generation.mocap.real_corpus import (
    CITATION,
    DEFAULT_BML_PATH,
    LICENCE,
    SOURCE_URL,
    RealCorpora,
    load_real_corpus,
    read_meta,
)
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS

from .config import GaitDataConfig
from .data import GaitSequences
from .real_data import RealAugment, clip_sequences, concat_sequences, stage_clips
from .weights import TrainingData

LABEL_MODES = ("acted", "soft")
BOTH_STAGE = "finetune-both"
EXTENDED_FRAMES = 150
BML_AUGMENT = RealAugment(windows_per_clip=3)
BANDAI_AUGMENT = RealAugment(windows_per_clip=12)


def extend_loop(motion: Motion, n_frames: int) -> Motion:
    """A looped capture (``metadata['loop_period_frames']`` = L) lengthened to ``n_frames``: frame t is the
    captured frame t mod L, its root moved on by (t // L) times one cycle's ground travel (root[L] - root[0], height
    kept). A motion without a loop period, or already long enough, is returned unchanged."""
    L = motion.metadata.get("loop_period_frames")
    if not L or motion.num_frames >= n_frames or L >= motion.num_frames:
        return motion
    t = np.arange(n_frames)
    k, r = t // L, t % L
    step = motion.root_positions[L] - motion.root_positions[0]
    step[1] = 0.0
    root = motion.root_positions[r] + k[:, None] * step
    meta = {**motion.metadata, "extended_from_frames": motion.num_frames, "extended_to_frames": n_frames}
    return Motion(motion.skeleton, motion.rotations[r], root, motion.fps, meta)


def emotion_for(clip, labels: str) -> np.ndarray:
    """(4,) emotion vector of a corpus clip (see the module docstring)."""
    if labels not in LABEL_MODES:
        raise ValueError(f"labels must be one of {LABEL_MODES}, got {labels!r}")
    eye = np.eye(len(GAIT_EMOTIONS))
    acted = clip.motion.metadata.get("acted_label", clip.label)
    if acted not in GAIT_EMOTIONS:
        acted = CAPTURE_GAIT_EMOTIONS.get(clip.style, acted)
    vec = eye[GAIT_EMOTIONS.index(acted)]
    perceived = clip.motion.metadata.get("perceived_label")
    if labels == "soft" and perceived in GAIT_EMOTIONS:
        vec = 0.5 * vec + 0.5 * eye[GAIT_EMOTIONS.index(perceived)]
    return vec


def _with_vector(clips: list, data: GaitDataConfig, augment: RealAugment, labels: str) -> list[GaitSequences]:
    """Sequences per group of clips with one emotion vector (their rows get that vector)."""
    import torch

    groups: dict[tuple, list] = {}
    for c in clips:
        groups.setdefault(tuple(np.round(emotion_for(c, labels), 6)), []).append(c)
    parts = []
    for vec, group in sorted(groups.items()):
        seqs = clip_sequences(group, data, augment)
        seqs.emotion = torch.as_tensor(np.tile(np.asarray(vec, np.float32), (len(seqs), 1)),
                                       dtype=seqs.emotion.dtype)
        parts.append(seqs)
    return parts


def bml_clips(split, path: str | Path | None = None, n_frames: int = EXTENDED_FRAMES) -> list:
    """BML corpus clips of ``split`` (performer split), their loops extended to ``n_frames``."""

    path = Path(path) if path is not None else DEFAULT_BML_PATH
    clips = load_real_corpus(path, skeleton="gait", split=split)
    for c in clips:
        c.motion = extend_loop(c.motion, n_frames)
    return clips


def load_both_sequences(data: GaitDataConfig, labels: str = "acted", bandai_path: str | Path | None = None,
                        bml_path: str | Path | None = None, bandai_windows: int | None = None) -> GaitSequences:
    """Training rows (Bandai dataset-1 emotion walks + BML training performers, augmented) and validation rows
    (BML validation performers, as captured) with their ``training_data`` (real capture of stage
    ``finetune-both``: both corpora with licences, citations, splits and SHA-256, the labels and the augmentation)
    for the weights file's record. ``bandai_windows``: windows per Bandai take (default :data:`BANDAI_AUGMENT`'s 12;
    more weighs the four Bandai takes more against the 84 BML walks)."""
    bandai, bml = astuple(RealCorpora.of(bandai_path, bml_path))
    bandai_train = stage_clips("finetune", "train", bandai)
    bml_train = bml_clips("train", bml)
    bml_val = bml_clips("val", bml)
    bandai_augment = RealAugment(windows_per_clip=bandai_windows) if bandai_windows else BANDAI_AUGMENT
    parts = _with_vector(bandai_train, data, bandai_augment, labels)
    parts += _with_vector(bml_train, data, BML_AUGMENT, labels)
    parts += _with_vector(bml_val, data, RealAugment.none(), labels)
    base = 0
    for p in parts:
        p.base_index = p.base_index + base
        base = int(p.base_index.max()) + 1
    corpus = {
        "stage": BOTH_STAGE,
        "labels": labels,
        "datasets": [_bandai_record(bandai, bandai_train), _bml_record(bml, len(bml_train), len(bml_val))],
        "augment": {"bandai_windows_per_clip": bandai_augment.windows_per_clip,
                    "bml_windows_per_clip": BML_AUGMENT.windows_per_clip, "mirror": True,
                    "speed_factors": list(BML_AUGMENT.speed_factors), "offsets": list(BML_AUGMENT.offsets)},
    }
    return replace(concat_sequences(parts), training_data=TrainingData.real(BOTH_STAGE, corpus, labels=labels),
                   clip_names=tuple(name for p in parts for name in p.clip_names))


def _bandai_record(path: Path, train_clips: list) -> dict:
    """The Bandai corpus file in a ``finetune-both`` training record."""
    return {"name": "bandai-namco-1", "corpus": str(path), "sha256": file_sha256(path), "licence": LICENCE,
            "citation": CITATION, "url": SOURCE_URL, "split": "by take (take 1 train, take 2 test)",
            "clips": sorted(c.name for c in train_clips)}


def _bml_record(path: Path, n_train: int, n_val: int) -> dict:
    """The BML corpus file in a ``finetune-both`` training record (split rule and performers from its meta)."""
    meta = read_meta(path)
    return {"name": BML_DATASET, "corpus": str(path), "sha256": file_sha256(path), "licence": BML_LICENCE,
            "citation": BML_CITATION, "url": meta.get("source_url", ""), "split": meta.get("split_rule", ""),
            "performer_split": meta.get("performer_split", {}), "clips_train": n_train, "clips_val": n_val,
            "extended_frames": EXTENDED_FRAMES}
