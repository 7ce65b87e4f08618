"""The catalogue: import rendered clips (upsert by clip_id) and select clip pools by catalogue fields.

`upsert_clips(records)` is the interface used by the renderer's `generate_clips` command and by `import_clips`. A
record carries the DESIGN.md clips.csv fields (``licence`` and ``citation`` too, else read from its metadata) plus
`video` (MP4 path relative to MEDIA_ROOT), `webm` (or ""), `poster`, `plan`, `loop` (bool) and `metadata` (dict);
optional `source_clip_id` (the clip_id of the source clip a generated clip was made from; also read from `pair` or
metadata["source_clip_id"] / metadata["pair"]) and `sections` (the plan's section-type hints, a list or
comma-separated; also read from metadata["sections"]); optional `qa` (the quality record, a dict: generation.quality)
and `qa_flag` (failed checks joined by ';', also read from qa["flag"]); optional `title` (else metadata["title"],
else derived by protocol.titles from the records written together: generator, condition, variant).
"""
from __future__ import annotations

import math

from django.db import transaction
from django.db.models import QuerySet

from protocol.pools import NORMS_RULE
from protocol.titles import clip_titles
from protocol.vocabulary import (
    BODY_MAX_LENGTH,
    CLIP_FLOAT_COLUMNS,
    CLIP_MODALITIES,
    CLIP_THEMES,
    GESTURE_EMOTIONS,
    ORIGINS,
    QA_CHECKS,
    SECTION_MODALITY,
)

from ..models import Clip
from .norms_rule import NormsSourceError, passing_ids
from .pool_filters import CatalogueError, filtered_clips, pool_calls

TEXT_FIELDS = ("emotion_label", "theme", "webm", "poster", "plan", "source_clip_id")


def _blank(value) -> bool:
    return value is None or (isinstance(value, str) and value.strip() == "") or (
        isinstance(value, float) and math.isnan(value))


def _float(rec: dict, name: str, where: str):
    value = rec.get(name)
    if _blank(value):
        return None
    try:
        return float(value)
    except (TypeError, ValueError) as exc:
        raise CatalogueError(f"{where}: field {name!r} must be a number or blank, got {value!r}") from exc


def clean_record(rec: dict, index: int = 0) -> dict:
    """Validate one clip record -> keyword arguments for Clip."""
    clip_id = str(rec.get("clip_id") or "").strip()
    where = f"clip record {index} ({clip_id or 'no clip_id'})"
    if not clip_id:
        raise CatalogueError(f"{where}: field 'clip_id' is required")
    modality = str(rec.get("modality") or "").strip()
    if modality not in CLIP_MODALITIES:
        raise CatalogueError(f"{where}: field 'modality' must be one of {', '.join(CLIP_MODALITIES)}, "
                             f"got {modality!r}")
    origin = str(rec.get("origin") or "").strip()
    if origin not in ORIGINS:
        raise CatalogueError(f"{where}: field 'origin' must be one of {', '.join(ORIGINS)}, got {origin!r}")
    video = str(rec.get("video") or "").strip()
    if not video:
        raise CatalogueError(f"{where}: field 'video' (path relative to MEDIA_ROOT) is required")
    if video.startswith("/") or ".." in video.split("/"):
        raise CatalogueError(f"{where}: field 'video' must be relative to MEDIA_ROOT, got {video!r}")
    metadata = rec.get("metadata") or {}
    if not isinstance(metadata, dict):
        raise CatalogueError(f"{where}: field 'metadata' must be a dict")
    out = {"modality": modality, "origin": origin, "video": video, "metadata": metadata,
           "loop": bool(rec.get("loop", False))}
    for name in CLIP_FLOAT_COLUMNS:
        out[name] = _float(rec, name, where)
    n = rec.get("n_features")
    if _blank(n):
        out["n_features"] = None
    else:
        try:
            out["n_features"] = int(float(n))
        except (TypeError, ValueError) as exc:
            raise CatalogueError(f"{where}: field 'n_features' must be an integer or blank, got {n!r}") from exc
    for name in TEXT_FIELDS:
        value = rec.get(name)
        out[name] = "" if _blank(value) else str(value).strip()
    if out["theme"] and out["theme"] not in CLIP_THEMES:
        raise CatalogueError(f"{where}: field 'theme' must be blank or one of {', '.join(CLIP_THEMES)}, "
                             f"got {out['theme']!r}")
    if out["theme"] and out["weight"] is None:
        raise CatalogueError(f"{where}: field 'weight' is required for a clip with a theme (0 for the neutral walk)")
    if modality == "gesture" and out["emotion_label"] and out["emotion_label"] not in GESTURE_EMOTIONS:
        raise CatalogueError(f"{where}: field 'emotion_label' of a gesture must be one of "
                             f"{', '.join(GESTURE_EMOTIONS)}, got {out['emotion_label']!r}")
    if not out["source_clip_id"]:
        for value in (rec.get("pair"), metadata.get("source_clip_id"), metadata.get("pair")):
            if not _blank(value):
                out["source_clip_id"] = str(value).strip()
                break
    sections = rec.get("sections", metadata.get("sections")) or []
    if isinstance(sections, str):
        sections = [s for s in sections.split(",")]
    out["sections"] = ",".join(str(s).strip() for s in sections if str(s).strip())
    for name in ("licence", "citation"):
        value = rec.get(name, metadata.get(name))
        out[name] = "" if _blank(value) else str(value).strip()
    out["body"] = _body(rec, where)
    out["qa"], out["qa_flag"] = _qa(rec, where)
    return out


