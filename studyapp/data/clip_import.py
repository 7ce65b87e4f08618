"""Clip imports from the admin: an uploaded manifest and its files (or a zip of them) saved into a job folder, then
``manage.py import_clips`` run on it as a detached process (probing, transcoding and rendering never run in a
request), and the job's state read back for the status page.

    IMPORTS_DIR/<job>/files/...            the uploaded manifest and files (a zip unpacked here)
                      import_report.csv    the command's report (appears when it is done)
                      import.log           its output
                      job.json             the collection and whether it is a dry run
                      import.pid           the process id while it is started

``IMPORTS_DIR`` is ``DATA_DIR/imports`` (never served). Zip members and file names that could leave the job
folder (absolute, ``..``, links) are refused before anything is written; the manifest's own paths are checked
again by the import (generation.imports.manifest).

Bounds, each checked before the bytes are written: every uploaded file at most MAX_UPLOAD_BYTES (the archive too,
and all files of one upload together), a zip of at most MAX_ZIP_MEMBERS members unpacking to at most MAX_ZIP_BYTES,
no member more than MAX_ZIP_RATIO times its compressed size, and the bytes actually unpacked counted against the
declared sizes. A zip that cannot be unpacked (a file and a folder of one name, an over-long name, an unsupported
compression method, a false size or checksum) is an UploadError saying so, never a server error. The ``files``
folder is removed when the job ends, whether it imported, failed or was a dry run (``import_clips --remove-after``;
:func:`import_state` removes one a killed job left); the report, log and job.json stay for the status page.
"""
from __future__ import annotations

import csv
import json
import lzma
import secrets
import shutil
import stat
import sys
import zipfile
import zlib
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path, PurePosixPath

from django.conf import settings
from django.utils.text import slugify

from generation.imports.run import REPORT_NAME

from ..models import Clip
from . import background

LOG_NAME = "import.log"
JOB_NAME = "job.json"
PID_NAME = "import.pid"
MAX_UPLOAD_BYTES = 1024**3
"""Largest uploaded file (the zip, the manifest or one file), and largest upload in all (bytes): the import's own
video limit (generation.imports.video.VideoLimits.max_bytes)."""
MAX_ZIP_BYTES = 2 * 1024**3
"""Largest total unpacked size of an uploaded zip (bytes)."""
MAX_ZIP_MEMBERS = 2000
"""Most members (files and folders) in an uploaded zip."""
MAX_ZIP_RATIO = 200
"""Largest unpacked / compressed size of one zip member above 1 MiB (videos barely compress; text ~10x)."""
FILES_DIR = "files"
COLLECTION_MAX_LENGTH = 40


class UploadError(ValueError):
    """An upload that cannot be imported (no manifest, a name that leaves the folder, a bad zip); says which."""


def imports_dir() -> Path:
    return Path(settings.DATA_DIR) / "imports"


def job_dir(job: str) -> Path:
    """The folder of an import job; UploadError for a name that is not one of ours."""
    if not job or not all(c.isalnum() or c == "-" for c in job):
        raise UploadError(f"no such import {job!r}")
    return imports_dir() / job


def _safe_name(name: str) -> PurePosixPath:
    pure = PurePosixPath(name.replace("\\", "/"))
    if not name or pure.is_absolute() or ".." in pure.parts or (len(name) > 1 and name[1] == ":"):
        raise UploadError(f"{name!r}: a file name must stay inside the upload (no absolute path, no '..')")
    if any(part.startswith(".") for part in pure.parts):
        raise UploadError(f"{name!r}: hidden names are not imported")
    return pure


def _zip_members(zf: zipfile.ZipFile) -> list[zipfile.ZipInfo]:
    """The file members of an open zip, every one checked (names, links, count, sizes) before any is written."""
    infos = zf.infolist()
    if len(infos) > MAX_ZIP_MEMBERS:
        raise UploadError(f"the archive holds {len(infos)} members, more than {MAX_ZIP_MEMBERS}")
    members = [m for m in infos if not m.is_dir()]
    total = 0
    files: set[PurePosixPath] = set()
    for m in members:
        name = _safe_name(m.filename)
        if stat.S_ISLNK(m.external_attr >> 16):
            raise UploadError(f"{m.filename!r}: links are not imported")
        if any(len(part.encode()) > 255 for part in name.parts):
            raise UploadError(f"{m.filename[:80]!r}...: a name in the archive is longer than 255 bytes")
        if m.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED, zipfile.ZIP_BZIP2, zipfile.ZIP_LZMA):
            raise UploadError(f"{m.filename!r}: compression method {m.compress_type} is not supported (store or "
                              "deflate it; encrypted archives are not read)")
        if m.flag_bits & 0x1:
            raise UploadError(f"{m.filename!r}: encrypted members are not read")
        if m.file_size > 2**20 and m.file_size > MAX_ZIP_RATIO * max(m.compress_size, 1):
            raise UploadError(f"{m.filename!r}: unpacks to {m.file_size / 2**20:.0f} MiB from "
                              f"{m.compress_size / 2**10:.0f} KiB: not an archive of stimuli")
        total += m.file_size
        files.add(name)
    if total > MAX_ZIP_BYTES:
        raise UploadError(f"the archive unpacks to {total / 2**30:.1f} GiB, more than "
                          f"{MAX_ZIP_BYTES / 2**30:.0f} GiB")
    clash = next((f for f in files if any(parent in files for parent in f.parents)), None)
    if clash is not None:
        raise UploadError(f"{str(clash)!r}: the archive holds a file and a folder of the same name "
                          f"({str(next(p for p in clash.parents if p in files))!r})")
    return members


