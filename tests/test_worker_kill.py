"""A gunicorn worker killed with SIGKILL while answer POSTs are in flight loses or duplicates nothing.

A scratch study (synthetic catalogue, demo preset, every participant already started) on SQLite and on PostgreSQL
(a scratch database, when a server answers at DATABASE_URL or 127.0.0.1:5432) is served by gunicorn in the demo's
configuration (ASGI workers, demo.sh) and in the production recipe's (threaded WSGI workers behind nginx); on
PostgreSQL the workers share a small connection pool (DB_CONNECTIONS=8), and its peak use is checked.
Participants answer every clip over HTTP, each in its own thread; meanwhile a worker is killed with -9
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
from studyapp.participant.assignment import start_participant
from studyapp.models import Participant
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue
from studyapp.participant.views import item_questions
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


PG_BASE = os.environ.get("DATABASE_URL", "").strip() or "postgres://postgres@127.0.0.1:5432/postgres"
DB_CONNECTIONS = 8


def _pg_admin():
    from urllib.parse import urlsplit

    import psycopg

    parts = urlsplit(PG_BASE)
    return psycopg.connect(host=parts.hostname, port=parts.port or 5432, user=parts.username or "postgres",
                           password=parts.password, dbname=parts.path.lstrip("/") or "postgres", autocommit=True,
                           connect_timeout=3)


@pytest.fixture
def scratch_postgres():
    """A scratch PostgreSQL database's URL (dropped afterwards) and a function giving its connection count now."""
    from urllib.parse import urlsplit, urlunsplit

    try:
        admin = _pg_admin()
    except Exception as exc:        # no server here
        pytest.skip(f"PostgreSQL not reachable at {PG_BASE}: {exc}")
    name = f"workerkill_{os.getpid()}_{secrets.token_hex(3)}"
    admin.execute(f'CREATE DATABASE "{name}"')
    try:
        yield (urlunsplit(urlsplit(PG_BASE)._replace(path="/" + name)),
               lambda: admin.execute("SELECT count(*) FROM pg_stat_activity WHERE datname = %s", [name]).fetchone()[0])
    finally:
        admin.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
        admin.close()


@pytest.mark.parametrize("server", sorted(SERVERS))
def test_killed_worker_stores_each_answer_once(server, tmp_path):
    run_with_kills(server, tmp_path, database_url="")


@pytest.mark.parametrize("server", sorted(SERVERS))
def test_killed_worker_stores_each_answer_once_on_postgres(server, tmp_path, scratch_postgres):
    url, connections = scratch_postgres
    stats = run_with_kills(server, tmp_path, database_url=url, connections=connections)
    assert not any(e.startswith("status 5") for e in stats["errors"]), stats["errors"]
    # the pool's bound (plus the set-up and check processes' own connection, never at the same time)
    assert stats["peak_connections"] <= DB_CONNECTIONS + 1, stats["peak_connections"]


def run_with_kills(server: str, tmp_path: Path, database_url: str, connections=None) -> dict:
    """Serve the scratch study, answer every page while killing workers, check the database; returns the client
    statistics (with the peak connection count when ``connections`` is given)."""
    env = dict(os.environ, DATA_DIR=str(tmp_path), SECRET_KEY=secrets.token_urlsafe(50), DEBUG="0",
               ALLOWED_HOSTS="127.0.0.1,localhost", OMP_NUM_THREADS="1", WEB_CONCURRENCY="2",
               DB_CONNECTIONS=str(DB_CONNECTIONS),
               START_RATE_BURST="0")      # every participant here comes from 127.0.0.1: no start rate limit
    env.pop("DATABASE_URL", None)
    env.pop("PRODUCTION", None)
    if database_url:
        env["DATABASE_URL"] = database_url
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
        stats, lock = {"posts": 0, "retries": 0, "errors": {}, "peak_connections": 0}, threading.Lock()
        clients = [threading.Thread(target=_answer_all, args=(base, p, stats, lock), daemon=True)
                   for p in participants]
        for t in clients:
            t.start()
        kills = 0
        expected_pages = sum(len(p["pages"]) for p in participants)
        # a kill at each of KILLS evenly spaced answer counts, so fast clients cannot finish before the last kill
        milestones = [expected_pages * (k + 1) // (KILLS + 1) for k in range(KILLS)]

        def sample():
            if connections is not None:
                stats["peak_connections"] = max(stats["peak_connections"], connections())

        while kills < KILLS and any(t.is_alive() for t in clients):
            time.sleep(0.02)
            sample()
            with lock:
                due = stats["posts"] >= milestones[kills]
            pids = _workers(master.pid) if due else []
            if pids:
                try:
                    os.kill(pids[kills % len(pids)], signal.SIGKILL)
                except ProcessLookupError:  # a worker that exited between pgrep and the kill
                    continue
                kills += 1
        end = time.monotonic() + 180
        while any(t.is_alive() for t in clients) and time.monotonic() < end:
            time.sleep(0.1)
            sample()
        assert not any(t.is_alive() for t in clients), "clients did not finish"
    finally:
        master.terminate()
        try:
            master.wait(40)
        except subprocess.TimeoutExpired:
            master.kill()
            master.wait()
    result = _manage_json(env, CHECK)
    print(server, "kills", kills, stats, result)
    assert kills == KILLS
    assert stats["retries"] > 0, "no request was in flight at any kill: nothing was tested"
    assert stats["posts"] == expected_pages
    assert result["unanswered"] == 0 and result["assignments"] == expected_pages
    assert result["duplicates"] == 0
    # every page's answers exactly once (a practice item stores none): no lost, partial or doubled answer set
    expected = sum(len(page["answers"]) for p in participants for page in p["pages"] if page["kind"] != "practice")
    assert result["responses"] == expected
    return stats