def _body(rec: dict, where: str) -> str:
    """The body preset a clip record shows: ``body`` as the renderer records it (a dict with ``preset``) or as
    clips.csv writes it (the preset's name); "" for the other figures."""
    body = rec.get("body")
    name = body.get("preset") if isinstance(body, dict) else body
    name = "" if _blank(name) else str(name).strip()
    if len(name) > BODY_MAX_LENGTH:
        raise CatalogueError(f"{where}: field 'body' is longer than {BODY_MAX_LENGTH} characters")
    return name


def _qa(rec: dict, where: str) -> tuple[dict, str]:
    """(quality record, flag) of a clip record: ``qa`` (a dict) and ``qa_flag`` (or qa["flag"]); failed checks
    must be names of QA_CHECKS."""
    qa = rec.get("qa") or {}
    if not isinstance(qa, dict):
        raise CatalogueError(f"{where}: field 'qa' must be a dict (the quality record), got {type(qa).__name__}")
    flag = rec.get("qa_flag")
    if _blank(flag):
        flag = qa.get("flag", "")
    flag = "" if _blank(flag) else str(flag).strip()
    unknown = [f for f in flag.split(";") if f and f not in QA_CHECKS]
    if unknown:
        raise CatalogueError(f"{where}: field 'qa_flag': {unknown[0]!r} is not a quality check "
                             f"({', '.join(QA_CHECKS)})")
    return {k: v for k, v in qa.items() if k != "flag"}, flag


def upsert_clips(records: list[dict]) -> int:
    """Insert or update clips by clip_id (idempotent). Returns the number of records written.

    All records are validated first; nothing is written if one is bad (CatalogueError names it).
    """
    cleaned = [(str(rec.get("clip_id")).strip(), clean_record(rec, i)) for i, rec in enumerate(records)]
    titles = clip_titles({**fields, "clip_id": clip_id, "title": rec.get("title")}
                         for (clip_id, fields), rec in zip(cleaned, records, strict=True))
    for clip_id, fields in cleaned:
        fields["title"] = titles[clip_id]
    with transaction.atomic():
        for clip_id, fields in cleaned:
            Clip.objects.update_or_create(clip_id=clip_id, defaults={**fields, "retired": False})
    return len(cleaned)


