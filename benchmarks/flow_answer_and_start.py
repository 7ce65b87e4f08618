"""Benchmark of the participant flow: SQL statements per answered clip, and concurrent starts.

    DATA_DIR=$(mktemp -d) .venv/bin/python -m benchmarks.flow_answer_and_start [--starts 200] [--threads 16]
        [--out docs/benchmarks/flow.md]

Runs on a fresh SQLite file database under DATA_DIR (WAL, the app's default), with the SYNTHETIC test catalogue
(studyapp.testing.make_catalogue: placeholder clips, not rendered motion) and the "demo" preset study.
1. Answer cost: SQL statements of one answered clip (GET the clip page + POST the answer, Django test client),
   with 10 and with 2,000 participants in the study (the 2,000 bulk-inserted with full assignment sets), and
   the number of HTTP round trips from one answer to the next clip page.
2. Starts: ``--starts`` participants start from ``--threads`` threads at once (start_participant, the work of
   the /resume page that starts them); wall time, per-start latency, and the per-clip spread of each section.
3. HTTP starts (--http): the same burst through the whole view stack with the Django test client: each thread's
   participants consent (GET + POST /s/<slug>/) and fill in the demographics first; then all at once GET /resume
   (which starts them) and the first clip page. Counts HTTP statuses (a 500 is a failed start), participants
   left unstarted, and the per-clip spread.
--db-url postgres://user@host:port/db runs everything on a scratch PostgreSQL database made next to that one
(<db>_flowbench_<pid>_<time>, dropped afterwards) instead of SQLite; --starts-only skips part 1.
Works without Assignment.seq too, so an older checkout can be measured the same way.
"""
from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import threading
import time
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path


def setup_django(data_dir: str, db_url: str = "") -> None:
    """Django on a fresh database: SQLite under data_dir, or the PostgreSQL database db_url (migrated)."""
    os.environ["DATA_DIR"] = data_dir
    if db_url:
        os.environ["DATABASE_URL"] = db_url
    else:
        os.environ.pop("DATABASE_URL", None)
    os.environ.setdefault("DJANGO_SETTINGS_MODULE", "studyapp.settings")
    import django
    from django.core.management import call_command
    from django.test.utils import setup_test_environment

    django.setup()
    setup_test_environment()
    call_command("migrate", verbosity=0)


def make_study():
    from django.conf import settings

    from studyapp.models import Study
    from studyapp.staff.presets import create_study_from_preset
    from studyapp.testing import make_catalogue

    make_catalogue(Path(settings.MEDIA_ROOT))
    study = create_study_from_preset("demo", f"bench-{int(time.time() * 1000)}", plan="test",
                                     status=Study.Status.OPEN)
    study.sections.update(require_full_play=False)
    return study


def add_crowd(study, n: int) -> None:
    """n - 1 started participants with the assignments of one real start, bulk-inserted."""
    from studyapp.models import Assignment, Participant
    from studyapp.participant.assignment import start_participant

    template = Participant.objects.create(study=study, demographics_done=True)
    start_participant(template)
    fields = [f for f in ("section_id", "position", "clip_id", "options", "seq", "kind", "instructed")
              if hasattr(Assignment, f.removesuffix("_id")) or f.endswith("_id")]
    rows = list(template.assignments.values(*fields))
    offset = Participant.objects.count()
    extra = {"n_items": len(rows)} if hasattr(Participant, "n_items") else {}
    people = Participant.objects.bulk_create([
        Participant(study=study, demographics_done=True, status=Participant.Status.STARTED, token=f"crowd-{i}",
                    public_id=f"c{i}", **extra) for i in range(offset, offset + n - 1)], batch_size=500)
    Assignment.objects.bulk_create([Assignment(participant=p, **r) for p in people for r in rows], batch_size=5000)


def answer_cost(study, n_clips: int = 3) -> dict:
    """Statements and round trips of answering n_clips clips of a fresh participant (mean per clip)."""
    from django.db import connection
    from django.test import Client
    from django.test.utils import CaptureQueriesContext
    from django.urls import reverse

    from studyapp.models import Participant
    from studyapp.participant.assignment import current_step
    from studyapp.questions import questions_for

    client = Client()
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]), {"consent": "on"})
    p = Participant.objects.get(token=r["Location"].rstrip("/").split("/")[-1])
    client.post(reverse("studyapp:demographics", args=[p.token]), {"gender": "female", "age_group": "25-34"})
    url = client.get(reverse("studyapp:resume", args=[p.token]))["Location"]
    statements, commits, trips = [], [], []
    for _ in range(n_clips):
        step = current_step(Participant.objects.select_related("study").get(pk=p.pk))
        a = step.assignment
        data = {q.key: q.choices[0][0] for q in questions_for(a.section.section_type, a.section.options,
                                                              a.clip.theme, a.options)}
        with CaptureQueriesContext(connection) as q:
            assert client.get(url).status_code == 200
            r = client.post(url, data)
            hops = 1
            while "/clip/" not in r["Location"]:
                r = client.get(r["Location"])
                hops += 1
            url = r["Location"]
        sql = [x["sql"].upper() for x in q.captured_queries]
        statements.append(len(sql))
        commits.append(sum(s.startswith(("BEGIN", "SAVEPOINT")) for s in sql))
        trips.append(1 + hops)
    return {"statements": statistics.mean(statements), "transactions": statistics.mean(commits),
            "requests": statistics.mean(trips)}


