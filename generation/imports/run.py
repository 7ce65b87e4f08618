"""Import every row of a manifest: each row staged, then committed all-or-nothing; the import report.

Per row: the file's SHA-256 gives the clip id (:func:`clip_id_for`: a 16-hex content hash of the file digest and
what the delivered files depend on: for videos whether audio is kept, for motion files the skeleton and render
settings). A clip whose files and record are already in MEDIA_ROOT is not made again (re-importing a manifest is
idempotent: only its catalogue row is refreshed from the manifest's labels). Otherwise the files are made in a
hidden staging folder inside MEDIA_ROOT, then moved into place in one step with the catalogue row:

    MEDIA_ROOT/clips/<clip_id>.mp4, .png (+ .webm)     the delivered clip (served by opaque keys only)
    MEDIA_ROOT/motions/<clip_id>.bvh                    the motion of an imported motion file
    MEDIA_ROOT/clip_records/<clip_id>.json              the record (probe, import report, quality), never served
    MEDIA_ROOT/clips.csv                                the catalogue row (origin ``imported``)

The caller's ``catalogue`` step (the Clip row, in a database transaction) wraps the moves; when anything fails the
files this row added are removed and clips.csv is restored, so a failed row leaves no media, no row and no poster.
The report (:data:`REPORT_COLUMNS`) has one line per manifest row, ``status`` ok or error with the cause.
"""
from __future__ import annotations

import contextlib
import csv
import hashlib
import json
import os
import shutil
import time
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from generation.core.digest import file_sha256
from generation.plans.catalogue import write_clips_csv
from generation.render.bodies import load_body
from generation.render.settings import RenderSettings
from protocol.vocabulary import CLIP_COLUMNS, IMPORTED

from .manifest import BadRow, ManifestError, ManifestRow, read_manifest
from .motion import MotionImportError, load_motion, render_settings, stage_motion
from .video import VideoImportError, VideoLimits, check_video, needs_transcode, stage_video

IMPORT_VERSION = 1
"""Part of every imported clip id: raise it when the delivered files of the same input change."""

REPORT_COLUMNS = ("row", "path", "status", "clip_id", "message")
REPORT_NAME = "import_report.csv"
STAGING_DIR = ".import-staging"

#: A catalogue step: called with the clip record, a context manager around moving its files into place; it may
#: append notes for the report (e.g. "retired <old clip id>"). Raising inside undoes the row.
CatalogueStep = Callable[[dict, list], contextlib.AbstractContextManager]
#: A check of a row's record against the catalogue before anything is made (a dry run runs it too): raises
#: RowRefused when the catalogue cannot take the row (e.g. its clip belongs to another collection).
RowCheck = Callable[[dict], None]


class RowRefused(Exception):
    """A catalogue step's refusal of a row (e.g. its clip belongs to another collection); the message says why."""


@dataclass(frozen=True)
class ImportSettings:
    """How rows are imported.

    limits: the longest (s) and largest (bytes) file accepted; keep_audio: the default of the manifest's
    ``keep_audio`` column; webm: also deliver VP9 WebM; render: the renderer's settings for motion files (the body
    comes from the manifest's ``body``); observer: read motion clips with the modality's observer; threads: ffmpeg
    threads per encode (0: ffmpeg decides); plan: the catalogue ``plan`` of this manifest's clips, their collection
    (a changed file retires the older clip of the same plan and path, never one of another plan)."""

    limits: VideoLimits = field(default_factory=VideoLimits)
    keep_audio: bool = False
    webm: bool = False
    render: RenderSettings = field(default_factory=RenderSettings)
    observer: bool = True
    threads: int = 0
    plan: str = "import"


@dataclass
class RowOutcome:
    """What happened to one manifest row: status "ok" or "error", the clip id (blank when none), the message,
    and for ok rows the catalogue record."""

    row: int
    path: str
    status: str
    clip_id: str = ""
    message: str = ""
    record: dict | None = None
    seconds: float = 0.0

    def report_row(self) -> dict:
        return {"row": self.row, "path": self.path, "status": self.status, "clip_id": self.clip_id,
                "message": self.message}


def _keep_audio(row: ManifestRow, settings: ImportSettings) -> bool:
    return settings.keep_audio if row.keep_audio is None else row.keep_audio


