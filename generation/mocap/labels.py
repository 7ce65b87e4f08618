"""Emotion labels of imported files: a labels CSV or a regular expression on the file names.

Labels CSV: a ``source`` column (the file's name, stem or path as given; matched in that order) and either one
column per gait emotion (``protocol.vocabulary.GAIT_EMOTIONS``, a vector, l1-normalised on import) or an ``emotion``
column (a category: a gait emotion or a gesture emotion of ``protocol.vocabulary.GESTURE_EMOTIONS``).
``--label-pattern REGEX``: the named group ``emotion`` (or the first named group) of a search in the file name.

Stored in the Motion's metadata as the procedural corpora do: gait ``emotion`` {happy: .., ...} (l1-normalised);
gestures ``emotion_label`` and ``vad`` [valence, arousal, dominance] from ``protocol.vocabulary.GESTURE_VAD``.
"""
from __future__ import annotations

import csv
import re
from dataclasses import dataclass
from pathlib import Path

from protocol.vocabulary import GAIT_EMOTIONS, GESTURE_VAD


class LabelError(ValueError):
    """A labels file or pattern is malformed, or a label is not in the study vocabulary."""


@dataclass(frozen=True)
class Label:
    """An emotion label: a category, a gait emotion vector (GAIT_EMOTIONS order), or both."""

    emotion: str | None = None
    vector: tuple[float, ...] | None = None

    def metadata(self, skeleton_name: str) -> dict:
        """Metadata entries for a Motion on the ``gait`` or ``gesture`` skeleton."""
        out: dict = {}
        vector = self.vector
        if vector is None and self.emotion in GAIT_EMOTIONS:
            vector = tuple(float(e == self.emotion) for e in GAIT_EMOTIONS)
        if self.emotion is not None:
            out["emotion_label"] = self.emotion
        if skeleton_name == "gesture":
            if self.emotion is not None:
                if self.emotion not in GESTURE_VAD:
                    raise LabelError(f"gesture emotion {self.emotion!r} is not one of {', '.join(GESTURE_VAD)}")
                out["vad"] = [float(x) for x in GESTURE_VAD[self.emotion]]
            if vector is not None and self.vector is not None:
                out["emotion"] = dict(zip(GAIT_EMOTIONS, vector, strict=True))
        elif vector is not None:
            out["emotion"] = dict(zip(GAIT_EMOTIONS, vector, strict=True))
        elif self.emotion is not None:
            raise LabelError(f"gait emotion {self.emotion!r} is not one of {', '.join(GAIT_EMOTIONS)}")
        return out


def open_csv(path: str | Path) -> tuple[Path, csv.DictReader, list[str]]:
    """(path, a DictReader over its rows, the stripped header names) of a UTF-8 (BOM allowed) CSV file; LabelError
    when it cannot be read. ``reader.line_num`` gives the line of the row just read, for error messages."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise LabelError(f"{path}: cannot read ({exc.strerror or exc})") from None
    reader = csv.DictReader(text.splitlines())
    cols = [c.strip() for c in (reader.fieldnames or [])]
    reader.fieldnames = cols
    return path, reader, cols


def read_labels(path: str | Path) -> dict[str, Label]:
    """{source as written in the CSV: Label}; LabelError names the file and line of a bad row."""
    path, reader, cols = open_csv(path)
    has_vector = all(e in cols for e in GAIT_EMOTIONS)
    if "source" not in cols or not (has_vector or "emotion" in cols):
        raise LabelError(f"{path}: line 1: need a 'source' column and either 'emotion' or the columns "
                         f"{', '.join(GAIT_EMOTIONS)}; found {', '.join(cols) or 'no header'}")
    out: dict[str, Label] = {}
    for row in reader:
        ln = reader.line_num
        source = (row.get("source") or "").strip()
        if not source:
            raise LabelError(f"{path}: line {ln}: empty 'source'")
        emotion = (row.get("emotion") or "").strip().lower() or None
        if emotion is not None and emotion not in GAIT_EMOTIONS and emotion not in GESTURE_VAD:
            raise LabelError(f"{path}: line {ln}: emotion {emotion!r} is not in the study vocabulary "
                             f"({', '.join(sorted(set(GAIT_EMOTIONS) | set(GESTURE_VAD)))})")
        vector = None
        if has_vector and any((row.get(e) or "").strip() for e in GAIT_EMOTIONS):
            try:
                vals = [float(row[e]) for e in GAIT_EMOTIONS]
            except (TypeError, ValueError):
                raise LabelError(f"{path}: line {ln}: the columns {', '.join(GAIT_EMOTIONS)} must all be "
                                 f"numbers") from None
            total = sum(vals)
            if min(vals) < 0 or not total > 0:
                raise LabelError(f"{path}: line {ln}: the emotion vector must be non-negative and not all zero")
            vector = tuple(v / total for v in vals)
        if emotion is None and vector is None:
            raise LabelError(f"{path}: line {ln}: no label for {source!r}")
        if source in out:
            raise LabelError(f"{path}: line {ln}: {source!r} is labelled twice")
        out[source] = Label(emotion, vector)
    return out


def label_for(labels: dict[str, Label], file: Path, given_as: str) -> Label | None:
    """The label of a file: by the path as given, its name, then its stem."""
    for key in (given_as, str(file), file.name, file.stem):
        if key in labels:
            return labels[key]
    return None


def label_from_pattern(pattern: re.Pattern, file: Path) -> Label | None:
    """Label from the ``emotion`` (or first) named group of ``pattern`` searched in the file name."""
    m = pattern.search(file.name)
    if m is None:
        return None
    groups = m.groupdict()
    value = groups.get("emotion", next(iter(groups.values()), None))
    if not value:
        return None
    value = value.lower()
    if value not in GAIT_EMOTIONS and value not in GESTURE_VAD:
        raise LabelError(f"{file}: --label-pattern gives {value!r}, not in the study vocabulary")
    return Label(value)


def compile_pattern(regex: str) -> re.Pattern:
    try:
        pattern = re.compile(regex)
    except re.error as exc:
        raise LabelError(f"--label-pattern {regex!r}: {exc}") from None
    if not pattern.groupindex:
        raise LabelError(f"--label-pattern {regex!r} needs a named group, e.g. (?P<emotion>[a-z]+)")
    return pattern
