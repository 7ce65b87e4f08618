"""The import manifest: a CSV naming each file to import and its labels (docs/study.md, "Bring your own stimuli").

Columns (:data:`MANIFEST_COLUMNS`; only ``path`` and ``modality`` are required, unknown columns are an error so a
misspelt label is not silently dropped):

    path        the file, relative to the manifest's folder: a video (.mp4 .m4v .mov .webm .mkv .avi) or a .bvh
    modality    gait | gesture | other (other: a video that is neither; a .bvh must be gait or gesture)
    origin      imported (blank means imported)
    happy, sad, angry, neutral, final_*     intended gait emotion vector (all four or none, each 0..1, not all 0;
                l1-normalised on import); final_*: a transition's final vector (gait only)
    emotion_label   a gesture emotion (protocol.vocabulary.GESTURE_EMOTIONS); not for gait clips
    valence, arousal, dominance             intended VAD, each 0..1
    theme, weight   a style theme (protocol.vocabulary.CLIP_THEMES) and its weight (required with a theme)
    title, licence, citation, notes         free text, kept with the clip
    keep_audio  yes | no (blank: the command's --keep-audio); videos only
    body        human | mannequin | stick | points (blank: human); BVH only: how the figure is drawn

The columns are separated by commas, or by semicolons or tabs (as spreadsheets in decimal-comma locales write
CSV; labels may then use decimal commas). Column names are lower case. A path that could leave the manifest's
folder (absolute, ``..``, a symlink pointing out of it) is refused. Every problem of a row is a
:class:`ManifestError` naming the manifest, the row (1 = the first line after the header) and the field.
"""
from __future__ import annotations

import csv
import difflib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from generation.render.settings import BODIES
from protocol.vocabulary import (
    CLIP_MODALITIES,
    CLIP_THEMES,
    FINAL_EMOTION_COLUMNS,
    GAIT_EMOTIONS,
    GESTURE_EMOTIONS,
    IMPORTED,
    OTHER_MODALITY,
    VAD_DIMENSIONS,
)

VIDEO_SUFFIXES = (".mp4", ".m4v", ".mov", ".webm", ".mkv", ".avi")
MOTION_SUFFIXES = (".bvh",)
MAX_MANIFEST_BYTES = 8 * 1024 * 1024
"""Largest manifest read (bytes), checked before it is opened."""
LABEL_COLUMNS = (*GAIT_EMOTIONS, *FINAL_EMOTION_COLUMNS, "emotion_label", *VAD_DIMENSIONS, "theme", "weight")
TEXT_COLUMNS = ("title", "licence", "citation", "notes")
OPTION_COLUMNS = ("keep_audio", "body")
MANIFEST_COLUMNS = ("path", "modality", "origin", *LABEL_COLUMNS, *TEXT_COLUMNS, *OPTION_COLUMNS)
"""The manifest's columns, in the order of the example in docs/study.md."""

YES = ("yes", "true", "1", "y")
NO = ("no", "false", "0", "n")


class ManifestError(ValueError):
    """A manifest (or one of its rows) that cannot be imported; names the manifest, row and field."""

    def __init__(self, manifest: str | Path, row: int | None, field: str | None, message: str):
        where = f"{manifest}" + (f": row {row}" if row is not None else "") + (f": field {field!r}" if field else "")
        super().__init__(f"{where}: {message}")
        self.row, self.field, self.message = row, field, message


@dataclass(frozen=True)
class ManifestRow:
    """One checked manifest row.

    ``row`` is 1 for the first line after the header; ``path`` the text as given; ``file`` the resolved file
    (inside the manifest's folder); ``labels`` the clips.csv label fields (floats / strings; gait vectors
    l1-normalised); ``text`` title, licence, citation and notes; ``keep_audio`` None when the column is blank."""

    row: int
    path: str
    file: Path
    modality: str
    kind: str                      # "video" or "motion"
    labels: dict = field(default_factory=dict)
    text: dict = field(default_factory=dict)
    keep_audio: bool | None = None
    body: str = "human"


@dataclass(frozen=True)
class BadRow:
    """A manifest row that failed its checks: its number, the path as given and the error."""

    row: int
    path: str
    error: ManifestError


def safe_file(folder: Path, given: str) -> Path:
    """The file ``given`` names inside ``folder``; ValueError when it is absolute, has a ``..`` part, resolves
    (symlinks followed) outside ``folder`` or is not a regular file."""
    text = given.strip()
    if not text:
        raise ValueError("is empty")
    pure = PurePosixPath(text.replace("\\", "/"))
    if pure.is_absolute() or text.startswith(("/", "\\")) or (len(text) > 1 and text[1] == ":"):
        raise ValueError(f"{given!r} is an absolute path; give it relative to the manifest's folder")
    if ".." in pure.parts:
        raise ValueError(f"{given!r} leaves the manifest's folder ('..')")
    base = folder.resolve()
    target = (base / Path(*pure.parts)).resolve()
    if not target.is_relative_to(base):
        raise ValueError(f"{given!r} leads outside the manifest's folder (a symlink to {target})")
    if not target.exists():
        raise ValueError(f"no such file {given!r} in {base}")
    if not target.is_file():
        raise ValueError(f"{given!r} is not a regular file")
    return target