def release_together(work, items, threads: int, gate: threading.Event) -> float:
    """Run ``work(item)`` for every item on ``threads`` threads; each call waits on ``gate``, which opens once all
    are submitted, so they arrive together. Returns the wall seconds from opening the gate to the last finish."""
    with ThreadPoolExecutor(threads) as pool:
        futures = [pool.submit(work, item) for item in items]
        t0 = time.perf_counter()
        gate.set()
        for f in futures:
            f.result()
        return time.perf_counter() - t0


def concurrent_starts(study, n: int, threads: int) -> dict:
    from django.db import connection

    from studyapp.models import Participant
    from studyapp.participant.assignment import start_participant

    people = [Participant.objects.create(study=study, demographics_done=True) for _ in range(n)]
    gate = threading.Event()
    latencies, failures = [], []

    def one(p):
        gate.wait()
        t = time.perf_counter()
        try:
            start_participant(p)
            latencies.append(time.perf_counter() - t)
        except Exception as exc:  # noqa: BLE001 - counted and reported
            failures.append(repr(exc))
        finally:
            connection.close()

    wall = release_together(one, people, threads, gate)
    lat = sorted(latencies)
    return {"started": len(latencies), "failed": len(failures), "wall_s": wall,
            "p50_ms": 1000 * lat[len(lat) // 2] if lat else float("nan"),
            "p95_ms": 1000 * lat[int(len(lat) * 0.95) - 1] if lat else float("nan"),
            "spread": spreads(study, people), "errors": Counter(failures).most_common(3)}


def spreads(study, people) -> dict[str, int]:
    """Section -> most minus least given trial clip among `people` (naturalness: per origin half)."""
    from studyapp.models import Assignment

    out = {}
    for section in study.sections.filter(reuse_section__isnull=True).order_by("order"):
        rows = Assignment.objects.filter(section=section, participant__in=people)
        if hasattr(Assignment, "kind"):
            rows = rows.filter(kind="")
        worst = 0
        for origin in set(rows.values_list("clip__origin", flat=True)):
            c = Counter(rows.filter(clip__origin=origin).values_list("clip_id", flat=True))
            worst = max(worst, max(c.values()) - min(c.values()))
        out[f"{section.order} {section.section_type}"] = worst
    return out


def _consent(study) -> tuple:
    """A fresh test client that consented to `study` and filled in the demographics: (client, token)."""
    import re

    from django.test import Client
    from django.urls import reverse

    client = Client(raise_request_exception=False)
    entry = reverse("studyapp:study_entry", args=[study.slug])
    page = client.get(entry).content.decode()
    key = re.search(r'name="consent_key" value="([^"]+)"', page)
    r = client.post(entry, {"consent": "on", "consent_key": key.group(1) if key else ""})
    token = r["Location"].rstrip("/").split("/")[-1]
    client.post(reverse("studyapp:demographics", args=[token]), {"gender": "female", "age_group": "25-34"})
    return client, token


def http_starts(study, n: int, threads: int) -> dict:
    """n participants consent, then all GET /resume (the start) and their first clip page at once, from
    `threads` threads with the Django test client. Statuses, unstarted participants, per-clip spread."""
    from django.db import connection
    from django.urls import reverse

    from studyapp.models import Participant

    ready = []
    with ThreadPoolExecutor(threads) as pool:
        ready = list(pool.map(lambda _: _consent_with_close(study), range(n)))
    gate, statuses, latencies = threading.Event(), Counter(), []

    def one(client_token):
        client, token = client_token
        gate.wait()
        t = time.perf_counter()
        try:
            r = client.get(reverse("studyapp:resume", args=[token]))
            statuses[f"resume {r.status_code}"] += 1
            if r.status_code == 302 and "/clip/" in r["Location"]:
                statuses[f"clip page {client.get(r['Location']).status_code}"] += 1
            latencies.append(time.perf_counter() - t)
        finally:
            connection.close()

    wall = release_together(one, ready, threads, gate)
    people = list(Participant.objects.filter(token__in=[t for _, t in ready]))
    lat = sorted(latencies)
    return {"n": n, "wall_s": wall, "statuses": dict(sorted(statuses.items())),
            "unstarted": sum(p.status == Participant.Status.CONSENTED for p in people),
            "p50_ms": 1000 * lat[len(lat) // 2] if lat else float("nan"),
            "p95_ms": 1000 * lat[int(len(lat) * 0.95) - 1] if lat else float("nan"),
            "spread": spreads(study, people)}


def _consent_with_close(study) -> tuple:
    from django.db import connection

    try:
        return _consent(study)
    finally:
        connection.close()


def scratch_database(base_url: str) -> tuple[str, str]:
    """Create a uniquely named PostgreSQL database next to base_url's: (its URL, its name)."""
    from urllib.parse import urlsplit, urlunsplit

    parts = urlsplit(base_url)
    name = f"{parts.path.lstrip('/') or 'postgres'}_flowbench_{os.getpid()}_{int(time.time())}"
    with _admin_connection(base_url) as conn:
        conn.execute(f'CREATE DATABASE "{name}"')
    return urlunsplit(parts._replace(path="/" + name)), name


def drop_database(base_url: str, name: str) -> None:
    from django.db import connections

    connections.close_all()
    with _admin_connection(base_url) as conn:
        conn.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')


def _admin_connection(base_url: str):
    from urllib.parse import urlsplit

    import psycopg

    parts = urlsplit(base_url)
    return psycopg.connect(host=parts.hostname, port=parts.port or 5432, user=parts.username or "postgres",
                           password=parts.password, dbname=parts.path.lstrip("/") or "postgres", autocommit=True)


def report(args, engine: str, small: dict | None, large: dict | None, starts: dict, http: dict | None) -> str:
    """The Markdown page of the figures."""
    lines = ["# Participant flow: answer cost and concurrent starts", "",
             f"Machine: 2-core CI VM, no GPU, shared with parallel jobs; date {time.strftime('%Y-%m-%d')}. "
             f"{engine}, SYNTHETIC placeholder catalogue, demo preset. `benchmarks/flow_answer_and_start.py`.", ""]
    if small and large:
        lines += ["| participants in study | SQL statements per answered clip (GET + POST) | transactions | "
                  "HTTP requests per answer |", "|---|---|---|---|",
                  f"| 10 | {small['statements']:.1f} | {small['transactions']:.1f} | {small['requests']:.0f} |",
                  f"| 2,000 | {large['statements']:.1f} | {large['transactions']:.1f} | {large['requests']:.0f} |",
                  ""]
    lines += [f"Concurrent starts: {starts['started']} of {args.starts} started ({starts['failed']} failed) from "
              f"{args.threads} threads in {starts['wall_s']:.2f} s; per start p50 {starts['p50_ms']:.0f} ms, "
              f"p95 {starts['p95_ms']:.0f} ms.", "",
              "Per-clip spread (most - least given clip; naturalness per origin half): "
              + ", ".join(f"{k}: {v}" for k, v in starts["spread"].items()) + "."]
    if starts["errors"]:
        lines += ["", f"Errors: {starts['errors']}"]
    if http:
        lines += ["", f"HTTP starts (Django test client, whole view stack): {http['n']} participants consented, "
                  f"then GET /resume + first clip page at once from {args.threads} threads in "
                  f"{http['wall_s']:.2f} s (p50 {http['p50_ms']:.0f} ms, p95 {http['p95_ms']:.0f} ms); "
                  "statuses: " + ", ".join(f"{k}: {v}" for k, v in http["statuses"].items())
                  + f"; left unstarted: {http['unstarted']}.", "",
                  "Per-clip spread: " + ", ".join(f"{k}: {v}" for k, v in http["spread"].items()) + "."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--starts", type=int, default=200)
    ap.add_argument("--threads", type=int, default=16)
    ap.add_argument("--http", action="store_true", help="also start --starts participants over HTTP")
    ap.add_argument("--starts-only", action="store_true", help="skip the answer-cost part")
    ap.add_argument("--db-url", default="", help="PostgreSQL server URL (a scratch database is made there)")
    ap.add_argument("--out", default="")
    args = ap.parse_args(argv)
    db_url, name = scratch_database(args.db_url) if args.db_url else ("", "")
    try:
        setup_django(os.environ.get("DATA_DIR") or tempfile.mkdtemp(prefix="flow-bench-"), db_url)
        small = large = None
        if not args.starts_only:
            study = make_study()
            add_crowd(study, 10)
            small = answer_cost(study)
            add_crowd(study, 2000)
            large = answer_cost(study)
        starts = concurrent_starts(make_study(), args.starts, args.threads)
        http = http_starts(make_study(), args.starts, args.threads) if args.http else None
    finally:
        if name:
            drop_database(args.db_url, name)
    engine = "PostgreSQL (scratch database)" if db_url else "SQLite file database (WAL)"
    text = report(args, engine, small, large, starts, http)
    print(text)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
