"""The real pool, exhausted: on PostgreSQL (a scratch database, when a server answers at DATABASE_URL or
127.0.0.1:5432) a server process whose pool connections are all held answers a request that needs the database with
503 and Retry-After once the pool's timeout passes, opens no connection beyond the pool's bound, and answers
normally again as soon as a connection is free."""
from __future__ import annotations

import json
import os
import secrets
import subprocess
import sys
from pathlib import Path
from urllib.parse import urlsplit, urlunsplit

import pytest

ROOT = Path(__file__).resolve().parent.parent
PG_BASE = os.environ.get("DATABASE_URL", "").strip() or "postgres://postgres@127.0.0.1:5432/postgres"

EXHAUST = """
import json, threading, time
from django.conf import settings
from django.db import connection
from django.test import Client
from django.urls import reverse

pool_size = settings.DATABASES["default"]["OPTIONS"]["pool"]["max_size"]
held, release = threading.Semaphore(0), threading.Event()

def hold():
    with connection.cursor() as cursor:       # this thread's connection, taken from the pool
        cursor.execute("SELECT 1")
        held.release()
        release.wait(30)
    connection.close()                        # back to the pool

holders = [threading.Thread(target=hold) for _ in range(pool_size)]
for t in holders:
    t.start()
for _ in holders:
    held.acquire()
url = reverse("studyapp:resume", args=["x" * 20])
client = Client(raise_request_exception=False)
started = time.monotonic()
busy = client.get(url)
waited = time.monotonic() - started
release.set()
for t in holders:
    t.join()
again = Client(raise_request_exception=False).get(url)
print("JSON" + json.dumps({"pool_size": pool_size, "busy": busy.status_code, "retry_after": busy.get("Retry-After"),
                           "busy_text": busy.content.decode()[:2000], "waited_s": waited,
                           "again": again.status_code}))
"""


@pytest.fixture
def scratch_database_url():
    """The URL of a scratch PostgreSQL database, dropped afterwards."""
    psycopg = pytest.importorskip("psycopg")
    parts = urlsplit(PG_BASE)
    try:
        admin = psycopg.connect(host=parts.hostname, port=parts.port or 5432, user=parts.username or "postgres",
                                password=parts.password, dbname=parts.path.lstrip("/") or "postgres",
                                autocommit=True, connect_timeout=3)
    except Exception as exc:        # no server here
        pytest.skip(f"PostgreSQL not reachable at {PG_BASE}: {exc}")
    name = f"poolexhaust_{os.getpid()}_{secrets.token_hex(3)}"
    admin.execute(f'CREATE DATABASE "{name}"')
    try:
        yield urlunsplit(parts._replace(path="/" + name))
    finally:
        admin.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
        admin.close()


def test_an_exhausted_pool_answers_503_with_retry_after_then_recovers(tmp_path, scratch_database_url):
    env = dict(os.environ, DATA_DIR=str(tmp_path), SECRET_KEY=secrets.token_urlsafe(50), DEBUG="0",
               DATABASE_URL=scratch_database_url, DB_CONNECTIONS="2", WEB_CONCURRENCY="1", DB_POOL_TIMEOUT="1",
               ALLOWED_HOSTS="testserver")
    env.pop("PRODUCTION", None)
    subprocess.run([sys.executable, "manage.py", "migrate", "--noinput", "-v", "0"], env=env, cwd=ROOT, check=True)
    run = subprocess.run([sys.executable, "manage.py", "shell", "-c", EXHAUST], env=env, cwd=ROOT,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    out = run.stdout
    result = json.loads(next(line for line in out.splitlines() if line.startswith("JSON"))[4:])
    assert result["pool_size"] == 2
    assert result["busy"] == 503 and result["retry_after"], result
    assert "Traceback" not in result["busy_text"] and "PoolTimeout" not in result["busy_text"]
    assert result["waited_s"] >= 0.9                     # it waited for the pool's timeout, then gave up
    assert result["again"] == 404                        # a free connection: the unknown token is a plain 404