def retire_superseded(plan: str, current_clip_ids: set[str], entry_ids: set[str] | None = None) -> int:
    """Mark clips of ``plan`` that a newer render replaced as retired; returns how many.

    A clip is superseded when it belongs to ``plan``, is not among ``current_clip_ids`` and, if ``entry_ids`` is
    given, was made for one of those plan entries (``metadata["entry_id"]``). With ``entry_ids=None`` every other
    clip of the plan is retired (a complete run: entries removed from the plan go too). Retired clips keep their
    rows and files, so earlier answers stay valid; they are left out of new assignments.
    """
    stale = Clip.objects.filter(plan=plan, retired=False).exclude(clip_id__in=current_clip_ids)
    if entry_ids is not None:
        stale = [c.pk for c in stale if str((c.metadata or {}).get("entry_id")) in entry_ids]
        return Clip.objects.filter(pk__in=stale).update(retired=True)
    return stale.update(retired=True)


def retire_replaced(plan: str, entry_id: str, clip_id: str) -> list[str]:
    """Retire the clips of ``plan`` made for the same entry (``metadata["entry_id"]``: an imported file's path in
    its manifest) that ``clip_id`` replaces, e.g. after the file changed; returns their clip ids. Retired clips keep
    their rows and files (earlier answers stay valid) and are left out of new assignments."""
    stale = Clip.objects.filter(plan=plan, retired=False, metadata__entry_id=entry_id).exclude(clip_id=clip_id)
    ids = sorted(stale.values_list("clip_id", flat=True))
    Clip.objects.filter(clip_id__in=ids).update(retired=True)
    return ids


def section_queryset(section_type: str | None, pool: dict | None, include_flagged: bool | None = None) -> QuerySet:
    """The clips a section of ``section_type`` draws from its pool: :func:`pool_queryset` limited to the modality
    the section type shows (``protocol.vocabulary.SECTION_MODALITY``: a gait section never shows a gesture or an
    imported ``other`` video, whatever its filters say; naturalness sections take any modality)."""
    qs = pool_queryset(pool, include_flagged)
    wanted = SECTION_MODALITY.get(section_type or "")
    return qs.filter(modality=wanted) if wanted else qs


def pool_queryset(pool: dict | None, include_flagged: bool | None = None) -> QuerySet:
    """Clips (not retired) matching a section's pool filter (see protocol.pools for the filter language).

    Clips that failed a quality check (``qa_flag`` not empty) are left out unless the pool says
    ``"include_flagged": true`` or ``include_flagged`` is given (True for a sub-pool, which only narrows its
    section's pool), or the pool's switches keep the checks they failed (``protocol.pools.kept_checks``:
    ``keep_advisory`` the advisory ones, ``observer_advisory`` the observer's). A ``norms`` rule
    (studyapp.data.norms_rule) keeps only clips whose norms pass, and keeps the ``observer`` check's flag of clips that
    have norms. Raises
    CatalogueError naming the filter (or the norms source's file, line and column) when the pool is not valid;
    sub-pools are left to the assignment.
    """
    pool_calls(pool)                       # a bad filter is named before any norms source is read
    passing: set[str] | None = None
    normed: set[str] | None = None
    if isinstance((pool or {}).get(NORMS_RULE), dict):
        try:
            passing, normed = passing_ids(pool)
        except NormsSourceError as exc:
            raise CatalogueError(str(exc)) from exc
    qs = filtered_clips(pool, include_flagged, normed)
    return qs if passing is None else qs.filter(clip_id__in=passing)


def clip_label(record: dict) -> str:
    """Caption of a clip on a contact sheet: plan entry id, origin, the generator actually used and the failed
    quality checks, if any."""
    meta = record.get("metadata") or {}
    gen = meta.get("generator", "")
    if meta.get("fallback_for"):
        gen = f"{gen} (fallback for {meta['fallback_for']})"
    flag = record.get("qa_flag") or ""
    parts = [str(meta.get("entry_id", record["clip_id"])), record["origin"], gen,
             f"QA: {flag.replace(';', ', ')}" if flag else ""]
    return " | ".join(p for p in parts if p)