def _copy_member(zf: zipfile.ZipFile, m: zipfile.ZipInfo, target: Path, budget: int) -> int:
    """Write one member to ``target``, counting the bytes: never more than its declared size or ``budget``."""
    written = 0
    with zf.open(m) as src, target.open("wb") as dst:
        while chunk := src.read(1 << 20):
            written += len(chunk)
            if written > m.file_size or written > budget:
                raise UploadError(f"{m.filename!r}: unpacks to more than its declared size")
            dst.write(chunk)
    return written


def unpack_zip(archive, dest: Path) -> list[Path]:
    """Unpack an uploaded zip into ``dest``: every member checked first (relative names of at most 255 bytes, no
    links, no file and folder of one name, at most MAX_ZIP_MEMBERS, total at most MAX_ZIP_BYTES, a supported
    compression method), then written, counting the bytes. Returns the files written; UploadError (never another
    exception) for an archive that cannot be unpacked."""
    try:
        zf = zipfile.ZipFile(archive)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, ValueError, EOFError) as exc:
        raise UploadError(f"the archive is not a zip file ({exc})") from None
    with zf:
        members = _zip_members(zf)
        out = []
        budget = MAX_ZIP_BYTES
        for m in members:
            target = dest / Path(*_safe_name(m.filename).parts)
            try:
                target.parent.mkdir(parents=True, exist_ok=True)
                budget -= _copy_member(zf, m, target, budget)
            except UploadError:
                raise
            except (zipfile.BadZipFile, EOFError, zlib.error, lzma.LZMAError, ValueError, NotImplementedError,
                    RuntimeError) as exc:
                raise UploadError(f"{m.filename!r}: cannot be unpacked ({exc})") from None
            except OSError as exc:
                raise UploadError(f"{m.filename!r}: cannot be written ({exc.strerror or exc})") from None
            out.append(target)
    return out


def find_manifest(files: list[Path], root: Path) -> Path:
    """The manifest among unpacked files: the only .csv, else ``manifest.csv`` nearest the top."""
    csvs = sorted((f for f in files if f.suffix.lower() == ".csv" and f.name != REPORT_NAME),
                  key=lambda f: (len(f.relative_to(root).parts), f.name != "manifest.csv", str(f)))
    if not csvs:
        raise UploadError("no manifest: the upload holds no .csv file")
    named = [f for f in csvs if f.name == "manifest.csv"]
    if len(csvs) > 1 and not named:
        raise UploadError(f"several .csv files ({', '.join(f.name for f in csvs)}): name the manifest manifest.csv")
    return named[0] if named else csvs[0]


def save_upload(manifest=None, files=(), archive=None) -> tuple[str, Path]:
    """Save an upload into a new job folder: (job name, manifest path). ``manifest`` and ``files`` are uploaded
    files (their manifest names the files by their names); ``archive`` a zip holding the manifest and its files.
    The job folder is removed again when the upload is refused."""
    if archive is None and manifest is None:
        raise UploadError("upload a manifest (with its files) or a zip of them")
    uploads = [u for u in (archive, manifest, *files) if u is not None]
    for upload in uploads:
        if upload.size > MAX_UPLOAD_BYTES:
            raise UploadError(f"{Path(upload.name).name!r}: {upload.size / 2**20:.0f} MiB, larger than the upload "
                              f"limit of {MAX_UPLOAD_BYTES / 2**20:.0f} MiB per file")
    if sum(u.size for u in uploads) > MAX_UPLOAD_BYTES:
        raise UploadError(f"the upload is {sum(u.size for u in uploads) / 2**20:.0f} MiB, more than "
                          f"{MAX_UPLOAD_BYTES / 2**20:.0f} MiB in all: import it in parts")
    job = f"{datetime.now(UTC):%Y%m%d-%H%M%S}-{secrets.token_hex(4)}"
    root = job_dir(job) / FILES_DIR
    root.mkdir(parents=True)
    try:
        written: list[Path] = []
        if archive is not None:
            written += unpack_zip(archive, root)
        for upload in ([manifest] if manifest is not None else []) + list(files):
            name = _safe_name(Path(upload.name).name)
            target = root / name.name
            try:
                with target.open("wb") as dst:
                    for chunk in upload.chunks():
                        dst.write(chunk)
            except OSError as exc:
                raise UploadError(f"{upload.name[:80]!r}: cannot be saved ({exc.strerror or exc})") from None
            written.append(target)
        found = (root / _safe_name(Path(manifest.name).name).name) if manifest is not None else find_manifest(
            written, root)
    except BaseException:
        shutil.rmtree(job_dir(job), ignore_errors=True)
        raise
    return job, found


