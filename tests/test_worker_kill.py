"""A gunicorn worker killed with SIGKILL while answer POSTs are in flight loses or duplicates nothing.

A scratch SQLite study (synthetic catalogue, demo preset, every participant already started) is served by gunicorn
in the demo's configuration (ASGI workers, demo.sh) and in the production recipe's (threaded WSGI workers behind
nginx). Participants answer every clip over HTTP, each in its own thread; meanwhile a worker is killed with -9
several times. A client whose request fails (connection reset, 5xx) sends the same answer again, as a browser's
retry would. Then the database must hold every answer exactly once: the kill stored an answer completely or
not at all, and the retry stored the missing ones once.
"""
from __future__ import annotations

import json
import os
import re
import secrets
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
pytestmark = pytest.mark.slow

SERVERS = {
    "asgi": ["studyapp.asgi:application", "--worker-class", "asgi"],
    "gthread": ["studyapp.wsgi", "--worker-class", "gthread", "--threads", "4"],
}
N_PARTICIPANTS = 16
KILLS = 4

SETUP = """
import json
from django.conf import settings
from studyapp.assignment import start_participant
from studyapp.models import Participant
from studyapp.presets import create_study_from_preset
from studyapp.testing import make_catalogue
from studyapp.views import item_questions
make_catalogue(settings.MEDIA_ROOT)
study = create_study_from_preset("demo", "demo", plan="test", status="open")
study.sections.update(require_full_play=False)
out = []
for i in range(%d):
    p = Participant.objects.create(study=study, demographics_done=True, gender="female", age_group="18-24")
    start_participant(p)
    pages = []
    for a in p.assignments.select_related("section", "clip").order_by("seq"):
        qs = item_questions(a.section, a.clip, a.options, a.kind, a.instructed)
        pages.append({"n": a.seq, "kind": a.kind, "answers": {q.key: q.choices[0][0] for q in qs}})
    out.append({"token": p.token, "pages": pages})
print("JSON" + json.dumps(out))
"""

CHECK = """
import json
from collections import Counter
from studyapp.models import Assignment, Response
dup = Counter(Response.objects.values_list("participant_id", "section_id", "clip_id", "question"))
print("JSON" + json.dumps({
    "unanswered": Assignment.objects.filter(answered_at__isnull=True).count(),
    "assignments": Assignment.objects.count(),
    "responses": Response.objects.count(),
    "duplicates": sum(1 for n in dup.values() if n > 1),
}))
"""


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _manage_json(env: dict, code: str):
    out = subprocess.run([sys.executable, str(ROOT / "manage.py"), "shell", "-c", code], env=env, cwd=ROOT,
                         check=True, capture_output=True, text=True).stdout
    return json.loads(next(line for line in out.splitlines() if line.startswith("JSON"))[4:])


def _workers(master: int) -> list[int]:
    out = subprocess.run(["pgrep", "-P", str(master)], capture_output=True, text=True).stdout
    return [int(pid) for pid in out.split()]


def _answer_all(base: str, participant: dict, stats: dict, lock: threading.Lock) -> None:
    """Answer every page in order; a failed POST is sent again until the server answers it."""
    import requests

    session = requests.Session()
    token = participant["token"]
    for page in participant["pages"]:
        url = f"{base}/p/{token}/clip/{page['n']}/"
        csrf = None
        while csrf is None:
            try:
                html = session.get(url, timeout=20).text
                found = re.search(r'name="csrfmiddlewaretoken" value="([^"]+)"', html)
                csrf = found.group(1) if found else None
            except requests.RequestException:
                pass
            if csrf is None:
                time.sleep(0.2)
        data = dict(page["answers"], csrfmiddlewaretoken=csrf)
        while True:
            try:
                r = session.post(url, data=data, timeout=20, allow_redirects=False)
                if r.status_code in (200, 302):
                    break
                error = f"status {r.status_code}"
            except requests.RequestException as exc:
                error = type(exc).__name__
            with lock:
                stats["retries"] += 1
                stats["errors"][error] = stats["errors"].get(error, 0) + 1
            time.sleep(0.2)
        with lock:
            stats["posts"] += 1


@pytest.mark.parametrize("server", sorted(SERVERS))
def test_killed_worker_stores_each_answer_once(server, tmp_path):
    env = dict(os.environ, DATA_DIR=str(tmp_path), SECRET_KEY=secrets.token_urlsafe(50), DEBUG="0",
               ALLOWED_HOSTS="127.0.0.1,localhost", OMP_NUM_THREADS="1")
    env.pop("DATABASE_URL", None)
    env.pop("PRODUCTION", None)
    subprocess.run([sys.executable, str(ROOT / "manage.py"), "migrate", "--noinput", "-v", "0"], env=env, cwd=ROOT,
                   check=True)
    participants = _manage_json(env, SETUP % N_PARTICIPANTS)
    port = _free_port()
    master = subprocess.Popen([sys.executable, "-m", "gunicorn", *SERVERS[server], "-w", "2",
                               "-b", f"127.0.0.1:{port}", "--log-level", "error"],
                              env=env, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    base = f"http://127.0.0.1:{port}"
    try:
        import requests

        deadline = time.monotonic() + 60
        while True:
            try:
                if requests.get(f"{base}/healthz", timeout=2).status_code == 200:
                    break
            except requests.RequestException:
                pass
            assert time.monotonic() < deadline, "gunicorn did not start"
            time.sleep(0.3)
        stats, lock = {"posts": 0, "retries": 0, "errors": {}}, threading.Lock()
        clients = [threading.Thread(target=_answer_all, args=(base, p, stats, lock), daemon=True)
                   for p in participants]
        for t in clients:
            t.start()
        kills = 0
        while kills < KILLS and any(t.is_alive() for t in clients):
            time.sleep(0.6)
            with lock:
                in_progress = stats["posts"] > 0
            pids = _workers(master.pid)
            if in_progress and pids:
                os.kill(pids[kills % len(pids)], signal.SIGKILL)
                kills += 1
        for t in clients:
            t.join(180)
        assert not any(t.is_alive() for t in clients), "clients did not finish"
    finally:
        master.terminate()
        master.wait(20)
    result = _manage_json(env, CHECK)
    expected_pages = sum(len(p["pages"]) for p in participants)
    print(server, "kills", kills, stats, result)
    assert kills == KILLS
    assert stats["retries"] > 0, "no request was in flight at any kill: nothing was tested"
    assert stats["posts"] == expected_pages
    assert result["unanswered"] == 0 and result["assignments"] == expected_pages
    assert result["duplicates"] == 0
    # every page's answers exactly once (a practice item stores none): no lost, partial or doubled answer set
    expected = sum(len(page["answers"]) for p in participants for page in p["pages"] if page["kind"] != "practice")
    assert result["responses"] == expected