def clip_id_for(row: ManifestRow, sha256: str, settings: ImportSettings) -> str:
    """16 hex digits of the SHA-256 of the file digest and the settings the delivered files depend on."""
    content: dict = {"kind": f"{IMPORTED}-{row.kind}", "version": IMPORT_VERSION, "file_sha256": sha256}
    if row.kind == "video":
        content["keep_audio"] = _keep_audio(row, settings)
    else:
        content["skeleton"] = row.modality
        content["render"] = render_settings(row.body, settings.render).content_dict()
    return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()[:16]


def _write_json_atomic(obj: dict, path: Path) -> None:
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    tmp.write_text(json.dumps(obj, indent=1, sort_keys=True, default=str), encoding="utf-8")
    os.replace(tmp, path)


def _read_json(path: Path):
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def base_record(row: ManifestRow, clip_id: str, sha256: str, settings: ImportSettings) -> dict:
    """The catalogue record of a row without the media facts: labels, provenance, file paths."""
    rec = {c: None for c in CLIP_COLUMNS}
    rec.update(row.labels)
    rec.update(clip_id=clip_id, modality=row.modality, origin=IMPORTED, video=f"clips/{clip_id}.mp4",
               webm=f"clips/{clip_id}.webm" if settings.webm else "", poster=f"clips/{clip_id}.png",
               plan=settings.plan, loop=False, **{k: row.text[k] for k in ("title", "licence", "citation")})
    key = PurePosixPath(row.path.strip().replace("\\", "/")).as_posix()      # "./a.mp4" and "a.mp4" are one entry
    rec["metadata"] = {"entry_id": key, "plan": settings.plan, "imported_file": row.path, "kind": row.kind,
                       "file_sha256": sha256, "file_bytes": row.file.stat().st_size, **row.text,
                       "import_version": IMPORT_VERSION}
    return rec


