"""The clip catalogue file ``clips.csv`` (DESIGN.md "Interchange formats"): write, read, check against files.

One row per clip, columns :data:`CLIP_COLUMNS`, the quality columns :data:`QA_COLUMNS`, then the provenance
columns :data:`CLIP_PROVENANCE_COLUMNS` (title, licence, citation) and the body column :data:`CLIP_BODY_COLUMNS` (the
human body preset shown; files without the extra columns still read, their rows get blank cells); blank cells are
missing values. ``clip_id`` is the
clip's content hash, which is also the stem of its files ``clips/<clip_id>.mp4|.webm|.png``.
"""
from __future__ import annotations

import csv
import math
import os
from collections.abc import Iterable
from pathlib import Path

from generation.quality.checks import qa_columns
from protocol.vocabulary import (
    CLIP_BODY_COLUMNS,
    CLIP_COLUMNS,
    CLIP_FLOAT_COLUMNS,
    CLIP_INT_COLUMNS,
    CLIP_MODALITIES,
    CLIP_PROVENANCE_COLUMNS,
    ORIGINS,
    QA_COLUMNS,
    QA_FLOAT_COLUMNS,
)

ALL_COLUMNS = (*CLIP_COLUMNS, *QA_COLUMNS, *CLIP_PROVENANCE_COLUMNS, *CLIP_BODY_COLUMNS)


class CatalogueFormatError(ValueError):
    """A clips.csv that cannot be read; the message names the file, line and field."""


def _cell(value) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def read_clips_csv(path: str | Path) -> list[dict]:
    """Rows of a clips.csv as dicts with floats/ints/None; CatalogueFormatError names file, line and field."""
    path = Path(path)
    try:
        f = path.open(newline="", encoding="utf-8")
    except OSError as exc:
        raise CatalogueFormatError(f"{path}: cannot open ({exc})") from None
    rows = []
    with f:
        reader = csv.DictReader(f)
        missing = [c for c in CLIP_COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            raise CatalogueFormatError(f"{path}: line 1: missing column(s) {missing}")
        for line_no, raw in enumerate(reader, start=2):
            row: dict = {}
            for col in ALL_COLUMNS:
                text = (raw.get(col) or "").strip()
                if col in CLIP_FLOAT_COLUMNS or col in CLIP_INT_COLUMNS or col in QA_FLOAT_COLUMNS:
                    if not text:
                        row[col] = None
                        continue
                    try:
                        row[col] = int(text) if col in CLIP_INT_COLUMNS else float(text)
                    except ValueError:
                        kind = "an integer" if col in CLIP_INT_COLUMNS else "a number"
                        raise CatalogueFormatError(
                            f"{path}: line {line_no}: field {col!r}: expected {kind} or blank, got {text!r}") from None
                else:
                    row[col] = text
            if not row["clip_id"]:
                raise CatalogueFormatError(f"{path}: line {line_no}: field 'clip_id' is empty")
            for col, allowed in (("modality", CLIP_MODALITIES), ("origin", ORIGINS)):
                if row[col] not in allowed:
                    raise CatalogueFormatError(f"{path}: line {line_no}: field {col!r}: expected "
                                               f"{' or '.join(allowed)}, got {row[col]!r}")
            rows.append(row)
    return rows


def write_clips_csv(records: Iterable[dict], path: str | Path, merge: bool = True) -> list[dict]:
    """Write clip records (dicts with at least the CLIP_COLUMNS keys) to ``path`` atomically.

    The quality columns come from a record's ``qa`` dict (:func:`generation.quality.qa_columns`) or, for rows
    read back from the file, from their own qa_ keys; title, licence and citation from the record's own keys, else
    its ``metadata`` (captured data keeps its licence there); ``body`` from the record's ``body`` dict (its
    ``preset``) or, read back, the cell.

    With ``merge``, rows already in the file whose clip_id is not among ``records`` are kept (the
    catalogue collects every plan rendered into this media folder); rows with the same clip_id are
    replaced. Rows are sorted by clip_id. Returns the rows written.
    """
    path = Path(path)
    rows: dict[str, dict] = {}
    if merge and path.exists():
        for row in read_clips_csv(path):
            rows[row["clip_id"]] = row
    for rec in records:
        qa = qa_columns(rec["qa"]) if isinstance(rec.get("qa"), dict) else {c: rec.get(c) for c in QA_COLUMNS}
        meta = rec.get("metadata") if isinstance(rec.get("metadata"), dict) else {}
        provenance = {c: rec.get(c) or meta.get(c) for c in CLIP_PROVENANCE_COLUMNS}
        body = rec.get("body")
        body = {"body": body.get("preset") if isinstance(body, dict) else body}
        rows[str(rec["clip_id"])] = {**{c: rec.get(c) for c in CLIP_COLUMNS}, **qa, **provenance, **body}
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    with tmp.open("w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        writer.writerow(ALL_COLUMNS)
        for clip_id in sorted(rows):
            writer.writerow([_cell(rows[clip_id].get(c)) for c in ALL_COLUMNS])
    os.replace(tmp, path)
    return [rows[k] for k in sorted(rows)]


def check_catalogue(csv_path: str | Path, clips_dir: str | Path, webm: bool = False) -> list[str]:
    """Problems between a clips.csv and the clip files: rows without files, files without rows.

    Returns human-readable problems (empty when they match).
    """
    clips_dir = Path(clips_dir)
    rows = read_clips_csv(csv_path)
    problems = []
    ids = set()
    for row in rows:
        cid = row["clip_id"]
        ids.add(cid)
        for ext in ("mp4", "png") + (("webm",) if webm else ()):
            f = clips_dir / f"{cid}.{ext}"
            if not f.is_file() or f.stat().st_size == 0:
                problems.append(f"clip {cid}: {f.name} missing or empty")
    for f in sorted(clips_dir.glob("*.mp4")):
        if not f.name.startswith(".") and f.stem not in ids:
            problems.append(f"{f.name}: no row in {Path(csv_path).name}")
    return problems
