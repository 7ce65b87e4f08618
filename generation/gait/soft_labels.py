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

No import of the analysis library: clip_norms.csv is read here with the csv module and checked cell by cell;
problems raise :class:`SoftLabelError` naming file, line and column.
"""
from __future__ import annotations

import csv
import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generation.core.digest import file_sha256
from generation.core.motion import Motion, MotionFormatError
from generation.core.skeleton import GAIT_JOINTS, gait_skeleton
from generation.formats.bvh import read_bvh
from study_protocol import CLIP_NORMS_COLUMNS, GAIT_EMOTIONS, NORMS_SHARE_PREFIX

from .config import GaitDataConfig
from .data import GaitSequences
from .real_data import STAGE_AUGMENT, clip_sequences
from .weights import TrainingData

SHARE_COLUMNS = tuple(f"{NORMS_SHARE_PREFIX}{e}" for e in GAIT_EMOTIONS)
REQUIRED = ("clip_id", "modality", "section_type", "question", "n_ratings", *SHARE_COLUMNS)
SUM_TOLERANCE = 1e-3
FPS = 30.0


class SoftLabelError(ValueError):
    """clip_norms.csv or a clip's motion cannot give a soft label; the message names file, line and column."""


@dataclass(frozen=True)
class SoftLabel:
    """One rated walk: its clip id, perceived shares (4,) in GAIT_EMOTIONS order (sum 1), ratings and file line."""
    clip_id: str
    shares: np.ndarray
    n_ratings: int
    line: int


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
    path = Path(path)
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            header = reader.fieldnames or []
            missing = [c for c in REQUIRED if c not in header]
            if missing:
                raise SoftLabelError(f"{path.name} header, column {missing[0]!r}: required column is missing "
                                     f"(clip_norms.csv has {', '.join(CLIP_NORMS_COLUMNS)}, then share_<label>)")
            rows = list(reader)
    except OSError as exc:
        raise SoftLabelError(f"{path}: cannot read ({exc.strerror or exc})") from None
    out = []
    for line, row in enumerate(rows, start=2):
        if (row["modality"], row["section_type"], row["question"]) != ("gait", "emotion_choice", "perceived"):
            continue
        values = []
        for c in ("n_ratings", *SHARE_COLUMNS):
            try:
                v = float(row[c])
            except (TypeError, ValueError):
                raise SoftLabelError(f"{path.name} line {line}, column {c!r}: {row[c]!r} is not a number") from None
            if not math.isfinite(v) or v < 0:
                raise SoftLabelError(f"{path.name} line {line}, column {c!r}: {row[c]!r} is not a number >= 0")
            values.append(v)
        shares = np.array(values[1:])
        if abs(shares.sum() - 1) > SUM_TOLERANCE:
            raise SoftLabelError(f"{path.name} line {line}, column 'share_*': the gait shares sum to "
                                 f"{shares.sum():.4g}, not 1")
        if values[0] >= min_ratings:
            out.append(SoftLabel(row["clip_id"].strip(), shares / shares.sum(), int(values[0]), line))
    if not out:
        raise SoftLabelError(f"{path.name}: no gait emotion row (section_type emotion_choice, question perceived) "
                             f"with at least {min_ratings} rating(s)")
    return out


def rated_clips(labels: list[SoftLabel], motions_dir: str | Path, source: str = "clip_norms.csv") -> list[RatedClip]:
    """Each label's motion from ``motions_dir/<clip_id>.bvh`` on the 21-joint gait skeleton at 30 fps, as a
    training clip. Raises SoftLabelError naming the clip (and its line of ``source``) when the file is missing
    or not a gait motion."""
    out = []
    for lab in labels:
        path = Path(motions_dir) / f"{lab.clip_id}.bvh"
        where = f"{source} line {lab.line}, column 'clip_id': clip {lab.clip_id!r}"
        if not path.exists():
            raise SoftLabelError(f"{where}: no motion file {path}")
        try:
            motion = read_bvh(path, scale=1.0)
        except MotionFormatError as exc:
            raise SoftLabelError(f"{where}: {exc}") from None
        gait = gait_skeleton()
        if tuple(np.asarray(motion.skeleton.parents)) != tuple(np.asarray(gait.parents)):
            raise SoftLabelError(f"{where}: {path.name} is not on the 21-joint gait skeleton")
        # BVH names leaf joints after their End Site ("left_heel_end"): give the joints their gait names back
        motion = dataclasses.replace(motion, skeleton=dataclasses.replace(motion.skeleton, name="gait",
                                                                          joints=tuple(GAIT_JOINTS)))
        if abs(motion.fps - FPS) > 1e-3:
            raise SoftLabelError(f"{where}: {path.name} is at {motion.fps:g} fps, the network reads {FPS:g}")
        out.append(RatedClip(lab.clip_id, motion, "train", lab.shares))
    return out


def load_soft_label_sequences(norms_path: str | Path, motions_dir: str | Path, data: GaitDataConfig,
                              study: str | None = None, min_ratings: int = 1, augment=None) -> GaitSequences:
    """Training sequences of every rated walk with its perceived shares as the emotion input; their
    ``training_data`` is of kind ``rated`` with corpus ``{"soft_labels": {path, sha256, study, n_clips,
    n_ratings, clips: {clip_id: n_ratings}}}`` (it goes into the weights file). ``study`` defaults to the name of
    the folder holding the file."""
    norms_path = Path(norms_path)
    labels = read_soft_labels(norms_path, min_ratings)
    clips = rated_clips(labels, motions_dir, norms_path.name)
    seqs = clip_sequences(clips, data, augment or STAGE_AUGMENT["finetune"], emotion_of=lambda c: c.shares)
    n_ratings = sum(lab.n_ratings for lab in labels)
    study = study or norms_path.resolve().parent.name
    norms = {"path": str(norms_path), "sha256": file_sha256(norms_path), "study": study, "n_clips": len(labels),
             "n_ratings": n_ratings, "clips": {lab.clip_id: lab.n_ratings for lab in labels}}
    description = (f"soft labels: the perceived emotion shares of {len(labels)} rated walks ({n_ratings} ratings, "
                   f"study {study})")
    return dataclasses.replace(seqs, training_data=TrainingData.rated(description, norms))
