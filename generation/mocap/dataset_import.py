"""A labelled capture dataset on disk -> the real-capture corpus: import every selected take, report every file.

Each take goes through :func:`generation.mocap.importer.import_file` (30 fps, onto the gait skeleton for
locomotion, the gesture skeleton for gestures); a take that fails (unreadable, wrong rig, import error or height
out of range: status ``error``) is a report row and is left out of the corpus, never patched. Takes are imported
in a process pool (``workers``) and come back in path order, so the corpus and the report do not depend on the
number of workers.
"""
from __future__ import annotations

import csv
import math
import sys
from collections import Counter
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from generation.core.skeleton import REFERENCE_HEIGHT_M
from protocol.vocabulary import GAIT_EMOTIONS, GESTURE_VAD

from . import bandai_namco as bn
from .importer import REPORT_COLUMNS, ImportOptions, import_file
from .labels import Label
from .real_corpus import CITATION, LICENCE, SOURCE_URL, CorpusClip, save_real_corpus

TAKE_COLUMNS = ("dataset", "content", "style", "label", "take", "split", "skeleton")
"""Columns the dataset import adds to the importer's report columns."""

FILE_ERROR = "error"


def report_columns() -> tuple[str, ...]:
    """``import_report.csv``'s header: the importer's columns, then :data:`TAKE_COLUMNS`."""
    return (*REPORT_COLUMNS, *TAKE_COLUMNS)


def _as_float(value) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _study_label(label: str, skeleton: str) -> Label | None:
    """The importer's emotion label when the style names one of the skeleton's study emotions (gait: the four
    gait emotions; gesture: the gesture categories), else None (the style is still kept in the metadata)."""
    vocabulary = GAIT_EMOTIONS if skeleton == "gait" else GESTURE_VAD
    return Label(emotion=label) if label in vocabulary else None


def take_row(take: bn.Take) -> dict:
    """The take's own columns (:data:`TAKE_COLUMNS`)."""
    return {"dataset": take.dataset, "content": take.content, "style": take.style, "label": take.label,
            "take": take.take, "split": take.split, "skeleton": take.skeleton or ""}


def import_take(take: bn.Take, height: float = REFERENCE_HEIGHT_M, build: str = "male"
                ) -> tuple[CorpusClip | None, dict]:
    """One take -> (its CorpusClip, or None when the import failed; the report row). Never raises for a bad
    file: an unexpected exception in the reader becomes an ``error`` row naming the exception."""
    options = ImportOptions(skeleton=take.skeleton, height=height, build=build, fps=30.0)
    try:
        result = import_file(take.path, options, _study_label(take.label, take.skeleton), str(take.path))
    except Exception as exc:  # noqa: BLE001 - a reader bug on one file must not end a batch of thousands
        row = {c: "" for c in REPORT_COLUMNS}
        row.update(source=str(take.path), status=FILE_ERROR,
                   message=f"{take.path}: unexpected {type(exc).__name__} while importing: {exc}")
        return None, {**row, **take_row(take)}
    row = {**result.row, **take_row(take)}
    if result.motion is None or result.row.get("status") != "ok":
        return None, row
    motion = result.motion
    motion.metadata.update(captured=True, dataset=take.dataset, content=take.content, style=take.style,
                           label=take.label, take=take.take, split=take.split, licence=LICENCE, citation=CITATION,
                           source_url=SOURCE_URL)
    clip = CorpusClip(take.name, take.dataset, take.content, take.style, take.label, take.take, take.split,
                      take.skeleton, motion, _as_float(row.get("import_error_cm")),
                      _as_float(row.get("height_m")), str(take.path))
    return clip, row


def _import_star(args) -> tuple[CorpusClip | None, dict]:
    return import_take(*args)


def bad_file_row(path: Path, message: str) -> dict:
    """A report row for a file that does not follow the dataset's layout (never imported)."""
    row = {c: "" for c in report_columns()}
    row.update(source=str(path), status=FILE_ERROR, message=message)
    try:
        t = bn.parse_name(path.name)
        row.update(dataset=t.dataset, content=t.content, style=t.style, take=t.take)
    except bn.LayoutError:
        pass
    return row


