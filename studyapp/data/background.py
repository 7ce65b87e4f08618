"""Detached background commands of the admin (clip imports, stimulus renders): started in their own session with
their output in a log and their process id in a file, so a request never waits for them and their state is read
back from files alone (a restarted server finds its jobs where it left them)."""
from __future__ import annotations

import os
import subprocess
import threading
from pathlib import Path

from django.conf import settings


def launch(cmd: list[str], folder: Path, log_name: str, pid_name: str) -> int:
    """Run ``cmd`` detached (own session, stdout and stderr appended to ``folder/log_name``), its pid written to
    ``folder/pid_name``; returns the pid at once."""
    env = dict(os.environ, DJANGO_SETTINGS_MODULE=os.environ.get("DJANGO_SETTINGS_MODULE", "studyapp.settings"),
               DATA_DIR=str(settings.DATA_DIR), MEDIA_ROOT=str(settings.MEDIA_ROOT), PYTHONUNBUFFERED="1")
    with open(folder / log_name, "ab") as log:
        proc = subprocess.Popen(cmd, cwd=settings.BASE_DIR, env=env, stdin=subprocess.DEVNULL, stdout=log,
                                stderr=subprocess.STDOUT, start_new_session=True)
    (folder / pid_name).write_text(str(proc.pid))
    threading.Thread(target=proc.wait, name=f"background-{proc.pid}", daemon=True).start()   # no zombie
    return proc.pid


def is_running(folder: Path, pid_name: str) -> bool:
    """Whether the process recorded in ``folder/pid_name`` is alive (not a zombie); False when there is none."""
    try:
        pid = int((folder / pid_name).read_text())
        os.kill(pid, 0)
    except (OSError, ValueError):
        return False
    try:      # a finished child not yet reaped still answers kill(0): read its state
        return Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0] != "Z"
    except OSError:
        return True
