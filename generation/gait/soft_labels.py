"""Soft emotion labels from people's ratings: each rated walk's perceived share vector as its emotion target.

Seed 000 trained its network on annotators' soft labels (section 3.2.2: the share of annotators who chose each
emotion). A norming study of this platform gives the same thing for our own clips: the ``share_happy .. share_neutral``
of each walk in ``clip_norms.csv`` (the public format of docs/study.md, written by the analysis). This module reads
them (rows of section ``emotion_choice``, question ``perceived``, gait clips), finds each clip's motion
(``MEDIA_ROOT/motions/<clip_id>.bvh``, kept for every rendered clip, real source takes and generated walks alike)
and turns the walks into network sequences whose emotion input is the share vector
(:func:`load_soft_label_sequences`). ``python -m generation.gait.train --soft-labels clip_norms.csv`` uses them
(with ``--real finetune`` beside the real fine-tuning takes); the weights file records the norms in its ``corpus``
entry: path, sha256, the study, the clips and their numbers of ratings.

Reading clip_norms.csv, the catalogue and the motion files is shared with the gesture network's soft labels
(:mod:`generation.formats.rated_clips`); problems raise :class:`SoftLabelError` naming file, line and column.

Only the stored motion is read, never the source take a real source clip was cut from: clips.csv names no source
file (only the clip record does, as the generator input ``file``), and the take is not what people rated (the
``captured_file`` generator retargets it onto the 21-joint gait skeleton, starts it at ``start_s`` and resamples it,
and the clip lasts the render duration; redoing that means running the generator, which lives in generation.plans,
above this package). The renderer writes ``motions/<clip_id>.bvh`` for every clip it renders,
real source takes included, so a rated clip without one is an imported video (no motion at all) or a deleted file.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from generation.core.skeleton import gait_skeleton
from generation.formats.rated_clips import (
    NormRow,
    SoftLabelError,
    default_catalogue,
    norms_record,
    read_catalogue,
    read_clip_motion,
    read_norm_rows,
    share_columns,
    where,
)
from protocol.vocabulary import GAIT_EMOTIONS

from .config import GaitDataConfig
from .data import GaitSequences
from .real_data import STAGE_AUGMENT, clip_sequences
from .weights import TrainingData

__all__ = ["SHARE_COLUMNS", "RatedClip", "SoftLabel", "SoftLabelError", "load_soft_label_sequences", "rated_clips",
           "read_soft_labels"]

SHARE_COLUMNS = share_columns(GAIT_EMOTIONS)
FPS = 30.0

SoftLabel = NormRow
"""One rated walk: its clip id, perceived shares (4,) in GAIT_EMOTIONS order (sum 1), ratings and file line."""


@dataclass
class RatedClip:
    """A rated walk as real_data.clip_sequences takes it: name, motion, split, and its soft label."""
    name: str
    motion: Motion
    split: str
    shares: np.ndarray
    label: str = ""


def read_soft_labels(path: str | Path, min_ratings: int = 1) -> list[SoftLabel]:
    """The gait emotion rows of a clip_norms.csv with at least ``min_ratings`` ratings. Raises SoftLabelError."""
    return read_norm_rows(path, "gait", "emotion_choice", GAIT_EMOTIONS, min_ratings=min_ratings)


def rated_clips(labels: list[SoftLabel], motions_dir: str | Path, source: str = "clip_norms.csv",
                catalogue: dict | None = None, catalogue_name: str = "clips.csv") -> list[RatedClip]:
    """Each label's motion from ``motions_dir/<clip_id>.bvh`` on the 21-joint gait skeleton at 30 fps, as a
    training clip. Raises SoftLabelError naming the clip (and its line of ``source``) when it is not in the
    ``catalogue`` (clip_id -> row, when given), its file is missing or it is not a gait motion."""
    out = []
    for lab in labels:
        motion = read_clip_motion(lab, motions_dir, gait_skeleton(), catalogue, source, catalogue_name)
        if abs(motion.fps - FPS) > 1e-3:
            raise SoftLabelError(f"{where(source, lab)}: {lab.clip_id}.bvh is at {motion.fps:g} fps, the network "
                                 f"reads {FPS:g}")
        out.append(RatedClip(lab.clip_id, motion, "train", lab.shares))
    return out


def load_soft_label_sequences(norms_path: str | Path, motions_dir: str | Path, data: GaitDataConfig,
                              study: str | None = None, min_ratings: int = 1, augment=None,
                              catalogue: str | Path | None = None) -> GaitSequences:
    """Training sequences of every rated walk with its perceived shares as the emotion input; their
    ``training_data`` is of kind ``rated`` with corpus ``{"soft_labels": {path, sha256, study, n_clips,
    n_ratings, clips: {clip_id: n_ratings}}}`` (it goes into the weights file). ``study`` defaults to the name of
    the folder holding the file; ``catalogue`` (default ``MEDIA_ROOT/clips.csv`` beside the motions folder, when
    there) tells an unknown clip from a missing motion file."""
    norms_path = Path(norms_path)
    labels = read_soft_labels(norms_path, min_ratings)
    catalogue = Path(catalogue) if catalogue is not None else default_catalogue(motions_dir)
    clips = rated_clips(labels, motions_dir, norms_path.name, read_catalogue(catalogue), str(catalogue))
    seqs = clip_sequences(clips, data, augment or STAGE_AUGMENT["finetune"], emotion_of=lambda c: c.shares)
    norms = norms_record(norms_path, labels, study)
    description = (f"soft labels: the perceived emotion shares of {len(labels)} rated walks ({norms['n_ratings']} "
                   f"ratings, study {norms['study']})")
    return dataclasses.replace(seqs, training_data=TrainingData.rated(description, norms))
