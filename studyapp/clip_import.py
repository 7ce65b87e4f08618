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
"""
from __future__ import annotations

import csv
import json
import secrets
import shutil
import stat
import sys
import zipfile
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path, PurePosixPath

from django.conf import settings
from django.utils.text import slugify

from generation.imports.run import REPORT_NAME

from . import background
from .models import Clip

LOG_NAME = "import.log"
JOB_NAME = "job.json"
PID_NAME = "import.pid"
MAX_ZIP_BYTES = 4 * 1024**3
"""Largest total unpacked size of an uploaded zip."""
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


def unpack_zip(archive, dest: Path) -> list[Path]:
    """Unpack an uploaded zip into ``dest``: every member checked first (relative names, no links, the total size
    at most MAX_ZIP_BYTES), then written. Returns the files written."""
    try:
        zf = zipfile.ZipFile(archive)
    except zipfile.BadZipFile as exc:
        raise UploadError(f"the archive is not a zip file ({exc})") from None
    with zf:
        members = [m for m in zf.infolist() if not m.is_dir()]
        total = 0
        for m in members:
            _safe_name(m.filename)
            if stat.S_ISLNK(m.external_attr >> 16):
                raise UploadError(f"{m.filename!r}: links are not imported")
            total += m.file_size
        if total > MAX_ZIP_BYTES:
            raise UploadError(f"the archive unpacks to {total / 2**30:.1f} GiB, more than "
                              f"{MAX_ZIP_BYTES / 2**30:.0f} GiB")
        out = []
        for m in members:
            target = dest / Path(*_safe_name(m.filename).parts)
            target.parent.mkdir(parents=True, exist_ok=True)
            with zf.open(m) as src, target.open("wb") as dst:
                shutil.copyfileobj(src, dst, 1 << 20)
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
    job = f"{datetime.now(UTC):%Y%m%d-%H%M%S}-{secrets.token_hex(4)}"
    root = job_dir(job) / "files"
    root.mkdir(parents=True)
    try:
        written: list[Path] = []
        if archive is not None:
            written += unpack_zip(archive, root)
        for upload in ([manifest] if manifest is not None else []) + list(files):
            name = _safe_name(Path(upload.name).name)
            target = root / name.name
            with target.open("wb") as dst:
                for chunk in upload.chunks():
                    dst.write(chunk)
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
           "--report", str(job_dir(job) / REPORT_NAME), "--name", name]
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
    status = "running" if _running(folder) else "done" if report.is_file() else "failed"
    return ImportState(job, status, rows, log, str(info.get("collection", "")), bool(info.get("dry_run")))