def import_takes(takes: list[bn.Take], workers: int = 1, height: float = REFERENCE_HEIGHT_M, build: str = "male",
                 progress: Callable[[Iterable], Iterable] | None = None) -> tuple[list[CorpusClip], list[dict]]:
    """Import ``takes`` (each with a skeleton) with ``workers`` processes -> (clips that imported, one report row
    per take), both in the order of ``takes``. ``progress`` wraps the result iterator (a progress bar)."""
    if workers < 1:
        raise ValueError(f"workers must be at least 1, got {workers}")
    jobs = [(t, height, build) for t in takes]
    wrap = progress or (lambda it: it)
    if workers == 1 or len(jobs) < 2:
        results = list(wrap(map(_import_star, jobs)))
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            results = list(wrap(pool.map(_import_star, jobs, chunksize=4)))
    return [c for c, _ in results if c is not None], [r for _, r in results]


def write_report(path: Path, rows: list[dict], columns: tuple[str, ...] | None = None) -> Path:
    """An import report at ``path``: ``columns`` (default :func:`report_columns`), one row per take."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns or report_columns(), extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    return path


def select_takes(takes: list[bn.Take], contents: Iterable[str] | None = None, limit: int | None = None
                 ) -> list[bn.Take]:
    """Takes with a skeleton (and, given ``contents``, of those contents), the first ``limit`` in path order."""
    wanted = set(contents) if contents else None
    out = [t for t in takes if t.skeleton is not None and (wanted is None or t.content in wanted)]
    return out[:limit] if limit is not None else out


def counts_table(clips: list[CorpusClip]) -> list[tuple[str, str, str, str, int, int, int]]:
    """(dataset, skeleton, content, style, train, val, test) per dataset, content and style, sorted."""
    counts = Counter((c.dataset, c.skeleton, c.content, c.style, c.split) for c in clips)
    keys = sorted({k[:4] for k in counts})
    return [(*k, counts[(*k, "train")], counts[(*k, "val")], counts[(*k, "test")]) for k in keys]


def build_bandai_namco(root: Path, out: Path, contents: list[str] | None = None, limit: int | None = None,
                       workers: int = 1, height: float = REFERENCE_HEIGHT_M, build: str = "male",
                       quiet: bool = False) -> int:
    """Find, import and save: the corpus at ``out``, ``import_report.csv`` beside it. Returns the exit status:
    0 every selected file imported, 1 any file failed or none was found (the good ones are still saved)."""
    extra = tuple(c for c in (contents or ()) if c in bn.FAST_CONTENTS.get("1", ()))
    takes, bad = bn.find_takes(root, extra)
    selected = select_takes(takes, contents, limit)
    from tqdm import tqdm

    def progress(it):
        return tqdm(it, total=len(selected), desc="import", unit="take", file=sys.stderr,
                    disable=quiet or len(selected) < 2 or None)

    clips, rows = import_takes(selected, workers, height, build, progress)
    rows += [bad_file_row(p, msg) for p, msg in bad]
    report = write_report(out.parent / "import_report.csv", rows)
    failed = [r for r in rows if r["status"] != "ok"]
    if clips:
        meta = {"split_rule": bn.SPLIT_RULE, "source_root": str(root), "contents": sorted({c.content for c in clips}),
                "takes_found": len(takes) + len(bad), "takes_selected": len(selected), "takes_failed": len(failed)}
        save_real_corpus(out, clips, meta)
    if not quiet:
        print(f"imported {len(clips)} of {len(selected)} selected takes ({len(takes) + len(bad)} files found, "
              f"{len(bad)} off the layout) -> {out if clips else 'no corpus written'}; report {report}",
              file=sys.stderr)
        for r in failed:
            print(f"  error: {r['message']}", file=sys.stderr)
    if not selected and not bad:
        print(f"error: no takes of the selected contents under {root}", file=sys.stderr)
        return 1
    return 1 if failed else 0
