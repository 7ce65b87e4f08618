"""Load test: N simulated participants take the demo study at once over HTTP against gunicorn + PostgreSQL.

    python benchmarks/bench_study_load.py --participants 20 --workers 3 [--db-url postgres://postgres@127.0.0.1:5432/postgres]

Loopback only, bounded in participant count (<= 200) and time (--time-limit). It creates a scratch database
(`<name>_studybench`, dropped and recreated), a SYNTHETIC catalogue (dummy media files, metadata synthetic=True) and
the demo study with clip playback checks off (no one watches), starts gunicorn, and runs one thread per participant
with its own cookie session: consent, demographics, every clip (GET page, POST answers), feedback, completion.
Every 4th answer is posted twice (a double submit) and every 5th clip page is reloaded before answering.

Reports answers per second (answer POSTs accepted / wall time), p50/p99 latency of answer POSTs and clip pages,
and lost / duplicated responses found in the database and in the streamed responses.csv (both must be 0).
"""
from __future__ import annotations

import argparse
import html
import json
import os
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from urllib.parse import urlsplit, urlunsplit

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

CSRF_RE = re.compile(r'name="csrfmiddlewaretoken" value="([^"]+)"')
INPUT_RE = re.compile(r'<input type="(checkbox|radio)" name="([^"]+)" id="[^"]*" value="([^"]*)"')
FEEDBACK_RE = re.compile(r'<(input|textarea)[^>]*name="([^"]+)"[^>]*?(?:value="([^"]*)")?')


def percentile(values: list[float], q: float) -> float:
    if not values:
        return float("nan")
    v = sorted(values)
    k = min(len(v) - 1, max(0, int(round(q / 100 * (len(v) - 1)))))
    return v[k]


def scratch_db_url(base: str) -> tuple[str, str]:
    parts = urlsplit(base)
    name = (parts.path.lstrip("/") or "postgres") + "_studybench"
    return urlunsplit(parts._replace(path="/" + name)), name


def recreate_db(base_url: str, name: str) -> None:
    import psycopg

    parts = urlsplit(base_url)
    with psycopg.connect(host=parts.hostname, port=parts.port or 5432, user=parts.username or "postgres",
                         password=parts.password, dbname=parts.path.lstrip("/") or "postgres",
                         autocommit=True) as conn:
        conn.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
        conn.execute(f'CREATE DATABASE "{name}"')


def setup_django(db_url: str, media_root: Path):
    os.environ["DATABASE_URL"] = db_url
    os.environ["MEDIA_ROOT"] = str(media_root)
    os.environ.setdefault("DJANGO_SETTINGS_MODULE", "studyapp.settings")
    import django

    django.setup()
    from django.core.management import call_command

    call_command("migrate", verbosity=0)
    from studyapp.models import Study
    from studyapp.presets import create_study_from_preset
    from studyapp.testing import make_catalogue

    make_catalogue(media_root, n_gait=40, n_transition=20, n_gait_source=10, n_gesture=40)
    study = create_study_from_preset("demo", "bench", status=Study.Status.OPEN)
    study.sections.update(require_full_play=False)
    return study


class Participant(threading.Thread):
    def __init__(self, base: str, slug: str, index: int, start_at: float, deadline: float):
        super().__init__(daemon=True)
        self.base, self.slug, self.index, self.start_at, self.deadline = base, slug, index, start_at, deadline
        self.answer_ms: list[float] = []
        self.page_ms: list[float] = []
        self.answered: set[tuple[int, str]] = set()      # (clip number, question) acknowledged by the server
        self.errors: list[str] = []
        self.completed = False

    def post(self, s, url, data, referer):
        return s.post(url, data=data, headers={"Referer": referer}, allow_redirects=True, timeout=30)

    def run(self):
        import requests

        s = requests.Session()
        try:
            while time.time() < self.start_at:
                time.sleep(0.001)
            entry = f"{self.base}/s/{self.slug}/?PROLIFIC_PID=bench-{self.index}"
            r = s.get(entry, timeout=30)
            r = self.post(s, entry, {"consent": "on", "csrfmiddlewaretoken": CSRF_RE.search(r.text).group(1)},
                          entry)
            if "/about-you/" in r.url:
                r = self.post(s, r.url, {"gender": "female", "age_group": "25-34",
                                         "csrfmiddlewaretoken": CSRF_RE.search(r.text).group(1)}, r.url)
            n_posts = 0
            while "/clip/" in r.url and time.time() < self.deadline:
                n = int(r.url.rstrip("/").split("/")[-1])
                if n % 5 == 0:                       # a reload before answering
                    t = time.perf_counter()
                    r = s.get(r.url, timeout=30)
                    self.page_ms.append(1000 * (time.perf_counter() - t))
                data: dict[str, str] = {}
                for _kind, name, value in INPUT_RE.findall(r.text):
                    data.setdefault(name, html.unescape(value))
                data["csrfmiddlewaretoken"] = CSRF_RE.search(r.text).group(1)
                data["rt"] = "1500"
                url = r.url
                repeats = 2 if n_posts % 4 == 3 else 1
                for _ in range(repeats):
                    t = time.perf_counter()
                    resp = s.post(url, data=data, headers={"Referer": url}, allow_redirects=False, timeout=30)
                    self.answer_ms.append(1000 * (time.perf_counter() - t))
                    if resp.status_code != 302:
                        self.errors.append(f"clip {n}: HTTP {resp.status_code}")
                n_posts += 1
                self.answered.update((n, k) for k in data if k not in ("csrfmiddlewaretoken", "rt"))
                t = time.perf_counter()
                r = s.get(self.base + resp.headers["Location"], timeout=30) if resp.status_code == 302 else r
                self.page_ms.append(1000 * (time.perf_counter() - t))
            if "/feedback/" in r.url:
                data = {"csrfmiddlewaretoken": CSRF_RE.search(r.text).group(1)}
                for tag, name, _v in FEEDBACK_RE.findall(r.text):
                    if name != "csrfmiddlewaretoken":
                        data.setdefault(name, "no" if tag == "input" else "")
                r = self.post(s, r.url, data, r.url)
            self.completed = "/done/" in r.url
        except Exception as exc:        # reported, never hidden
            self.errors.append(repr(exc))