UPLOAD_PREFIX = "upload"
PLAN_PREFIX = "import:"
"""The catalogue ``plan`` of an import's clips is its collection: ``import:<name>``."""


def collection_plan(name: str) -> str:
    """The catalogue plan of the collection ``name``: ``import:<name>``; UploadError when it would not fit the
    plan field (cut short, two collections could merge)."""
    plan = PLAN_PREFIX + name
    if len(plan) > Clip._meta.get_field("plan").max_length:
        raise UploadError(f"the collection {plan} is too long: give a shorter collection name")
    return plan


def collection_name(username: str, collection: str) -> str:
    """The ``import_clips --name`` of an admin upload: ``upload/<user>/<collection>``, so one user's collection is
    never another's (a changed file retires only the older clip of the same collection and path); UploadError
    when its catalogue plan would not fit (:func:`collection_plan`)."""
    name = f"{UPLOAD_PREFIX}/{username}/{collection}"
    collection_plan(name)
    return name


def default_collection(upload_name: str) -> str:
    """A collection slug from an uploaded file's name (``Spring Walks.zip`` -> ``spring-walks``)."""
    return slugify(Path(upload_name).stem)[:COLLECTION_MAX_LENGTH] or "upload"


def import_command(manifest: Path, job: str, name: str, keep_audio: bool, dry_run: bool) -> list[str]:
    """The ``manage.py import_clips`` command line of a job."""
    cmd = [sys.executable, str(Path(settings.BASE_DIR) / "manage.py"), "import_clips", str(manifest),
           "--report", str(job_dir(job) / REPORT_NAME), "--name", name,
           "--remove-after", str(job_dir(job) / FILES_DIR)]
    return cmd + (["--keep-audio"] if keep_audio else []) + (["--dry-run"] if dry_run else [])


def launch(cmd: list[str], job: str) -> None:
    """Run ``cmd`` detached (own session, output to the job's log), recording its pid; returns at once."""
    background.launch(cmd, job_dir(job), LOG_NAME, PID_NAME)


def start_import(manifest: Path, job: str, name: str, keep_audio: bool = False, dry_run: bool = False) -> None:
    """Start ``import_clips`` on a saved upload into the collection ``import:<name>`` (:func:`collection_name`);
    what was asked is kept in the job's JOB_NAME for the status page."""
    (job_dir(job) / JOB_NAME).write_text(json.dumps({"collection": collection_plan(name), "dry_run": dry_run}))
    launch(import_command(manifest, job, name, keep_audio, dry_run), job)


@dataclass(frozen=True)
class ImportState:
    """Where an import job stands: ``status`` running | done | failed, its report rows and its log's tail; the
    collection it imports into and whether it is a dry run (only checks, imports nothing)."""

    job: str
    status: str
    rows: list[dict]
    log: str
    collection: str = ""
    dry_run: bool = False


def _running(folder: Path) -> bool:
    return background.is_running(folder, PID_NAME)


def _job_info(folder: Path) -> dict:
    try:
        info = json.loads((folder / JOB_NAME).read_text())
    except (OSError, ValueError):
        return {}
    return info if isinstance(info, dict) else {}


def without_server_paths(text: str, folder: Path) -> str:
    """``text`` with the server's folders (the job's upload folder, MEDIA_ROOT, DATA_DIR, the code) replaced by
    names a researcher can read: the admin shows import messages and logs, not the server's layout."""
    places = [(folder / "files", "<upload>"), (folder, "<import job>"), (Path(settings.MEDIA_ROOT), "<media>"),
              (Path(settings.DATA_DIR), "<data>"), (Path(settings.BASE_DIR), "<app>")]
    for path, name in places:
        for spelling in {str(path), str(path.resolve())}:
            text = text.replace(spelling, name)
    return text


def import_state(job: str) -> ImportState:
    folder = job_dir(job)
    if not folder.is_dir():
        raise UploadError(f"no such import {job!r}")
    log = (folder / LOG_NAME).read_text(errors="replace")[-3000:] if (folder / LOG_NAME).is_file() else ""
    log = without_server_paths(log, folder)
    report = folder / REPORT_NAME
    rows = []
    if report.is_file():
        with report.open(newline="", encoding="utf-8") as f:
            rows = [{k: without_server_paths(v or "", folder) for k, v in row.items()} for row in csv.DictReader(f)]
    info = _job_info(folder)
    running = _running(folder)
    if not running and (folder / PID_NAME).is_file():
        shutil.rmtree(folder / FILES_DIR, ignore_errors=True)      # a job killed before it could remove them
    status = "running" if running else "done" if report.is_file() else "failed"
    return ImportState(job, status, rows, log, str(info.get("collection", "")), bool(info.get("dry_run")))
