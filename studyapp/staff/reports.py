"""Analysis-report zips built outside the web request, kept until the study's data change.

The staff "Build report" button calls `start_build`, which returns at once: it takes the version's lock and starts
`manage.py build_report STUDY_ID --data-version V --lock-fd N` as a detached process (own session, stdin closed, output
to build.log) that inherits the lock. The command exports the CSVs, runs analysis.report.write_report and zips the
folder. Files, per study and data version:

    REPORTS_DIR/<study id>/<data version>/report.zip   the finished report (appears atomically: written as .part)
                                          build.lock   flock()ed by the running build; released when it exits
                                          error.txt    why the last build failed
                                          build.log    the build's stdout/stderr
                                          purged       a participant was removed during the build: no zip

The data version (`data_version`) is a digest of the study's participant and response counts, largest ids and
latest times, sections, exclusion rules and the catalogue's latest change: equal digests mean equal exports, so a
finished zip is reused until the data change. A new build's success removes the study's older versions. The
lock is an flock (fcntl.flock) on build.lock: never two builds of one version at once, and a killed build frees it
automatically (one host; REPORTS_DIR must not be on NFS). The export is read after the digest, so a zip may
include answers that arrived during the build; the next status check then sees a newer version and offers a new
build.
"""
from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import zipfile
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from django.conf import settings
from django.db.models import Count, Max, Q

from ..data.export import run_report
from ..data.privacy import PURGED_NAME
from ..models import Clip, Participant, Response, Study

REPORT_NAME = "report.zip"
LOCK_NAME = "build.lock"
ERROR_NAME = "error.txt"
LOG_NAME = "build.log"
STATUSES = ("none", "running", "ready", "failed")
MANAGE_PY = Path(settings.BASE_DIR) / "manage.py"


class BuildRunning(RuntimeError):
    """Another process holds the version's lock."""


@dataclass(frozen=True)
class ReportState:
    """Where a study's report stands for its current data version. status: one of STATUSES."""

    study_id: int
    version: str
    status: str
    zip_path: Path | None = None
    error: str = ""
    started_at: float | None = None         # epoch seconds, running builds only
    finished_at: float | None = None        # epoch seconds of the zip, ready only

    @property
    def started(self) -> datetime | None:
        """When the running build started, as an aware UTC datetime (None when unknown or not running)."""
        return datetime.fromtimestamp(self.started_at, UTC) if self.started_at else None

    @property
    def finished(self) -> datetime | None:
        """When the zip was written, as an aware UTC datetime (None unless ready)."""
        return datetime.fromtimestamp(self.finished_at, UTC) if self.finished_at else None


def data_version(study: Study) -> str:
    """16 hex digits that change whenever the study's exported data can change (3 aggregate queries)."""
    people = Participant.objects.filter(study=study).aggregate(
        n=Count("id"), max_id=Max("id"), active=Max("last_active_at"), consented=Max("consented_at"),
        completed=Max("completed_at"), n_completed=Count("id", filter=Q(status=Participant.Status.COMPLETED)),
        n_withdrawn=Count("id", filter=Q(status=Participant.Status.WITHDRAWN)),
        n_demographics=Count("id", filter=Q(demographics_done=True)),
        n_feedback=Count("id", filter=Q(feedback_done=True)))
    answers = Response.objects.filter(section__study=study).aggregate(
        n=Count("id"), max_id=Max("id"), last=Max("created_at"))
    clips = Clip.objects.aggregate(n=Count("id"), changed=Max("updated_at"))
    sections = list(study.sections.order_by("id").values_list("id", "order", "section_type", "options"))
    record = [study.pk, study.exclusion_rules, sections, people, answers, clips, study.report_includes_pilot]
    return hashlib.sha256(json.dumps(record, sort_keys=True, default=str).encode()).hexdigest()[:16]


def version_dir(study_id: int, version: str) -> Path:
    """The folder of a study's report for one data version, REPORTS_DIR/<study id>/<version>; ValueError for a version
    that is not hex digits, so no path can leave REPORTS_DIR."""
    if not version or not all(c in "0123456789abcdef" for c in version):
        raise ValueError(f"not a data version: {version!r}")
    return Path(settings.REPORTS_DIR) / str(int(study_id)) / version


def _lock_is_held(folder: Path) -> bool:
    path = folder / LOCK_NAME
    if not path.exists():
        return False
    with open(path, "a+") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return True
        fcntl.flock(fh, fcntl.LOCK_UN)
        return False


def acquire_lock(folder: Path, attempts: int = 3) -> int:
    """An open fd of folder/build.lock holding an exclusive flock. Raises BuildRunning when another process holds
    it (a status check's momentary probe is waited out: `attempts` tries 50 ms apart)."""
    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder / LOCK_NAME, os.O_RDWR | os.O_CREAT, 0o600)
    for attempt in range(attempts):
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return fd
        except BlockingIOError:
            if attempt + 1 < attempts:
                time.sleep(0.05)
    os.close(fd)
    raise BuildRunning(f"a report build for {folder} is already running")


def _record_start(fd: int, pid: int) -> None:
    os.ftruncate(fd, 0)
    os.pwrite(fd, json.dumps({"pid": pid, "started": time.time()}).encode(), 0)


def _log_tail(folder: Path, n_chars: int = 600) -> str:
    log = folder / LOG_NAME
    return log.read_text(errors="replace")[-n_chars:].strip() if log.exists() else ""