def wait_for_server(base: str, timeout: float = 30) -> None:
    import requests

    end = time.time() + timeout
    while time.time() < end:
        try:
            if requests.get(base + "/", timeout=2).status_code == 200:
                return
        except requests.RequestException:
            time.sleep(0.2)
    raise SystemExit(f"gunicorn did not answer on {base} within {timeout} s")


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--participants", type=int, default=20)
    ap.add_argument("--workers", type=int, default=3, help="gunicorn sync workers")
    ap.add_argument("--port", type=int, default=8765)
    ap.add_argument("--db-url", default=os.environ.get("DATABASE_URL") or "postgres://postgres@127.0.0.1:5432/postgres")
    ap.add_argument("--time-limit", type=float, default=180.0, help="seconds before clients stop")
    ap.add_argument("--json", default="", help="also write the figures to this JSON file")
    args = ap.parse_args(argv)
    if not 1 <= args.participants <= 200:
        raise SystemExit("--participants must be 1..200 (bounded load test on loopback)")
    db_url, name = scratch_db_url(args.db_url)
    recreate_db(args.db_url, name)
    media_root = Path(tempfile.mkdtemp(prefix="studybench-media-"))
    study = setup_django(db_url, media_root)
    env = dict(os.environ, DATABASE_URL=db_url, MEDIA_ROOT=str(media_root), DJANGO_SETTINGS_MODULE="studyapp.settings",
               OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    gunicorn = subprocess.Popen(
        [sys.executable, "-m", "gunicorn", "studyapp.wsgi", "-w", str(args.workers), "-b", f"127.0.0.1:{args.port}",
         "--log-level", "warning", "--timeout", "60"], cwd=ROOT, env=env)
    base = f"http://127.0.0.1:{args.port}"
    try:
        wait_for_server(base)
        start = time.time() + 0.5
        clients = [Participant(base, study.slug, i, start, start + args.time_limit) for i in range(args.participants)]
        for c in clients:
            c.start()
        for c in clients:
            c.join(args.time_limit + 60)
        wall = time.time() - start
    finally:
        gunicorn.send_signal(signal.SIGTERM)
        gunicorn.wait(30)

    import csv
    import io

    from django.db import connection
    from django.db.models import Count

    from studyapp.export import stream_csv
    from studyapp.models import Participant as P
    from studyapp.models import Response

    connection.close()
    stored = Response.objects.filter(section__study=study).count()
    dup_groups = (Response.objects.filter(section__study=study)
                  .values("participant_id", "section_id", "clip_id", "question").annotate(n=Count("id"))
                  .filter(n__gt=1).count())
    expected = sum(len(c.answered) for c in clients)
    rows = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "responses")))))
    keys = [(r["participant_id"], r["section_type"], r["clip_id"], r["question"]) for r in rows]
    answer_posts = sum(len(c.answer_ms) for c in clients)
    all_answer = [x for c in clients for x in c.answer_ms]
    all_pages = [x for c in clients for x in c.page_ms]
    result = {
        "participants": args.participants, "gunicorn_workers": args.workers, "database": "postgresql",
        "completed": sum(c.completed for c in clients),
        "completed_in_db": P.objects.filter(study=study, status="completed").count(),
        "answer_posts": answer_posts, "answers_stored": stored, "answers_expected": expected,
        "lost": max(0, expected - stored), "duplicated_db": dup_groups, "csv_rows": len(rows),
        "duplicated_csv": len(keys) - len(set(keys)),
        "wall_s": round(wall, 2), "answers_per_s": round(answer_posts / wall, 1),
        "answer_post_ms_p50": round(statistics.median(all_answer), 1) if all_answer else None,
        "answer_post_ms_p99": round(percentile(all_answer, 99), 1),
        "clip_page_ms_p50": round(statistics.median(all_pages), 1) if all_pages else None,
        "clip_page_ms_p99": round(percentile(all_pages, 99), 1),
        "errors": [e for c in clients for e in c.errors][:10],
    }
    print(json.dumps(result, indent=1))
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1))
    ok = result["lost"] == 0 and result["duplicated_db"] == 0 and result["duplicated_csv"] == 0 and not result["errors"]
    if not ok:
        print("FAILED: lost, duplicated or failed requests", file=sys.stderr)
    return result


if __name__ == "__main__":
    res = main()
    sys.exit(0 if res["lost"] == 0 and res["duplicated_db"] == 0 and not res["errors"] else 1)
