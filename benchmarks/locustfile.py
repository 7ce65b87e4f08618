"""Locust users of the study load benchmark (SYNTHETIC participants; started by benchmarks/bench_study_load.py).

Why Locust: its users are gevent greenlets (and FastHttpUser's client is geventhttpclient), so a few hundred
participants cost one generator process a few MB and little CPU, and the generator is not what saturates first;
with `--processes N` it forks N generator processes on a bigger machine. On the 2-core CI VM one process is used:
every core the generator takes is taken from gunicorn and PostgreSQL.

User classes (chosen on the locust command line):
    StudyParticipant  takes the whole study once (benchmarks/bench_study_load.take_study: consent, demographics,
                      every clip page and answer POST with double submits and reloads, feedback), appends its
                      record to $STUDY_BENCH_RESULTS (one JSON line) and idles; at most
                      $STUDY_BENCH_PARTICIPANTS in all generator processes (a flock()ed counter file)
    MediaViewer       a slow player: 64 KiB Range requests of one clip ($STUDY_BENCH_MEDIA), 4 per second
    HealthUser        GET /healthz as fast as possible: the requests/s ceiling of the stack

Run by hand from the repository root against a running server (the benchmark script sets the variables):
    STUDY_BENCH_SLUG=bench STUDY_BENCH_RESULTS=/tmp/p.jsonl STUDY_BENCH_TICKETS=/tmp/t STUDY_BENCH_PARTICIPANTS=50 \
        .venv/bin/python -m locust -f benchmarks/locustfile.py \
        --headless --host http://127.0.0.1:8000 -u 50 -r 5 -t 120s StudyParticipant
"""
from __future__ import annotations

import fcntl
import itertools
import json
import os
import time
from urllib.parse import urlencode

from locust import FastHttpUser, constant, task
from locust.exception import StopUser

from benchmarks.bench_study_load import MEDIA_CHUNK, take_study

_numbers = itertools.count()


class LocustHttp:
    """The http object of take_study over a FastHttpSession: no automatic redirects (take_study follows them and
    times every hop), form bodies url-encoded, the session's cookie jar kept per user."""

    def __init__(self, client):
        self.client = client

    def request(self, method: str, url: str, data: dict | None, name: str):
        body = urlencode(data) if data is not None else None
        headers = {"Referer": url}
        if body is not None:
            headers["Content-Type"] = "application/x-www-form-urlencoded"
        t = time.perf_counter()
        r = self.client.request(method, url, data=body, name=name, headers=headers, allow_redirects=False)
        ms = 1000 * (time.perf_counter() - t)
        location = r.headers.get("Location") if r.headers else None
        return r.status_code or 599, location, r.text or "", ms


def claim_ticket() -> int | None:
    """The next participant number (0-based) from the counter file $STUDY_BENCH_TICKETS, shared by every
    generator process under flock; None once $STUDY_BENCH_PARTICIPANTS have been handed out."""
    cap = int(os.environ.get("STUDY_BENCH_PARTICIPANTS", "0") or 0)
    fd = os.open(os.environ["STUDY_BENCH_TICKETS"], os.O_RDWR | os.O_CREAT, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        issued = int(os.pread(fd, 32, 0).decode() or 0)
        if cap and issued >= cap:
            return None
        os.pwrite(fd, str(issued + 1).encode(), 0)
        return issued
    finally:
        os.close(fd)            # closing releases the flock


class StudyParticipant(FastHttpUser):
    """One participant: takes the study once, then idles until the run ends (no StopUser: locust would start a
    replacement user, i.e. an extra participant)."""

    wait_time = constant(0)
    connection_timeout = 60.0
    network_timeout = 60.0
    done = False

    @task
    def take_the_study(self):
        index = None if self.done else claim_ticket()
        self.done = True
        if index is None:
            time.sleep(1.0)     # gevent-patched: this user's part is over
            return
        deadline = float(os.environ.get("STUDY_BENCH_DEADLINE", time.time() + 600))
        record = take_study(LocustHttp(self.client), self.host.rstrip("/"), os.environ["STUDY_BENCH_SLUG"], index,
                            deadline, float(os.environ.get("STUDY_BENCH_THINK", "0") or 0))
        line = json.dumps(record) + "\n"
        fd = os.open(os.environ["STUDY_BENCH_RESULTS"], os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o600)
        try:
            os.write(fd, line.encode())           # one write per record: O_APPEND keeps the lines whole
        finally:
            os.close(fd)


class MediaViewer(FastHttpUser):
    """A slow player: sequential 64 KiB ranges of one clip, 4 per second (256 KiB/s), wrapping at the end."""

    wait_time = constant(0.25)
    fixed_count = int(os.environ.get("STUDY_BENCH_VIEWERS", "0") or 0)

    def on_start(self):
        urls = [u for u in os.environ.get("STUDY_BENCH_MEDIA", "").split(",") if u]
        if not urls:
            raise StopUser()
        self.url = urls[next(_numbers) % len(urls)]
        self.offset, self.size = 0, None
        # clips need a session that may see them: the benchmark's staff session
        self.cookie = {"Cookie": f"sessionid={os.environ.get('STUDY_BENCH_MEDIA_SESSION', '')}"}

    @task
    def next_range(self):
        end = self.offset + MEDIA_CHUNK - 1
        headers = {"Range": f"bytes={self.offset}-{end}", **self.cookie}
        with self.client.get(self.url, name="media range", headers=headers, catch_response=True) as r:
            if r.status_code != 206:
                r.failure(f"expected 206, got {r.status_code}")
                return
            self.size = int(r.headers["Content-Range"].rsplit("/", 1)[1])
        self.offset = end + 1 if end + 1 < self.size else 0


class HealthUser(FastHttpUser):
    wait_time = constant(0)

    @task
    def healthz(self):
        self.client.get("/healthz", name="healthz")