def _number(text: str, lo: float | None, hi: float | None):
    value = float(text)
    if not math.isfinite(value) or (lo is not None and value < lo) or (hi is not None and value > hi):
        raise ValueError
    return value


def _labels(raw: dict, modality: str, fail) -> dict:
    """The label fields of one row, checked (``fail(field, message)`` raises)."""
    out: dict = {}
    for group in (GAIT_EMOTIONS, FINAL_EMOTION_COLUMNS):
        given = {c: raw[c] for c in group if raw.get(c)}
        if not given:
            continue
        if modality != "gait":
            fail(next(iter(given)), f"an emotion vector is for gait clips, not {modality}")
        missing = [c for c in group if c not in given]
        if missing:
            fail(missing[0], f"give all of {', '.join(group)} or none")
        values = {}
        for c in group:
            try:
                values[c] = _number(given[c], 0.0, 1.0)
            except ValueError:
                fail(c, f"expected a number in 0..1, got {given[c]!r}")
        total = sum(values.values())
        if not total > 0:
            fail(group[0], "the emotion vector sums to 0")
        out.update({c: round(v / total, 6) for c, v in values.items()})
    if any(raw.get(c) for c in FINAL_EMOTION_COLUMNS) and not raw.get(GAIT_EMOTIONS[0]):
        fail(GAIT_EMOTIONS[0], "a transition (final_*) needs its initial vector too")
    label = (raw.get("emotion_label") or "").lower()
    if label:
        if modality == "gait":
            fail("emotion_label", "gait clips are labelled with happy, sad, angry, neutral, not emotion_label")
        if label not in GESTURE_EMOTIONS:
            fail("emotion_label", f"expected one of {', '.join(GESTURE_EMOTIONS)}, got {raw['emotion_label']!r}")
        out["emotion_label"] = label
    for c in VAD_DIMENSIONS:
        if raw.get(c):
            try:
                out[c] = _number(raw[c], 0.0, 1.0)
            except ValueError:
                fail(c, f"expected a number in 0..1, got {raw[c]!r}")
    theme = (raw.get("theme") or "").lower()
    if theme and theme not in CLIP_THEMES:
        fail("theme", f"expected one of {', '.join(CLIP_THEMES)}, got {raw['theme']!r}")
    if raw.get("weight"):
        try:
            out["weight"] = _number(raw["weight"], None, None)
        except ValueError:
            fail("weight", f"expected a number, got {raw['weight']!r}")
    if theme:
        if "weight" not in out:
            fail("weight", "required with a theme (0 for an unstyled walk)")
        out["theme"] = theme
    return out


def check_row(raw: dict, row: int, folder: Path, manifest: str | Path) -> ManifestRow:
    """One manifest line (a dict of stripped cells) -> ManifestRow; ManifestError names the first problem."""

    def fail(name: str, message: str):
        raise ManifestError(manifest, row, name, message)

    given = raw.get("path", "")
    try:
        file = safe_file(folder, given)
    except ValueError as exc:
        fail("path", str(exc))
    suffix = file.suffix.lower()
    if suffix not in VIDEO_SUFFIXES + MOTION_SUFFIXES:
        fail("path", f"{given!r}: expected a video ({' '.join(VIDEO_SUFFIXES)}) or a motion file "
                     f"({' '.join(MOTION_SUFFIXES)})")
    kind = "motion" if suffix in MOTION_SUFFIXES else "video"
    modality = raw.get("modality", "").lower()
    if modality not in CLIP_MODALITIES:
        fail("modality", f"expected one of {', '.join(CLIP_MODALITIES)}, got {raw.get('modality', '')!r}")
    if kind == "motion" and modality == OTHER_MODALITY:
        fail("modality", "a motion file is rendered on the gait or the gesture skeleton: give gait or gesture")
    origin = raw.get("origin", "").lower() or IMPORTED
    if origin != IMPORTED:
        fail("origin", f"imported clips have origin {IMPORTED!r}, got {raw['origin']!r}")
    labels = _labels(raw, modality, fail)
    keep = raw.get("keep_audio", "").lower()
    if keep and keep not in YES + NO:
        fail("keep_audio", f"expected yes or no, got {raw['keep_audio']!r}")
    if keep and kind == "motion":
        fail("keep_audio", "a motion file has no audio")
    body = raw.get("body", "").lower()
    if body and kind == "video":
        fail("body", "is for motion files (how the figure is drawn), not videos")
    if body and body not in BODIES:
        fail("body", f"expected one of {', '.join(BODIES)}, got {raw['body']!r}")
    return ManifestRow(row=row, path=given, file=file, modality=modality, kind=kind, labels=labels,
                       text={c: raw.get(c, "") for c in TEXT_COLUMNS}, keep_audio=(keep in YES) if keep else None,
                       body=body or "human")


