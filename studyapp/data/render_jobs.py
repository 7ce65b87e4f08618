"""Stimulus renders from the admin: a plan (a stimulus set's YAML, or a built-in plan by name) rendered by
``manage.py generate_clips`` as a detached process (studyapp.data.background), never inside a request; its state read
back from the job's files, so a job outlives the server that started it.

    RENDERS_DIR/<job>/plan.yaml          the stimulus set's plan (absent for a built-in plan)
                      job.json           the plan's name and reference, the clip count, the estimate, who asked
                      progress.json      the command's counts (total, todo, skipped, done, failed, finished)
                      render.log         its output
                      render.pid         the process id of the latest run
                      contact_sheet.png  the posters of the plan's clips (when it is done)

``RENDERS_DIR`` is ``DATA_DIR/renders`` (never served). A job whose process is gone before the command said it
finished (the server or the machine was restarted, the process killed) is *interrupted*: shown as failed and
resumable; a resumed job runs the same command again, which skips every clip whose files and record are complete.
"""
from __future__ import annotations

import json
import secrets
import sys
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from django.conf import settings

from . import background
from .clip_import import without_server_paths

PLAN_NAME = "plan.yaml"
JOB_NAME = "job.json"
PROGRESS_NAME = "progress.json"
LOG_NAME = "render.log"
PID_NAME = "render.pid"
SHEET_NAME = "contact_sheet.png"

RUNNING, DONE, FAILED, INTERRUPTED = "running", "done", "failed", "interrupted"


class RenderJobError(ValueError):
    """A job that does not exist or cannot be started; says which."""


def renders_dir() -> Path:
    return Path(settings.DATA_DIR) / "renders"


def job_dir(job: str) -> Path:
    """The folder of a render job; RenderJobError for a name that is not one of ours."""
    if not job or len(job) > 60 or not all(c.isalnum() or c == "-" for c in job):
        raise RenderJobError(f"no such render {job!r}")
    return renders_dir() / job


def new_job(plan_name: str, n_clips: int, estimate_s: float, user: str, plan_text: str | None = None,
            builtin: str | None = None) -> str:
    """Create a job folder for a stimulus set's plan (``plan_text``, its YAML) or a built-in plan (``builtin``, its
    name); returns the job name. Nothing runs yet (:func:`start`)."""
    if (plan_text is None) == (builtin is None):
        raise RenderJobError("give the plan's YAML or a built-in plan's name")
    job = f"{datetime.now(UTC):%Y%m%d-%H%M%S}-{secrets.token_hex(4)}"
    folder = job_dir(job)
    folder.mkdir(parents=True)
    if plan_text is not None:
        (folder / PLAN_NAME).write_text(plan_text, encoding="utf-8")
    info = {"plan": plan_name, "builtin": builtin or "", "n_clips": n_clips, "estimate_s": round(estimate_s, 1),
            "user": user, "created": datetime.now(UTC).isoformat(timespec="seconds")}
    (folder / JOB_NAME).write_text(json.dumps(info), encoding="utf-8")
    return job


def plan_ref(job: str) -> str:
    """What ``generate_clips --plan`` is given: the job's plan file, or the built-in plan's name."""
    info = _info(job_dir(job))
    return info.get("builtin") or str(job_dir(job) / PLAN_NAME)


def render_command(job: str) -> list[str]:
    """The ``manage.py generate_clips`` command line of a job."""
    folder = job_dir(job)
    return [sys.executable, str(Path(settings.BASE_DIR) / "manage.py"), "generate_clips", "--plan", plan_ref(job),
            "--no-progress", "--progress-file", str(folder / PROGRESS_NAME), "--contact-sheet",
            str(folder / SHEET_NAME)]


def start(job: str) -> int:
    """Run the job's render detached (again, for a resumed job); returns its pid. RenderJobError while it runs."""
    folder = job_dir(job)
    if not folder.is_dir():
        raise RenderJobError(f"no such render {job!r}")
    if background.is_running(folder, PID_NAME):
        raise RenderJobError(f"render {job} is running already")
    (folder / PROGRESS_NAME).unlink(missing_ok=True)
    return background.launch(render_command(job), folder, LOG_NAME, PID_NAME)


def _info(folder: Path) -> dict:
    try:
        info = json.loads((folder / JOB_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return info if isinstance(info, dict) else {}


def _progress(folder: Path) -> dict:
    try:
        progress = json.loads((folder / PROGRESS_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return progress if isinstance(progress, dict) else {}


@dataclass(frozen=True)
class RenderState:
    """Where a render job stands.

    Attributes:
        status: running | done | failed (the command finished with failed clips) | interrupted (its process is gone
            before it finished: a restart, a kill).
        total, todo, skipped, done, failed: clips of the plan, to render in this run, already done before it,
            rendered and failed so far.
        percent: 0..100 of this run's clips finished (100 when there was nothing to do).
        log: the log's tail, the server's folders replaced by names.
    """

    job: str
    status: str
    plan: str
    builtin: str
    n_clips: int
    estimate_s: float
    total: int
    todo: int
    skipped: int
    done: int
    failed: int
    log: str
    created: str
    user: str
    has_sheet: bool
    has_plan_file: bool

    @property
    def percent(self) -> int:
        if self.status == DONE:
            return 100
        return int(100 * (self.done + self.failed) / self.todo) if self.todo else 0

    @property
    def resumable(self) -> bool:
        return self.status in (FAILED, INTERRUPTED)


def render_state(job: str) -> RenderState:
    folder = job_dir(job)
    if not folder.is_dir():
        raise RenderJobError(f"no such render {job!r}")
    info, progress = _info(folder), _progress(folder)
    log_path = folder / LOG_NAME
    log = log_path.read_text(errors="replace")[-4000:] if log_path.is_file() else ""
    if background.is_running(folder, PID_NAME):
        status = RUNNING
    elif progress.get("finished"):
        status = FAILED if progress.get("failed") else DONE
    else:
        status = INTERRUPTED
    return RenderState(job, status, str(info.get("plan", "")), str(info.get("builtin", "")),
                       int(info.get("n_clips", 0)), float(info.get("estimate_s", 0.0)),
                       int(progress.get("total", 0)), int(progress.get("todo", 0)), int(progress.get("skipped", 0)),
                       int(progress.get("done", 0)), int(progress.get("failed", 0)),
                       without_server_paths(log, folder), str(info.get("created", "")), str(info.get("user", "")),
                       (folder / SHEET_NAME).is_file(), (folder / PLAN_NAME).is_file())


def recent_jobs(n: int = 20) -> list[RenderState]:
    """The newest ``n`` render jobs, newest first (unreadable folders skipped)."""
    root = renders_dir()
    if not root.is_dir():
        return []
    out = []
    for folder in sorted((p for p in root.iterdir() if p.is_dir()), reverse=True)[:n]:
        try:
            out.append(render_state(folder.name))
        except RenderJobError:
            continue
    return out


def plan_file(job: str) -> Path:
    """The job's plan file (RenderJobError for a built-in plan's job, which has none)."""
    path = job_dir(job) / PLAN_NAME
    if not path.is_file():
        raise RenderJobError(f"render {job} has no plan file")
    return path


def sheet_file(job: str) -> Path:
    path = job_dir(job) / SHEET_NAME
    if not path.is_file():
        raise RenderJobError(f"render {job} has no contact sheet yet")
    return path
