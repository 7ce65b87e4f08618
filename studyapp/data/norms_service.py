"""The one reader of per-clip norms: a norms rule's ``from`` (a study of this site or a clip_norms.csv under
``settings.DATA_DIR``) -> clip_id -> norm, cached per source version. The norms rule (studyapp.data.norms_rule) and the
admin read norms only through :func:`load_norms`; the model layer (models, catalogue's clip filters, exports) does not
import this module, so saving a section never exports a study or runs the analysis.

A study source is computed from the study's exports with its exclusion rules, as the report does (analysis.norms); a
file is read and checked whole by analysis.norms.read_clip_norms before anything is used, so a bad file changes
nothing. A file must be a .csv inside DATA_DIR once symbolic links and ``..`` are resolved (:func:`norms_file`,
whoever reads it), so no other file of the server is opened.
"""
from __future__ import annotations

import io
import os
import threading
from pathlib import Path

from django.conf import settings

from analysis import exclusion
from analysis.io import StudyData, ValidationError, load_study
from analysis.norms import clip_norms, read_clip_norms

from ..models import Clip, Response, Study
from .export import stream_csv


class NormsSourceError(ValueError):
    """The ``from`` of a norms rule cannot give norms; the message names the field, and the file, line and column
    of each problem of a clip_norms.csv."""


_cache: dict[tuple, dict[str, dict]] = {}
_lock = threading.Lock()


def is_file_source(source: str) -> bool:
    """Whether a ``from`` names a file (a .csv or a path) rather than a study slug."""
    return source.endswith(".csv") or "/" in source or os.sep in source


def norms_file(source: str) -> Path:
    """The file a ``from`` path names: relative to settings.DATA_DIR unless absolute, and, with symbolic links and
    ``..`` resolved, a .csv inside DATA_DIR; NormsSourceError before the file is opened otherwise."""
    root = Path(getattr(settings, "DATA_DIR", ".")).resolve()
    path = (root / source).resolve()           # an absolute source replaces root
    if path.suffix.lower() != ".csv":
        raise NormsSourceError(f"pool.norms.from: {source!r} is not a .csv file (give a study's slug or the path of "
                               "a clip_norms.csv under the data folder, DATA_DIR)")
    if not path.is_relative_to(root):
        raise NormsSourceError(f"pool.norms.from: {source!r} is outside the data folder: a clip_norms.csv must lie "
                               "under DATA_DIR (give it relative to that folder, e.g. norms/clip_norms.csv)")
    return path


def _from_file(source: str) -> tuple[tuple, callable]:
    path = norms_file(source)
    try:
        stat = path.stat()
    except OSError as exc:
        raise NormsSourceError(f"pool.norms.from: cannot read {source!r} ({exc.strerror or exc})") from None

    def load():
        try:
            return read_clip_norms(path, known_clips=Clip.objects.values_list("clip_id", flat=True))
        except ValidationError as exc:
            more = f"; and {exc.total - len(exc.problems)} more" if exc.total > len(exc.problems) else ""
            raise NormsSourceError("pool.norms.from: " + "; ".join(map(str, exc.problems)) + more) from None
    return ("file", str(path), stat.st_mtime_ns, stat.st_size), load


def _from_study(slug: str) -> tuple[tuple, callable]:
    study = Study.objects.filter(slug=slug).first()
    if study is None:
        raise NormsSourceError(f"pool.norms.from: no study {slug!r} on this site (give a study's slug or a "
                               "clip_norms.csv path)")
    answers = Response.objects.filter(section__study=study)
    last = answers.order_by("-id").values_list("id", flat=True).first()

    def load():
        texts = {k: io.StringIO("".join(stream_csv(study, k)))
                 for k in ("responses", "clips", "participants", "viewing")}
        data = load_study(texts["responses"], texts["clips"], texts["participants"], texts["viewing"])
        rules = exclusion.resolve_rules(study.exclusion_rules)
        excl = exclusion.exclusions(data.responses, data.clips, participants=data.participants, rules=rules,
                                    viewing=data.viewing)
        kept = StudyData(exclusion.apply_exclusions(data.responses, excl), data.clips, data.participants)
        norms = clip_norms(kept.responses, kept.clips)
        if norms.empty:
            raise NormsSourceError(f"pool.norms.from: study {slug!r} has no norms yet (no answers to an emotion "
                                   "question of its clips)")
        return norms
    return ("study", study.pk, last, answers.count()), load


def load_norms(source: str) -> dict[str, dict]:
    """clip_id -> its norm (the chosen clip_norms row as a dict) from a norms rule's ``from``; cached per source
    version (file mtime and size, or the study's answers). Raises NormsSourceError."""
    source = (source or "").strip()
    key, load = _from_file(source) if is_file_source(source) else _from_study(source)
    with _lock:
        if key in _cache:
            return _cache[key]
    table = load()
    with_intended = table.assign(_has=table["intended"].notna() & (table["intended"].astype(str) != ""))
    best = (with_intended.sort_values(["clip_id", "_has", "n_ratings"], ascending=[True, False, False])
            .drop_duplicates("clip_id").drop(columns="_has"))
    norms = {row["clip_id"]: row for row in best.to_dict("records")}
    with _lock:
        _cache[key] = norms
        while len(_cache) > 16:
            _cache.pop(next(iter(_cache)))
    return norms


def clear() -> None:
    """Forget every cached norm (tests, and after a study's answers were changed outside the app)."""
    with _lock:
        _cache.clear()