def report_state(study: Study, version: str | None = None) -> ReportState:
    """The report's status for the study's current data (or the given version)."""
    version = version or data_version(study)
    folder = version_dir(study.pk, version)
    zip_path = folder / REPORT_NAME
    if zip_path.exists():
        return ReportState(study.pk, version, "ready", zip_path=zip_path, finished_at=zip_path.stat().st_mtime)
    if _lock_is_held(folder):
        with contextlib.suppress(OSError, ValueError):
            started = json.loads((folder / LOCK_NAME).read_text() or "{}").get("started")
            return ReportState(study.pk, version, "running", started_at=started)
        return ReportState(study.pk, version, "running")
    if (folder / ERROR_NAME).exists():
        return ReportState(study.pk, version, "failed", error=(folder / ERROR_NAME).read_text().strip())
    if (folder / LOCK_NAME).exists():            # a build took the lock and stopped without a zip or an error
        tail = _log_tail(folder)
        return ReportState(study.pk, version, "failed",
                           error="the build process stopped without finishing" + (f":\n{tail}" if tail else ""))
    return ReportState(study.pk, version, "none")


def build_command(study_id: int, version: str, lock_fd: int) -> list[str]:
    """The argv of the detached ``manage.py build_report`` run for this version, handed the already locked
    ``lock_fd``."""
    return [sys.executable, str(MANAGE_PY), "build_report", str(study_id), "--data-version", version,
            "--lock-fd", str(lock_fd)]


def start_build(study: Study) -> ReportState:
    """Start a detached build of the current data version unless its zip exists or a build is running; returns
    at once with the state (ready, or running)."""
    state = report_state(study)
    if state.status in ("ready", "running"):
        return state
    folder = version_dir(study.pk, state.version)
    try:
        fd = acquire_lock(folder)
    except BuildRunning:
        return report_state(study, state.version)
    try:
        (folder / ERROR_NAME).unlink(missing_ok=True)
        env = dict(os.environ, DJANGO_SETTINGS_MODULE=os.environ.get("DJANGO_SETTINGS_MODULE", "studyapp.settings"),
                   REPORTS_DIR=str(settings.REPORTS_DIR))       # the folder this process locked, whatever the env
        with open(folder / LOG_NAME, "ab") as log:
            proc = subprocess.Popen(build_command(study.pk, state.version, fd), cwd=settings.BASE_DIR, env=env,
                                    stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, pass_fds=(fd,),
                                    start_new_session=True)
        _record_start(fd, proc.pid)
    finally:
        os.close(fd)         # the child holds the lock through its inherited copy of the fd
    threading.Thread(target=proc.wait, name=f"report-build-{proc.pid}", daemon=True).start()   # no zombie
    return ReportState(study.pk, state.version, "running", started_at=time.time())


def zip_folder(src: Path, dest: Path) -> None:
    """Zip every file below src (paths relative to src) into dest, atomically (written as dest.part)."""
    part = dest.with_name(dest.name + ".part")
    with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as zf:
        for path in sorted(src.rglob("*")):
            if path.is_file():
                zf.write(path, path.relative_to(src).as_posix())
    os.replace(part, dest)


def prune_old_versions(study_id: int, keep: str) -> list[Path]:
    """Remove the study's other version folders whose build is not running; returns the removed folders."""
    removed = []
    root = Path(settings.REPORTS_DIR) / str(int(study_id))
    for folder in root.iterdir() if root.is_dir() else []:
        if folder.is_dir() and folder.name != keep and not _lock_is_held(folder):
            shutil.rmtree(folder, ignore_errors=True)
            removed.append(folder)
    return removed


def forget_reports(study_id: int) -> int:
    """Delete every stored report zip of the study, because a participant of it was deleted or withdrew
    (studyapp.data.privacy): idle version folders go whole; a running build's folder gets the PURGED_NAME mark, so the
    build discards its zip. Returns how many stored zips were deleted."""
    root = Path(settings.REPORTS_DIR) / str(int(study_id))
    removed = 0
    for folder in root.iterdir() if root.is_dir() else []:
        if not folder.is_dir():
            continue
        removed += (folder / REPORT_NAME).is_file()
        if _lock_is_held(folder):
            (folder / PURGED_NAME).write_text("a participant was removed while this report was being built\n")
            (folder / REPORT_NAME).unlink(missing_ok=True)
        else:
            shutil.rmtree(folder, ignore_errors=True)
    return removed


def build_report(study: Study, version: str, lock_fd: int) -> Path:
    """Write version's report.zip (the caller holds the lock through lock_fd). On failure error.txt says why and
    the exception propagates."""

    folder = version_dir(study.pk, version)
    _record_start(lock_fd, os.getpid())
    (folder / ERROR_NAME).unlink(missing_ok=True)
    try:
        with tempfile.TemporaryDirectory(prefix=".build-", dir=folder) as tmp:
            run_report(study, tmp)
            zip_folder(Path(tmp), folder / REPORT_NAME)
        if (folder / PURGED_NAME).exists():         # a participant was removed meanwhile (studyapp.data.privacy)
            (folder / REPORT_NAME).unlink(missing_ok=True)
            raise RuntimeError("a participant was deleted or withdrew while the report was built: build it again")
    except Exception as exc:
        if isinstance(exc, ImportError):
            message = f"the analysis library is not available in this deployment ({exc})"
        elif isinstance(exc, ValueError):          # analysis.io.ValidationError: file, line and column
            message = f"the study's exports did not validate: {exc}"
        else:
            message = f"{type(exc).__name__}: {exc}"
        (folder / ERROR_NAME).write_text(message + "\n")
        raise
    prune_old_versions(study.pk, keep=version)
    return folder / REPORT_NAME