def _done(media_root: Path, clip_id: str, webm: bool, kind: str) -> dict | None:
    """The stored record of a clip whose files are all in place, else None."""
    rec_path = media_root / "clip_records" / f"{clip_id}.json"
    needed = [media_root / "clips" / f"{clip_id}.{ext}" for ext in ("mp4", "png", *(("webm",) if webm else ()))]
    if kind == "motion":
        needed.append(media_root / "motions" / f"{clip_id}.bvh")
    if not rec_path.is_file() or not all(p.is_file() and p.stat().st_size > 0 for p in needed):
        return None
    try:
        rec = json.loads(rec_path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return rec if rec.get("clip_id") == clip_id and rec.get("origin") == IMPORTED else None


MEDIA_KEYS = ("probe", "delivered", "action", "audio", "n_frames", "fps", "import", "camera", "motion", "render")


def _with_media(rec: dict, stored: dict) -> dict:
    """``rec`` (from the manifest) with the media facts of a stored record (duration, probe, quality...)."""
    rec["duration_s"] = stored.get("duration_s")
    rec["metadata"].update({k: v for k, v in (stored.get("metadata") or {}).items() if k in MEDIA_KEYS})
    for key in ("qa", "qa_flag", "body"):
        if key in stored:
            rec[key] = stored[key]
    return rec


def _stage(row: ManifestRow, rec: dict, stage: Path, settings: ImportSettings) -> dict[str, Path]:
    """Make the row's files in ``stage``; returns {final path relative to MEDIA_ROOT: staged file} and fills the
    media facts into ``rec``."""
    clip_id = rec["clip_id"]
    meta = rec["metadata"]
    if row.kind == "video":
        v = stage_video(row.file, stage, clip_id, settings.limits, _keep_audio(row, settings), settings.webm,
                        settings.threads)
        rec["duration_s"] = v.duration_s
        meta.update(probe=v.probe.as_dict(), delivered=v.delivered.as_dict(), action=v.action, audio=v.audio,
                    n_frames=v.n_frames, fps=v.delivered.fps)
        files = {f"clips/{clip_id}.mp4": v.mp4}
        if v.webm is not None:
            files[f"clips/{clip_id}.webm"] = v.webm
        files[f"clips/{clip_id}.png"] = v.poster
        return files
    rs = render_settings(row.body, settings.render, settings.webm)
    m = stage_motion(row.file, stage, clip_id, row.modality, rs, settings.limits.max_duration_s, row.labels,
                     settings.observer)
    rec["duration_s"] = m.duration_s
    rec["qa"], rec["qa_flag"] = m.qa, m.qa_flag
    if (m.camera or {}).get("body_preset"):  # the human body shown, with its licence and citation
        rec["body"] = load_body(m.camera["body_preset"]).record()
    meta.update(action="render", n_frames=m.n_frames, fps=rs.fps, camera=m.camera, render=rs.content_dict(),
                motion=m.motion_metadata, **{"import": m.import_row})
    files = {f"clips/{clip_id}.mp4": m.mp4}
    if m.webm is not None:
        files[f"clips/{clip_id}.webm"] = m.webm
    files[f"motions/{clip_id}.bvh"] = m.bvh
    files[f"clips/{clip_id}.png"] = m.poster
    return files


def commit_row(rec: dict, files: dict[str, Path], media_root: Path, catalogue: CatalogueStep | None,
               notes: list) -> None:
    """Move staged ``files`` into MEDIA_ROOT, write the record and the clips.csv row, all inside the catalogue
    step; on any failure remove what this row added and restore clips.csv, then re-raise."""
    csv_path = media_root / "clips.csv"
    before = csv_path.read_bytes() if csv_path.is_file() else None
    added: list[Path] = []
    csv_written = False
    step = catalogue(rec, notes) if catalogue is not None else contextlib.nullcontext()
    try:
        with step:
            for rel, staged in files.items():
                final = media_root / rel
                final.parent.mkdir(parents=True, exist_ok=True)
                existed = final.exists()
                os.replace(staged, final)
                if not existed:
                    added.append(final)
            rec_path = media_root / "clip_records" / f"{rec['clip_id']}.json"
            rec_path.parent.mkdir(parents=True, exist_ok=True)
            existed = rec_path.exists()
            stored = {**rec, "record_version": IMPORT_VERSION}
            if not existed or _read_json(rec_path) != json.loads(json.dumps(stored, default=str)):
                _write_json_atomic(stored, rec_path)
            if not existed:
                added.append(rec_path)
            csv_written = True
            write_clips_csv([rec], csv_path)
    except BaseException:
        for path in added:
            path.unlink(missing_ok=True)
        if csv_written:
            if before is None:
                csv_path.unlink(missing_ok=True)
            else:
                tmp = csv_path.with_name(f".{csv_path.name}.restore{os.getpid()}")
                tmp.write_bytes(before)
                os.replace(tmp, csv_path)
        raise


def _summary(rec: dict) -> str:
    """The report message of a newly imported clip: what was done, its duration, audio and quality flag."""
    meta = rec["metadata"]
    text = meta["action"] + (f" {meta['probe']['video_codec']}" if "probe" in meta else "")
    text += f", {rec['duration_s']:.2f} s"
    source_s = (meta.get("motion") or {}).get("source_duration_s")
    if source_s and source_s > rec["duration_s"] + 0.05:
        text += f" (the first {rec['duration_s']:.2f} s of {source_s:.2f} s: the render length)"
    if "audio" in meta:
        text += f", audio {meta['audio']}"
    return text + (f", quality flag {rec['qa_flag']}" if rec.get("qa_flag") else "")


def _render_span(source_s: float, render_s: float) -> str:
    """What of a take of ``source_s`` seconds a render of at most ``render_s`` seconds shows."""
    if source_s > render_s + 0.05:
        return f"the first {render_s:.2f} s of {source_s:.2f} s of motion (cut to the render length, {render_s:g} s)"
    return f"{source_s:.2f} s of motion"


ROW_ERRORS = (ManifestError, VideoImportError, MotionImportError, RowRefused, OSError)


def import_row(row: ManifestRow, media_root: Path, settings: ImportSettings, catalogue: CatalogueStep | None,
               dry_run: bool = False, sha: str | None = None, check: RowCheck | None = None) -> RowOutcome:
    """Import one checked manifest row (see the module docstring; ``sha``: the file's SHA-256 if known; ``check``
    runs on its record first, in a dry run too); never raises for a bad file: an error outcome names the cause, a
    failing catalogue step's exception too."""
    t0 = time.perf_counter()
    out = RowOutcome(row.row, row.path, "error")
    try:
        sha = sha or file_sha256(row.file)
        out.clip_id = clip_id_for(row, sha, settings)
        rec = base_record(row, out.clip_id, sha, settings)
        if check is not None:
            check(rec)
        notes: list[str] = []
        stored = None if dry_run else _done(media_root, out.clip_id, settings.webm, row.kind)
        if dry_run:
            if row.kind == "video":
                probe = check_video(row.file, settings.limits)
                notes.append(f"would {'transcode' if needs_transcode(probe) else 'remux'} {probe.video_codec} "
                             f"{probe.width}x{probe.height}, {probe.duration_s:.2f} s (dry run: nothing written)")
            else:
                motion, _ = load_motion(row.file, row.modality, settings.limits.max_duration_s)
                notes.append(f"would render {_render_span(motion.duration, settings.render.duration_s)} "
                             "(dry run: nothing written)")
        elif stored is not None:
            _with_media(rec, stored)
            commit_row(rec, {}, media_root, catalogue, notes)
            notes.insert(0, "already imported (same file): catalogue row refreshed")
        else:
            stage = media_root / STAGING_DIR / f"{os.getpid()}-{uuid.uuid4().hex[:8]}"
            stage.mkdir(parents=True)
            try:
                files = _stage(row, rec, stage, settings)
                commit_row(rec, files, media_root, catalogue, notes)
            finally:
                shutil.rmtree(stage, ignore_errors=True)
                with contextlib.suppress(OSError):
                    stage.parent.rmdir()
            notes.insert(0, _summary(rec))
    except ROW_ERRORS as exc:
        message = str(exc)
        out.message = message if isinstance(exc, ManifestError) else f"{row.path}: {message}"
        out.clip_id = ""
        out.seconds = time.perf_counter() - t0
        return out
    except Exception as exc:  # noqa: BLE001 - the catalogue step's own error (database, validation) fails the row
        out.message = f"{row.path}: {type(exc).__name__}: {exc}"
        out.clip_id = ""
        out.seconds = time.perf_counter() - t0
        return out
    out.status, out.message, out.record = "ok", "; ".join(notes), rec
    out.seconds = time.perf_counter() - t0
    return out


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale_staging(media_root: Path) -> list[Path]:
    """Delete staging folders left by an import that was killed (``<pid>-<random>`` of a process that is gone)."""
    removed = []
    for folder in sorted((media_root / STAGING_DIR).glob("*-*")):
        pid = folder.name.split("-", 1)[0]
        if folder.is_dir() and pid.isdigit() and not _alive(int(pid)):
            shutil.rmtree(folder, ignore_errors=True)
            removed.append(folder)
    return removed


def import_manifest(manifest: str | Path, media_root: str | Path, settings: ImportSettings | None = None,
                    catalogue: CatalogueStep | None = None, dry_run: bool = False,
                    on_row: Callable[[RowOutcome], None] | None = None,
                    check: RowCheck | None = None) -> list[RowOutcome]:
    """Import every row of ``manifest`` into ``media_root``; one outcome per row, in manifest order.

    ``dry_run`` checks every row (paths, labels, probe and limits of videos, the importer's checks of motion
    files, ``check`` against the catalogue) and writes nothing. Two rows that give the same clip (the same file
    with the same settings) are one clip: the second is an error naming the first. ManifestError for a manifest
    that cannot be read at all."""
    settings = settings or ImportSettings()
    media_root = Path(media_root)
    if not dry_run:
        remove_stale_staging(media_root)
    outcomes: list[RowOutcome] = []
    seen: dict[str, int] = {}
    for item in read_manifest(manifest):
        if isinstance(item, BadRow):
            out = RowOutcome(item.row, item.path, "error", "", str(item.error))
        else:
            try:
                sha = file_sha256(item.file)
            except OSError as exc:
                sha, out = None, RowOutcome(item.row, item.path, "error", "", f"{item.path}: cannot read ({exc})")
            clip_id = clip_id_for(item, sha, settings) if sha else ""
            if sha and clip_id in seen:
                out = RowOutcome(item.row, item.path, "error", "", f"{item.path}: the same clip as row "
                                 f"{seen[clip_id]} (same file and settings); give each file once")
            elif sha:
                out = import_row(item, media_root, settings, catalogue, dry_run, sha, check)
                if out.status == "ok":
                    seen[clip_id] = item.row
        outcomes.append(out)
        if on_row is not None:
            on_row(out)
    return outcomes


def write_report(outcomes: list[RowOutcome], path: str | Path) -> Path:
    """Write the import report (:data:`REPORT_COLUMNS`) to ``path`` atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    with tmp.open("w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=REPORT_COLUMNS)
        writer.writeheader()
        for out in outcomes:
            writer.writerow(out.report_row())
    os.replace(tmp, path)
    return path
