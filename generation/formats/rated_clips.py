"""Rated clips for training on perceived labels: the rows of ``clip_norms.csv``, the catalogue and the motion files.

Both network trainers take soft labels from a norming study's ``clip_norms.csv`` (the public format of
docs/study.md, written by the analysis): the gait network the ``share_<emotion>`` of rated walks
(:mod:`generation.gait.soft_labels`), the gesture network the ``share_<category>`` of rated gestures
(:mod:`generation.gesture.soft_labels`). What they share lives here, below both in the package layers:

- :func:`read_norm_rows`: one modality's rows of clip_norms.csv, checked cell by cell;
- :func:`read_catalogue`: the clip ids of ``clips.csv`` (to tell an unknown clip from a missing motion file);
- :func:`read_clip_motion`: a rated clip's stored motion ``MEDIA_ROOT/motions/<clip_id>.bvh`` on a given skeleton;
- :func:`norms_record`: what a weights file records of the norms it learned from (path, sha256, study, ratings).

No import of the analysis library: the files are read with the csv module. Every problem raises
:class:`SoftLabelError` naming file, line and column.
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
from generation.core.skeleton import Skeleton
from protocol.vocabulary import CLIP_NORMS_COLUMNS, NORMS_SHARE_PREFIX

from .bvh import read_bvh

SUM_TOLERANCE = 1e-3
KEY_COLUMNS = ("clip_id", "modality", "section_type", "question", "n_ratings")


class SoftLabelError(ValueError):
    """clip_norms.csv, the catalogue or a clip's motion cannot give a soft label; the message names file, line and
    column."""


@dataclass(frozen=True)
class NormRow:
    """One rated clip of clip_norms.csv: its id, perceived shares (L,) in the order of the labels asked for (sum 1),
    number of ratings and line in the file."""
    clip_id: str
    shares: np.ndarray
    n_ratings: int
    line: int


def share_columns(labels) -> tuple[str, ...]:
    """The clip_norms.csv columns of the shares of ``labels``: ``share_<label>``."""
    return tuple(f"{NORMS_SHARE_PREFIX}{label}" for label in labels)


def read_norm_rows(path: str | Path, modality: str, section_type: str, labels, question: str = "perceived",
                   min_ratings: int = 1) -> list[NormRow]:
    """The rows of one (modality, section_type, question) of a clip_norms.csv with at least ``min_ratings``
    ratings, their shares over ``labels``. Raises SoftLabelError naming file, line and column; a row whose shares do
    not sum to one names each share column with its value."""
    path = Path(path)
    columns = share_columns(labels)
    rows = _read_rows(path, (*KEY_COLUMNS, *columns))
    out = []
    for line, row in rows:
        if (row["modality"], row["section_type"], row["question"]) != (modality, section_type, question):
            continue
        n_ratings = _number(path, line, "n_ratings", row["n_ratings"])
        shares = np.array([_number(path, line, c, row[c]) for c in columns])
        if abs(shares.sum() - 1) > SUM_TOLERANCE:
            cells = ", ".join(f"{c!r} {row[c].strip()}" for c in columns)
            raise SoftLabelError(f"{path.name} line {line}, columns {cells}: the {modality} shares sum to "
                                 f"{shares.sum():.4g}, not 1")
        if n_ratings >= min_ratings:
            out.append(NormRow(row["clip_id"].strip(), shares / shares.sum(), int(n_ratings), line))
    if not out:
        raise SoftLabelError(f"{path.name}: no {modality} row (section_type {section_type}, question {question}) "
                             f"with at least {min_ratings} rating(s)")
    return out


def _read_rows(path: Path, required) -> list[tuple[int, dict]]:
    """(line, row) of a clip_norms.csv that has the ``required`` columns."""
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            header = reader.fieldnames or []
            missing = [c for c in required if c not in header]
            if missing:
                raise SoftLabelError(f"{path.name} header, column {missing[0]!r}: required column is missing "
                                     f"(clip_norms.csv has {', '.join(CLIP_NORMS_COLUMNS)}, then share_<label>)")
            return list(enumerate(reader, start=2))
    except OSError as exc:
        raise SoftLabelError(f"{path}: cannot read ({exc.strerror or exc})") from None


def _number(path: Path, line: int, column: str, text) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise SoftLabelError(f"{path.name} line {line}, column {column!r}: {text!r} is not a number") from None
    if not math.isfinite(value) or value < 0:
        raise SoftLabelError(f"{path.name} line {line}, column {column!r}: {text!r} is not a number >= 0")
    return value


def read_catalogue(path: str | Path | None) -> dict[str, dict] | None:
    """clip_id -> row (strings) of a clips.csv (the catalogue, ``MEDIA_ROOT/clips.csv``); None when ``path`` is None
    or no file is there (then an unknown clip cannot be told from a missing motion file)."""
    if path is None or not Path(path).is_file():
        return None
    path = Path(path)
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            if "clip_id" not in (reader.fieldnames or []):
                raise SoftLabelError(f"{path.name} header, column 'clip_id': required column is missing")
            return {(row.get("clip_id") or "").strip(): row for row in reader}
    except OSError as exc:
        raise SoftLabelError(f"{path}: cannot read ({exc.strerror or exc})") from None


def default_catalogue(motions_dir: str | Path) -> Path:
    """Where the catalogue of a motions folder is: ``MEDIA_ROOT/clips.csv`` beside ``MEDIA_ROOT/motions``."""
    return Path(motions_dir).parent / "clips.csv"


def where(source: str, row: NormRow) -> str:
    """The place of a rated clip in its clip_norms.csv, to start an error message with."""
    return f"{source} line {row.line}, column 'clip_id': clip {row.clip_id!r}"


def clip_motion_path(row: NormRow, motions_dir: str | Path, catalogue: dict | None, source: str,
                     catalogue_name: str = "clips.csv") -> Path:
    """``motions_dir/<clip_id>.bvh`` of a rated clip. SoftLabelError when the clip is not in the ``catalogue`` (when
    one is given) or its motion file is missing."""
    if catalogue is not None and row.clip_id not in catalogue:
        raise SoftLabelError(f"{where(source, row)}: unknown clip (not in the catalogue {catalogue_name})")
    path = Path(motions_dir) / f"{row.clip_id}.bvh"
    if not path.is_file():
        raise SoftLabelError(f"{where(source, row)}: no motion file {path} (the renderer keeps one for every clip "
                             f"it renders, the import for every imported motion file; an imported video has none)")
    return path


def read_clip_motion(row: NormRow, motions_dir: str | Path, skeleton: Skeleton, catalogue: dict | None = None,
                     source: str = "clip_norms.csv", catalogue_name: str = "clips.csv") -> Motion:
    """A rated clip's stored motion on ``skeleton``'s joint tree, its joints named as ``skeleton``'s (a BVH names leaf
    joints after their End Site), at the file's frame rate. SoftLabelError naming the clip and its line of
    ``source`` when it is unknown, its file is missing or unreadable, or the motion is on another skeleton."""
    path = clip_motion_path(row, motions_dir, catalogue, source, catalogue_name)
    try:
        motion = read_bvh(path, scale=1.0)
    except MotionFormatError as exc:
        raise SoftLabelError(f"{where(source, row)}: {exc}") from None
    if tuple(np.asarray(motion.skeleton.parents)) != tuple(np.asarray(skeleton.parents)):
        raise SoftLabelError(f"{where(source, row)}: {path.name} is not on the {len(skeleton.parents)}-joint "
                             f"{skeleton.name} skeleton")
    return dataclasses.replace(motion, skeleton=dataclasses.replace(motion.skeleton, name=skeleton.name,
                                                                    joints=tuple(skeleton.joints)))


def norms_record(path: str | Path, rows: list[NormRow], study: str | None = None, **extra) -> dict:
    """What a weights file records of the norms it learned from: ``{path, sha256, study, n_clips, n_ratings,
    clips: {clip_id: n_ratings}}`` plus ``extra``; ``study`` defaults to the name of the folder holding the file."""
    path = Path(path)
    return {"path": str(path), "sha256": file_sha256(path), "study": study or path.resolve().parent.name,
            "n_clips": len(rows), "n_ratings": sum(r.n_ratings for r in rows),
            "clips": {r.clip_id: r.n_ratings for r in rows}, **extra}