DELIMITERS = (",", ";", "\t")
"""Column separators a manifest may use: a comma, or a semicolon or tab as spreadsheets write CSV in locales whose
decimal mark is a comma."""
DECIMAL_COMMA = re.compile(r"^[+-]?\d*,\d+$")


def sniff_delimiter(header_line: str) -> str:
    """The separator of a manifest: the one of :data:`DELIMITERS` that splits its header line into the most
    manifest column names (in any case; the comma when none does better). A header names the columns it has, so
    this never depends on the cells, which may hold commas (citations) or decimal commas."""
    known = {c.lower() for c in MANIFEST_COLUMNS}

    def names(delimiter: str) -> int:
        return sum(h.strip().strip('"').lower() in known for h in header_line.split(delimiter))

    return max(DELIMITERS, key=names)           # the first of equals: the comma


def expected_column(name: str) -> str:
    """A hint for a header name that is not a manifest column: the column it differs from only in case, else a
    close spelling; "" when none is near."""
    same = [c for c in MANIFEST_COLUMNS if c.lower() == name.lower()]
    if same:
        return f"; column names are lower case: write {same[0]!r}"
    close = difflib.get_close_matches(name.lower(), MANIFEST_COLUMNS, n=1, cutoff=0.8)
    return f"; did you mean {close[0]!r}?" if close else ""


def _cells(raw: dict, delimiter: str) -> dict:
    """One line's cells, stripped; with a semicolon or tab separator a label's decimal comma (0,8) reads as 0.8."""
    cells = {k: (v or "").strip() for k, v in raw.items() if k is not None and isinstance(v, str)}
    if delimiter != ",":
        cells.update({k: v.replace(",", ".") for k, v in cells.items()
                      if k in LABEL_COLUMNS and DECIMAL_COMMA.match(v)})
    return cells


def read_manifest(path: str | Path) -> list[ManifestRow | BadRow]:
    """Every row of the manifest at ``path``, checked: a ManifestRow or a BadRow with its error.

    The separator is a comma, a semicolon or a tab (:func:`sniff_delimiter`). Raises ManifestError (row None) for a
    manifest that cannot be read at all: missing, not UTF-8, no header, without the ``path`` or ``modality``
    column, or with a column that is not a manifest column (names are lower case; the error names the column
    meant when it differs only in case or spelling)."""
    path = Path(path)
    try:
        size = path.stat().st_size
        if size > MAX_MANIFEST_BYTES:
            raise ManifestError(path, None, None, f"{size / 2**20:.1f} MiB, larger than the manifest limit of "
                                                  f"{MAX_MANIFEST_BYTES / 2**20:.0f} MiB (one line per file)")
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ManifestError(path, None, None, f"cannot read ({exc}): save it as UTF-8 text (a spreadsheet's "
                                              "\"CSV UTF-8\")") from None
    except OSError as exc:
        raise ManifestError(path, None, None, f"cannot read ({exc})") from None
    lines = text.splitlines()
    delimiter = sniff_delimiter(lines[0]) if lines else ","
    reader = csv.DictReader(lines, delimiter=delimiter)
    header = [h.strip() for h in (reader.fieldnames or [])]
    if not header:
        raise ManifestError(path, None, None, "empty: expected a header line with at least path and modality")
    for needed in ("path", "modality"):
        if needed not in header:
            differs = [h for h in header if h.lower() == needed]
            hint = f"; column names are lower case: write {needed!r} for {differs[0]!r}" if differs else ""
            raise ManifestError(path, None, needed, f"missing column (the header has {', '.join(header)}){hint}")
    unknown = [h for h in header if h not in MANIFEST_COLUMNS]
    if unknown:
        raise ManifestError(path, None, unknown[0], f"not a manifest column (expected some of "
                                                    f"{', '.join(MANIFEST_COLUMNS)}){expected_column(unknown[0])}")
    reader.fieldnames = header
    out: list[ManifestRow | BadRow] = []
    for row, raw in enumerate(reader, start=1):
        cells = _cells(raw, delimiter)
        if not any(cells.values()):
            continue
        try:
            out.append(check_row(cells, row, path.parent, path.name))   # the report lies beside the manifest
        except ManifestError as exc:
            out.append(BadRow(row, cells.get("path", ""), exc))
    return out
