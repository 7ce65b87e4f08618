"""Load test: simulated participants take the demo study over HTTP against gunicorn + PostgreSQL.

    python -m benchmarks.bench_study_load --participants 200 --arrival 30 --workers 2 --threads 8 \
        [--driver locust|threads] [--viewers 4] [--db-url postgres://postgres@127.0.0.1:5432/postgres]

Loopback only, bounded in participant count (<= 400) and time (--time-limit). It creates its own uniquely named
scratch database (`<name>_studybench_<pid>_<time>`, dropped at the end unless --keep-db), a SYNTHETIC catalogue
(dummy media files, metadata synthetic=True) and the demo study with clip playback checks off (no one watches),
and starts gunicorn (gthread workers). Then:

1. ceiling (locust driver): `/healthz` (no database, no session) as fast as the generator can for --ceiling-s:
   the requests/s of the stack itself on this machine;
2. the study: --participants arrive evenly within --arrival seconds, each with its own cookie session, and take
   the whole study: consent, demographics, every clip (GET page, POST answers), feedback, completion. Every 4th
   answer is posted twice (a double submit), every 5th clip page is reloaded before answering; --think pauses on
   each clip page before answering (default 0: as fast as the server allows). --viewers slow
   media viewers fetch a clip in 64 KiB Range requests, 4 per second each, meanwhile.

Pages are parsed generically (the post form with the most fields; radios/checkboxes take their first value, hidden
fields are kept, redirects are followed whatever their target), so the driver does not depend on the exact page
sequence. An answer POST is acknowledged by a redirect or, as the clip page's form asks for it
(studyapp.participant.views.INLINE_NEXT_FIELD), by the next clip page itself, whose form action is then the page's URL
(as the browser's study.js does). The locust driver (benchmarks/locustfile.py: gevent users, so the generator is not the
bottleneck) is the default; --driver threads runs one Python thread per participant with `requests`.

Reports answers per second (answer POSTs accepted / wall time, and answers stored / wall time), p50/p99 latency
of answer POSTs and of clip pages (GETs of a clip page: reloads, and after a redirect), the healthz ceiling and the
ratio of the study's requests/s to it, lost / duplicated answers found in the database and in the streamed
responses.csv (all must be 0), and the CPU seconds of the study phase by gunicorn, PostgreSQL (the whole local
server), the generator and the machine (Linux /proc), also per answered clip.

    python -m benchmarks.bench_study_load --server asgi --participants 0 --burst 3 --burst-size 40 --in-process 0
    python -m benchmarks.bench_study_load --driver threads --server asgi --participants 55 --kill 1 \
        [--database sqlite] [--db-connections 20]

--server asgi serves with demo.sh's asyncio workers instead of gthread; --database sqlite uses a scratch SQLite file.
On PostgreSQL the peak of the server's connections (pg_stat_activity, all databases and the scratch one) is
reported; the server's pool gets --db-connections over its --workers (DB_CONNECTIONS, WEB_CONCURRENCY). --burst W
sends W waves of --burst-size page loads released together (consent page, consent POST and its redirects) and
reports each wave's successes, 5xx and p50/p99. --kill K (threads driver) kills a worker with -9 K times during the
study; clients resend a request the kill cut off, and lost / duplicated answers and 5xx must still be 0.

    python -m benchmarks.bench_study_load --in-process-only --in-process 10 [--profile FILE]

measures only the server time, CPU time and queries of each request kind in-process (Django test client, same
scratch database set-up, no gunicorn or Locust), optionally with a cProfile of the measured participants.
"""
from __future__ import annotations

import argparse
import html
import json
import os
import random
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from urllib.parse import urlencode, urljoin, urlsplit, urlunsplit

ROOT = Path(__file__).resolve().parent.parent
LOCUSTFILE = Path(__file__).resolve().parent / "locustfile.py"

FORM_RE = re.compile(r"<form\b([^>]*)>(.*?)</form>", re.S | re.I)
FIELD_RE = re.compile(r"<(input|textarea|select|option|/select)\b([^>]*)>", re.I)
ATTR_RE = re.compile(r'([a-zA-Z_:][-\w:.]*)(?:\s*=\s*"([^"]*)")?')
TOKEN_RE = re.compile(r"/p/([^/]+)/")
CLIP_RE = re.compile(r"/clip/(\d+)/")
MAX_STEPS = 400
MEDIA_CHUNK = 64 * 1024


def percentile(values: list[float], q: float) -> float:
    if not values:
        return float("nan")
    v = sorted(values)
    k = min(len(v) - 1, max(0, int(round(q / 100 * (len(v) - 1)))))
    return v[k]


# ----------------------------------------------------------------------------------------------------- forms ---

def _attrs(text: str) -> dict[str, str]:
    return {k.lower(): html.unescape(v or "") for k, v in ATTR_RE.findall(text)}


def fill_form(page: str, url: str) -> tuple[str | None, dict[str, str], list[str]]:
    """(action URL, data, question names) for the page's main POST form: the one with the most named fields.

    Hidden fields keep their value; a radio group or checkbox takes its first value ("on" without one); a select
    its first non-empty option; text fields and textareas stay empty; a field named "rt" (response time, set by
    JavaScript in a browser) gets 1500 ms. (None, {}, []) when the page has no POST form."""
    best = None
    for form_attrs, body in FORM_RE.findall(page):
        attrs = _attrs(form_attrs)
        if attrs.get("method", "get").lower() != "post":
            continue
        data, questions = _form_fields(body)
        if best is None or len(data) > len(best[1]):
            best = (urljoin(url, attrs.get("action") or url), data, questions)
    return best if best is not None else (None, {}, [])


def _form_fields(body: str) -> tuple[dict[str, str], list[str]]:
    data: dict[str, str] = {}
    questions: list[str] = []
    select = None
    for tag, raw in FIELD_RE.findall(body):
        tag, a = tag.lower(), _attrs(raw)
        if tag == "/select":
            select = None
        elif tag == "option":
            if select and not data.get(select) and a.get("value"):
                data[select] = a["value"]
        elif tag == "select" and a.get("name"):
            select = a["name"]
            data.setdefault(select, "")
            questions.append(select)
        elif tag == "textarea" and a.get("name"):
            data.setdefault(a["name"], "")
        elif tag == "input" and a.get("name"):
            kind, name = a.get("type", "text").lower(), a["name"]
            if kind in ("submit", "button", "reset", "image", "file"):
                continue
            if kind in ("radio", "checkbox"):
                if name not in data:
                    questions.append(name)
                    data[name] = a.get("value") or "on"
            else:
                data.setdefault(name, a.get("value", ""))
    if "rt" in data:
        data["rt"] = "1500"
    return data, [q for q in dict.fromkeys(questions) if q not in ("consent",)]


# ------------------------------------------------------------------------------------------ participant flow ---

class Page:
    def __init__(self, status: int, url: str, text: str, ms: float):
        self.status, self.url, self.text, self.ms = status, url, text, ms


def follow(http, method: str, url: str, data: dict | None, name: str, hops: int = 10) -> Page:
    """Send one request and follow its redirects with GETs; ms = total time of all hops.
    http.request(method, url, data, name) -> (status, location or None, text, ms)."""
    total = 0.0
    for _ in range(hops):
        status, location, text, ms = http.request(method, url, data, name)
        total += ms
        if not (300 <= status < 400 and location):
            return Page(status, url, text, total)
        url, method, data = urljoin(url, location), "GET", None
        name = name if name.endswith("(redirect)") else name + " (redirect)"
    return Page(599, url, "too many redirects", total)


def new_record(index: int) -> dict:
    return {"index": index, "token": "", "acknowledged": [], "answer_ms": [], "page_ms": [], "answer_posts": 0,
            "errors": [], "completed": False, "start": time.time(), "end": None}


def take_study(http, base: str, slug: str, index: int, deadline: float, think_s: float = 0.0) -> dict:
    """One participant from the study link to the completion page, pausing think_s (mean; uniform 0.5x-1.5x) on
    each clip page before answering. Returns its record (JSON-able)."""
    rec = new_record(index)
    acknowledged: set[int] = set()
    link = {"PROLIFIC_PID": f"bench{index:05d}{os.getpid()}", "STUDY_ID": "bench", "SESSION_ID": f"s{index}"}
    try:
        page = follow(http, "GET", f"{base}/s/{slug}/?{urlencode(link)}", None, "consent page")
        for _ in range(MAX_STEPS):
            if "/done/" in page.url or time.time() > deadline:
                break
            if page.status >= 400:
                rec["errors"].append(f"HTTP {page.status} on {_path(page.url)}: {_snippet(page.text)}")
                break
            if m := TOKEN_RE.search(page.url):
                rec["token"] = m.group(1)
            action, data, _questions = fill_form(page.text, page.url)
            if action is None:
                rec["errors"].append(f"no form on {_path(page.url)}")
                break
            if m := CLIP_RE.search(page.url):
                if think_s > 0:
                    time.sleep(think_s * random.uniform(0.5, 1.5))      # gevent-patched under locust
                page = _answer_clip(http, page, action, data, int(m.group(1)), rec, acknowledged)
            else:
                page = follow(http, "POST", action, data, _step_name(page.url) + " POST")
        rec["completed"] = "/done/" in page.url
    except Exception as exc:        # reported, never hidden
        rec["errors"].append(repr(exc)[:300])
    rec["acknowledged"], rec["end"] = sorted(acknowledged), time.time()
    return rec


def _answer_clip(http, page: Page, action: str, data: dict, n: int, rec: dict, acknowledged: set[int]) -> Page:
    if n % 5 == 0:                                    # a reload before answering
        page = follow(http, "GET", page.url, None, "clip page")
        rec["page_ms"].append(page.ms)
        action, data, _ = fill_form(page.text, page.url)
    repeats = 2 if rec["answer_posts"] % 4 == 3 else 1
    location, status, text = None, 0, ""
    for _ in range(repeats):
        status, location, text, ms = http.request("POST", action, data, "answer POST")
        rec["answer_ms"].append(ms)
        if not (300 <= status < 400 and location) and status != 200:
            rec["errors"].append(f"clip {n}: HTTP {status} {_snippet(text)}")
    rec["answer_posts"] += 1
    if status == 200:
        # The next clip page came as the answer (studyapp.participant.views.INLINE_NEXT_FIELD); like the browser's
        # script, take its form's action as the page's URL.
        next_action, _data, _questions = fill_form(text, action)
        if next_action is None or not CLIP_RE.search(next_action):
            rec["errors"].append(f"clip {n}: HTTP 200 without a next clip page: {_snippet(text)}")
            return Page(599, page.url, text, 0.0)
        acknowledged.add(n)
        return Page(200, next_action, text, 0.0)
    if not (300 <= status < 400 and location):
        return Page(status or 599, page.url, text, 0.0)
    acknowledged.add(n)
    nxt = follow(http, "GET", urljoin(page.url, location), None, "clip page")
    rec["page_ms"].append(nxt.ms)
    return nxt


def _path(url: str) -> str:
    return TOKEN_RE.sub("/p/***/", urlsplit(url).path)


def _snippet(text: str) -> str:
    m = re.search(r'class="error"[^>]*>([^<]{0,160})', text or "")
    return (m.group(1) if m else re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", text or ""))[:160]).strip()


def _step_name(url: str) -> str:
    path = _path(url)
    return "consent" if path.startswith("/s/") else (path.rstrip("/").split("/")[-1] or "page")


# ------------------------------------------------------------------------------------ set-up and tear-down ---

def scratch_db_url(base: str) -> tuple[str, str]:
    """A unique scratch database next to base's: <name>_studybench_<pid>_<time>."""
    parts = urlsplit(base)
    name = f"{parts.path.lstrip('/') or 'postgres'}_studybench_{os.getpid()}_{int(time.time())}"
    return urlunsplit(parts._replace(path="/" + name)), name


def _admin_connection(base_url: str):
    import psycopg

    parts = urlsplit(base_url)
    return psycopg.connect(host=parts.hostname, port=parts.port or 5432, user=parts.username or "postgres",
                           password=parts.password, dbname=parts.path.lstrip("/") or "postgres", autocommit=True)


def recreate_db(base_url: str, name: str) -> None:
    with _admin_connection(base_url) as conn:
        conn.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
        conn.execute(f'CREATE DATABASE "{name}"')


def drop_db(base_url: str, name: str) -> None:
    from django.db import connections

    connections.close_all()
    with _admin_connection(base_url) as conn:
        conn.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')


def setup_django(db_url: str, media_root: Path):
    """Migrate the scratch database, insert the synthetic catalogue (every clip shares one 2 MB synthetic media
    file, so Range requests have something to read) and open the demo study with playback checks off."""
    os.environ["DATABASE_URL"] = db_url
    os.environ["MEDIA_ROOT"] = str(media_root)
    os.environ.setdefault("DJANGO_SETTINGS_MODULE", "studyapp.settings")
    import django

    django.setup()
    from django.core.management import call_command

    call_command("migrate", verbosity=0)
    from studyapp.models import Study
    from studyapp.staff.presets import create_study_from_preset
    from studyapp.testing import make_catalogue

    synthetic_media = bytes((i * 131 + 7) % 256 for i in range(2 * 1024 * 1024))
    make_catalogue(media_root, video_bytes=synthetic_media, n_gait=40, n_transition=20, n_gait_source=10,
                   n_gesture=40)
    study = create_study_from_preset("demo", "bench", status=Study.Status.OPEN, plan="test")   # make_catalogue's
    study.sections.update(require_full_play=False)
    return study


def media_urls(n: int = 4) -> list[str]:
    from studyapp.models import Clip

    return [f"/m/{key}.mp4" for key in Clip.objects.order_by("id").values_list("media_key", flat=True)[:n]]


def media_session() -> str:
    """The session key of a staff account that may see the catalogue: the media viewers are no participants, and
    clips need a session that may see them (studyapp.participant.views.media_allowed)."""
    from django.contrib.auth import BACKEND_SESSION_KEY, HASH_SESSION_KEY, SESSION_KEY, get_user_model
    from django.contrib.sessions.backends.db import SessionStore

    user, _ = get_user_model().objects.get_or_create(username="bench-media-viewer",
                                                     defaults={"is_staff": True, "is_superuser": True})
    session = SessionStore()
    session.update({SESSION_KEY: str(user.pk), BACKEND_SESSION_KEY: "django.contrib.auth.backends.ModelBackend",
                    HASH_SESSION_KEY: user.get_session_auth_hash()})
    session.create()
    return session.session_key


def start_gunicorn(args, env: dict, log: Path) -> subprocess.Popen:
    """gunicorn on 127.0.0.1:--port (--server: gthread or sync WSGI workers, or asgi: demo.sh's asyncio workers);
    its stderr (warnings, Django's error tracebacks) goes to ``log``."""
    app = "studyapp.asgi:application" if args.server == "asgi" else "studyapp.wsgi"
    cmd = [sys.executable, "-m", "gunicorn", app, "-w", str(args.workers), "-b",
           f"127.0.0.1:{args.port}", "--log-level", "warning", "--timeout", "60", "--backlog", "2048",
           # Idle keep-alive connections stay open like behind nginx (keepalive_timeout 65s); gunicorn's default
           # of 2 s closes them while a pausing participant's next POST is on its way ("connection closed").
           "--keep-alive", "75"]
    if args.server == "asgi":
        cmd += ["--worker-class", "asgi"]
    elif args.threads > 1:
        cmd += ["--worker-class", "gthread", "--threads", str(args.threads)]
    return subprocess.Popen(cmd, cwd=ROOT, env=env, stderr=open(log, "ab"))


def start_local_nginx(args, out: Path) -> tuple[str, subprocess.Popen]:
    """deploy/nginx/study.conf templated to this run (TLS with a self-signed certificate, /protected-media/ ->
    out/media) in front of gunicorn; returns its https base URL and process."""
    from deploy.nginx.local_site import free_port, start_nginx, write_local_site

    (out / "static").mkdir(exist_ok=True)
    https_port = free_port()
    conf = write_local_site(out / "nginx", out, args.port, free_port(), https_port)
    return f"https://127.0.0.1:{https_port}", start_nginx(conf)


def wait_for_server(base: str, timeout: float = 30) -> None:
    import requests
    import urllib3

    urllib3.disable_warnings(urllib3.exceptions.InsecureRequestWarning)

    end = time.time() + timeout
    while time.time() < end:
        try:
            if requests.get(base + "/healthz", timeout=2, verify=False).status_code == 200:   # self-signed
                return
        except requests.RequestException:
            time.sleep(0.2)
    raise SystemExit(f"gunicorn did not answer on {base} within {timeout} s")


# --------------------------------------------------------------------------------------------- the drivers ---

class RequestsHttp:
    """The http object of take_study for the threads driver: one requests.Session (its own cookies)."""

    def __init__(self, retries: int = 0):
        import requests

        self.session = requests.Session()
        self.retries = retries          # a request cut off (a killed worker) is sent again, as a browser would
        self.retried = 0

    def request(self, method: str, url: str, data: dict | None, name: str):
        import requests

        for attempt in range(self.retries + 1):
            t = time.perf_counter()
            try:
                r = self.session.request(method, url, data=data, headers={"Referer": url}, allow_redirects=False,
                                         timeout=60, verify=False)   # --nginx: the run's self-signed certificate
            except requests.ConnectionError:
                if attempt == self.retries:
                    raise
                self.retried += 1
                time.sleep(0.2)
                continue
            return r.status_code, r.headers.get("Location"), r.text, 1000 * (time.perf_counter() - t)


class DjangoClientHttp:
    """The http object of take_study in-process (django.test.Client, no network, no gunicorn): records the
    server-side time and the number of SQL queries of every request by name."""

    def __init__(self):
        from django.test import Client

        self.client = Client()
        self.costs: dict[str, list[tuple[float, int, float]]] = {}     # name -> [(wall ms, queries, CPU ms)]

    def request(self, method: str, url: str, data: dict | None, name: str):
        from django.db import connection
        from django.test.utils import CaptureQueriesContext

        parts = urlsplit(url)
        path = parts.path + (f"?{parts.query}" if parts.query else "")
        with CaptureQueriesContext(connection) as queries:
            t, cpu = time.perf_counter(), time.thread_time()
            r = (self.client.post(path, urlencode(data or {}), content_type="application/x-www-form-urlencoded")
                 if method == "POST" else self.client.get(path))      # url-encoded like a browser's form
            ms, cpu_ms = 1000 * (time.perf_counter() - t), 1000 * (time.thread_time() - cpu)
        self.costs.setdefault(name, []).append((ms, len(queries), cpu_ms))
        return r.status_code, r.get("Location"), r.content.decode(), ms


def in_process_costs(slug: str, n: int, profile: str = "") -> dict[str, dict]:
    """Per request kind: median server time (wall ms; cpu_ms: this Python thread's CPU time, i.e. without
    PostgreSQL's share and less sensitive to other load) and queries, from n participants taken in-process after the
    load run (the machine's other load still applies). The first participant only warms up (imports, template
    compilation, the pool cache) when n > 1. profile: also write cProfile stats of the measured participants to
    this file (read with `python -m pstats FILE`)."""
    import cProfile

    if n > 1:
        take_study(DjangoClientHttp(), "http://testserver", slug, 899_999, time.time() + 300)
    http = DjangoClientHttp()
    profiler = cProfile.Profile() if profile else None
    for i in range(n):
        if profiler:
            profiler.enable()
        take_study(http, "http://testserver", slug, 900_000 + i, time.time() + 300)
        if profiler:
            profiler.disable()
    if profiler:
        profiler.dump_stats(profile)
    return {name: {"n": len(v), "ms_p50": round(statistics.median(c[0] for c in v), 2),
                   "cpu_ms_p50": round(statistics.median(c[2] for c in v), 2),
                   "queries_p50": statistics.median(c[1] for c in v)} for name, v in sorted(http.costs.items())}


def in_process_only(args) -> dict:
    """--in-process-only: the set-up of a load run (scratch PostgreSQL database, synthetic catalogue, demo study)
    and the in-process costs, without gunicorn or Locust."""
    db_url, name = scratch_db_url(args.db_url)
    recreate_db(args.db_url, name)
    out = Path(tempfile.mkdtemp(prefix="studybench-"))
    try:
        study = setup_django(db_url, out / "media")
        return {"in_process": in_process_costs(study.slug, max(args.in_process, 1), args.profile),
                "load_average_1m": round(os.getloadavg()[0], 1)}
    finally:
        if not args.keep_db:
            drop_db(args.db_url, name)


def run_threads(args, base: str, slug: str, gunicorn_pid: int | None = None) -> list[dict]:
    """The thread driver: one thread per participant, started evenly over --arrival seconds. With --kill K a
    gunicorn worker is killed with SIGKILL K times while answers are in flight (evenly over the arrival time);
    clients then retry a cut-off request (connection error) up to 5 times."""
    start = time.time() + 0.5
    deadline = start + args.arrival + args.time_limit
    records: list[dict] = []
    retried = []

    def one(i: int):
        time.sleep(max(0.0, start + i * args.arrival / args.participants - time.time()))
        http = RequestsHttp(retries=5 if args.kill else 0)
        records.append(take_study(http, base, slug, i, deadline, args.think))
        retried.append(http.retried)

    threads = [threading.Thread(target=one, args=(i,), daemon=True) for i in range(args.participants)]
    for t in threads:
        t.start()
    kills = 0
    while kills < args.kill and gunicorn_pid and any(t.is_alive() for t in threads):
        time.sleep(max(0.5, args.arrival / (args.kill + 1)))
        workers = [int(p) for p in subprocess.run(["pgrep", "-P", str(gunicorn_pid)], capture_output=True,
                                                  text=True).stdout.split()]
        if workers:
            os.kill(workers[kills % len(workers)], signal.SIGKILL)
            kills += 1
    for t in threads:
        t.join(args.arrival + args.time_limit + 60)
    if records:
        records[0]["kills"], records[0]["retried"] = kills, sum(retried)
    return records


class ConnectionSampler(threading.Thread):
    """Polls pg_stat_activity every 50 ms: the peak number of the server's connections (all databases, as
    max_connections counts them) and of the scratch database's."""

    def __init__(self, admin_url: str, dbname: str):
        super().__init__(daemon=True)
        self.admin_url, self.dbname = admin_url, dbname
        self.stop, self.peak_total, self.peak_db, self.baseline_total = threading.Event(), 0, 0, None

    def run(self):
        with _admin_connection(self.admin_url) as conn:
            while not self.stop.is_set():
                total, ours = conn.execute("SELECT count(*), count(*) FILTER (WHERE datname = %s) "
                                           "FROM pg_stat_activity", [self.dbname]).fetchone()
                if self.baseline_total is None:
                    self.baseline_total = total
                self.peak_total, self.peak_db = max(self.peak_total, total), max(self.peak_db, ours)
                time.sleep(0.05)

    def result(self) -> dict:
        self.stop.set()
        self.join(5)
        return {"db_connections_before": self.baseline_total, "db_connections_peak_server": self.peak_total,
                "db_connections_peak_study_db": self.peak_db,
                "max_connections": _max_connections(self.admin_url)}


def _max_connections(admin_url: str) -> int:
    with _admin_connection(admin_url) as conn:
        return int(conn.execute("SHOW max_connections").fetchone()[0])


def page_load(base: str, slug: str, index: int) -> tuple[int, float]:
    """One participant's first page loads: the consent page (a new session), the consent POST and the pages it
    redirects to (the participant is created and started). (last status, total ms)."""
    http = RequestsHttp()
    link = {"PROLIFIC_PID": f"burst{index:05d}{os.getpid()}", "STUDY_ID": "burst", "SESSION_ID": f"b{index}"}
    t = time.perf_counter()
    try:
        page = follow(http, "GET", f"{base}/s/{slug}/?{urlencode(link)}", None, "consent page")
        if page.status == 200:
            action, data, _ = fill_form(page.text, page.url)
            if action:
                page = follow(http, "POST", action, data, "consent POST")
        status = page.status
    except Exception:        # connection refused or reset: counted as a failed load
        status = 0
    return status, 1000 * (time.perf_counter() - t)


def run_burst(args, base: str, slug: str) -> dict:
    """--burst W: W waves of --burst-size concurrent page loads (page_load), one wave after the other."""
    waves = []
    for w in range(args.burst):
        results: list[tuple[int, float]] = []
        barrier = threading.Barrier(args.burst_size)

        def one(i: int, w=w, results=results, barrier=barrier):
            barrier.wait()
            results.append(page_load(base, slug, 10_000 * (w + 1) + i))

        threads = [threading.Thread(target=one, args=(i,), daemon=True) for i in range(args.burst_size)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(120)
        statuses = [s for s, _ in results]
        ms = [m for _, m in results]
        waves.append({"wave": w + 1, "loads": len(results), "ok": statuses.count(200),
                      "status_5xx": sum(500 <= s < 600 for s in statuses), "failed": sum(s == 0 for s in statuses),
                      "status_503": statuses.count(503), "ms_p50": round(statistics.median(ms), 1),
                      "ms_p99": round(percentile(ms, 99), 1)})
    return {"burst": waves}


def _locust(args, base: str, env: dict, users: list[str], n_users: int, rate: float, run_s: float, csv: str,
            results: Path | None = None, expected: int = 0) -> None:
    """Run locust headless on LOCUSTFILE; stops it once `expected` records are in `results` (or at run_s)."""
    cmd = [sys.executable, "-m", "locust", "-f", str(LOCUSTFILE), "--headless", "--host", base, "-u", str(n_users),
           "-r", f"{rate:.3f}", "-t", f"{int(run_s)}s", "--csv", csv, "--only-summary", "--loglevel", "WARNING",
           "--stop-timeout", "5", *users]
    if args.processes > 1:
        cmd[3:3] = ["--processes", str(args.processes)]
    proc = subprocess.Popen(cmd, cwd=ROOT, env=env, start_new_session=True)
    while proc.poll() is None:
        if results is not None and expected and results.exists() and \
                sum(1 for _ in results.open()) >= expected:
            proc.send_signal(signal.SIGTERM)
            break
        time.sleep(0.5)
    try:
        proc.wait(30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()


def locust_rows(csv_prefix: str) -> dict[str, dict]:
    import csv

    path = Path(csv_prefix + "_stats.csv")
    if not path.exists():
        return {}
    with open(path) as fh:
        return {f"{row['Type']} {row['Name']}".strip(): row for row in csv.DictReader(fh)}


# ------------------------------------------------------------------------------------------ CPU accounting ---

CLOCK_TICKS = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


def _stat_fields(pid: int) -> list[str]:
    """/proc/<pid>/stat from field 3 (state) on; [] when the process is gone."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return []


def tree_cpu_s(pid: int) -> float:
    """CPU seconds of a process tree: every live process's own time and its reaped children's."""
    total = 0.0
    for p in process_tree(pid):
        fields = _stat_fields(p)
        total += sum(int(v) for v in fields[11:15]) / CLOCK_TICKS if fields else 0.0
    return total


def process_tree(pid: int) -> list[int]:
    """pid and its descendants (Linux /proc/<pid>/task/*/children)."""
    pids, todo = [], [pid]
    while todo:
        p = todo.pop()
        pids.append(p)
        for task in Path(f"/proc/{p}/task").glob("*"):      # nothing when p is gone
            try:
                todo += [int(c) for c in (task / "children").read_text().split()]
            except OSError:
                pass
    return pids


def postmaster_pid() -> int | None:
    """The PostgreSQL server's main process (the parent of this process's backend), when it runs on this machine."""
    from django.db import connection

    with connection.cursor() as cursor:
        cursor.execute("SELECT pg_backend_pid()")
        backend = cursor.fetchone()[0]
    fields = _stat_fields(backend)
    return int(fields[1]) if fields else None


def machine_busy_s() -> float:
    """CPU seconds the whole machine has been busy (all cores; /proc/stat, idle and iowait excluded)."""
    values = [int(v) for v in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    return (sum(values[:8]) - values[3] - values[4]) / CLOCK_TICKS


class CpuMeter:
    """CPU seconds spent during the study phase by gunicorn (master and workers), PostgreSQL (the whole server:
    backends, also those that exited, and its background processes), the load generator (children of this process
    reaped meanwhile: locust) and the machine."""

    def __init__(self, gunicorn_pid: int):
        import resource

        self._resource = resource
        self.gunicorn_pid, self.postmaster = gunicorn_pid, postmaster_pid()
        self.gunicorn0 = tree_cpu_s(gunicorn_pid)
        self.postgres0 = tree_cpu_s(self.postmaster) if self.postmaster else 0.0
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        self.children0 = usage.ru_utime + usage.ru_stime
        self.machine0, self.t0 = machine_busy_s(), time.time()
        self.result: dict = {}

    def stop_servers(self) -> None:
        """Read gunicorn's and PostgreSQL's share (call while gunicorn still runs)."""
        gunicorn = tree_cpu_s(self.gunicorn_pid) - self.gunicorn0
        postgres = tree_cpu_s(self.postmaster) - self.postgres0 if self.postmaster else float("nan")
        self.result.update(cpu_s_gunicorn=round(gunicorn, 1), cpu_s_postgres=round(postgres, 1),
                           cpu_s_machine=round(machine_busy_s() - self.machine0, 1),
                           cpu_wall_s=round(time.time() - self.t0, 1))

    def stop_generator(self) -> None:
        """Read the generator's share (call once locust has been reaped)."""
        usage = self._resource.getrusage(self._resource.RUSAGE_CHILDREN)
        self.result["cpu_s_generator"] = round(usage.ru_utime + usage.ru_stime - self.children0, 1)


def run_ceiling(args, base: str, env: dict, out: Path) -> dict:
    prefix = str(out / "ceiling")
    _locust(args, base, env, ["HealthUser"], args.ceiling_users, args.ceiling_users, args.ceiling_s, prefix)
    row = locust_rows(prefix).get("Aggregated", {})
    return {"healthz_requests_per_s": round(float(row.get("Requests/s", "nan")), 1),
            "healthz_ms_p50": row.get("50%"), "healthz_ms_p99": row.get("99%"),
            "healthz_failures": int(row.get("Failure Count", 0) or 0)}


def run_locust_study(args, base: str, env: dict, out: Path, slug: str, meter: CpuMeter | None = None
                     ) -> tuple[list[dict], dict]:
    results = out / "participants.jsonl"
    env = dict(env, STUDY_BENCH_SLUG=slug, STUDY_BENCH_RESULTS=str(results), STUDY_BENCH_VIEWERS=str(args.viewers),
               STUDY_BENCH_PARTICIPANTS=str(args.participants), STUDY_BENCH_TICKETS=str(out / "tickets"),
               STUDY_BENCH_THINK=str(args.think),
               STUDY_BENCH_MEDIA=",".join(media_urls()), STUDY_BENCH_MEDIA_SESSION=media_session(),
               STUDY_BENCH_DEADLINE=str(time.time() + args.arrival +
                                                                                   args.time_limit + 30))
    users = ["StudyParticipant"] + (["MediaViewer"] if args.viewers else [])
    n_users = args.participants + args.viewers
    _locust(args, base, env, users, n_users, n_users / args.arrival, args.arrival + args.time_limit + 30,
            str(out / "study"), results, args.participants)
    if meter is not None:
        meter.stop_generator()
    records = [json.loads(line) for line in results.open()] if results.exists() else []
    return records, locust_rows(str(out / "study"))


# ------------------------------------------------------------------------------------------------ results ---

def database_checks(study, records: list[dict]) -> dict:
    """Lost = clips the server acknowledged (a redirect or the next clip page after the answer POST) that are not
    answered in the database;
    duplicated = (participant, section, clip, question) groups with more than one row, in the DB and the CSV."""
    import csv
    import io

    from django.db import connection
    from django.db.models import Count, Exists, OuterRef

    from studyapp.data.export import stream_csv
    from studyapp.models import Assignment, Participant, Response

    connection.close()
    answered = dict(Assignment.objects.filter(section__study=study, answered_at__isnull=False)
                    .values_list("participant__token").annotate(n=Count("id")))
    lost = sum(max(0, len(r["acknowledged"]) - answered.get(r["token"], 0)) for r in records)
    responses = Response.objects.filter(section__study=study)
    rows_of = Response.objects.filter(participant=OuterRef("participant"), section=OuterRef("section"),
                                      clip=OuterRef("clip"))
    silent = Assignment.objects.filter(section__study=study, answered_at__isnull=False).filter(~Exists(rows_of))
    if hasattr(Assignment, "Kind") and hasattr(Assignment.Kind, "PRACTICE"):
        silent = silent.exclude(kind=Assignment.Kind.PRACTICE)      # practice items store no answers by design
    rows = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "responses")))))
    keys = [(r.get("participant_id"), r.get("section_type"), r.get("clip_id"), r.get("question")) for r in rows]
    return {
        "completed_in_db": Participant.objects.filter(study=study, status="completed").count(),
        "answers_stored": responses.count(), "assignments_answered": sum(answered.values()),
        "acknowledged_clips": sum(len(r["acknowledged"]) for r in records), "lost": lost,
        "answered_without_rows": silent.count(),
        "duplicated_db": responses.values("participant_id", "section_id", "clip_id", "question")
        .annotate(n=Count("id")).filter(n__gt=1).count(),
        "csv_rows": len(rows), "duplicated_csv": len(keys) - len(set(keys)),
    }


def summarise(args, records: list[dict], checks: dict, ceiling: dict, stats: dict) -> dict:
    starts = [r["start"] for r in records]
    ends = [r["end"] for r in records if r.get("end")]
    wall = (max(ends) - min(starts)) if starts and ends else float("nan")
    answers = [x for r in records for x in r["answer_ms"]]
    pages = [x for r in records for x in r["page_ms"]]
    agg = stats.get("Aggregated", {})
    total_requests = int(agg.get("Request Count", 0) or 0)
    study_rps = total_requests / wall if total_requests and wall == wall else None
    ceiling_rps = ceiling.get("healthz_requests_per_s")
    media = stats.get("GET media range", {})
    return {
        "driver": args.driver, "participants": args.participants, "arrival_s": args.arrival, "think_s": args.think,
        "gunicorn": (f"{args.workers} ASGI workers" if args.server == "asgi" else
                     f"{args.workers} workers x {args.threads} threads" + (" (gthread)" if args.threads > 1 else "")),
        "status_5xx": sum(bool(re.search(r"HTTP 5\d\d", e)) for r in records for e in r["errors"]),
        "kills": records[0].get("kills", 0) if records else 0,
        "retried_requests": records[0].get("retried", 0) if records else 0,
        "nginx": bool(args.nginx),
        "locust_processes": args.processes if args.driver == "locust" else None, "viewers": args.viewers,
        "database": args.database, "completed": sum(bool(r["completed"]) for r in records),
        "records": len(records), "wall_s": round(wall, 2),
        "answer_posts": len(answers), "answer_posts_per_s": round(len(answers) / wall, 1) if answers else 0,
        "answers_stored_per_s": round(checks["answers_stored"] / wall, 1) if wall == wall else None,
        "answer_post_ms_p50": round(statistics.median(answers), 1) if answers else None,
        "answer_post_ms_p99": round(percentile(answers, 99), 1) if answers else None,
        "clip_page_ms_p50": round(statistics.median(pages), 1) if pages else None,
        "clip_page_ms_p99": round(percentile(pages, 99), 1) if pages else None,
        "media_range_requests": int(media.get("Request Count", 0) or 0),
        "media_range_ms_p50": media.get("50%"), "media_range_ms_p99": media.get("99%"),
        "study_requests": total_requests, "study_requests_per_s": round(study_rps, 1) if study_rps else None,
        **ceiling,
        "study_to_ceiling_ratio": round(study_rps / ceiling_rps, 2) if study_rps and ceiling_rps else None,
        **checks,
        "errors": [e for r in records for e in r["errors"]][:10],
        "n_errors": sum(len(r["errors"]) for r in records),
        "load_average_1m": round(os.getloadavg()[0], 1),
    }


def cpu_per_answered_clip(cpu: dict, result: dict) -> dict:
    """CPU milliseconds per answered clip (acknowledged answer) of gunicorn, PostgreSQL and the generator, and
    the share of the machine's busy time that none of them used (other jobs)."""
    clips = result.get("acknowledged_clips") or 0
    if not clips or "cpu_s_gunicorn" not in cpu:
        return {}
    ours = cpu["cpu_s_gunicorn"] + cpu["cpu_s_postgres"] + cpu.get("cpu_s_generator", 0.0)
    return {f"cpu_ms_per_clip_{k}": round(1000 * cpu[f"cpu_s_{k}"] / clips, 2)
            for k in ("gunicorn", "postgres", "generator") if f"cpu_s_{k}" in cpu} | {
        "cpu_s_other_jobs": round(max(cpu["cpu_s_machine"] - ours, 0.0), 1)}


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--participants", type=int, default=200)
    ap.add_argument("--arrival", type=float, default=30.0, help="seconds over which the participants arrive")
    ap.add_argument("--driver", choices=["locust", "threads"], default="locust")
    ap.add_argument("--processes", type=int, default=1, help="locust generator processes (--processes)")
    ap.add_argument("--viewers", type=int, default=4, help="slow media viewers (locust driver)")
    ap.add_argument("--think", type=float, default=0.0,
                    help="mean seconds a participant spends on a clip page before answering (0: as fast as possible)")
    ap.add_argument("--workers", type=int, default=2, help="gunicorn worker processes")
    ap.add_argument("--threads", type=int, default=8, help="threads per worker (gthread; 1 = sync workers)")
    ap.add_argument("--server", choices=["gthread", "asgi"], default="gthread",
                    help="gunicorn workers: threaded WSGI (the nginx recipe) or asyncio ASGI (demo.sh)")
    ap.add_argument("--database", choices=["postgresql", "sqlite"], default="postgresql",
                    help="sqlite: a scratch SQLite file (no connection figures)")
    ap.add_argument("--db-connections", type=int, default=20,
                    help="DB_CONNECTIONS of the server: its PostgreSQL pool over all --workers")
    ap.add_argument("--burst", type=int, default=0,
                    help="waves of --burst-size concurrent page loads (consent page + consent) before the study")
    ap.add_argument("--burst-size", type=int, default=40)
    ap.add_argument("--kill", type=int, default=0,
                    help="threads driver: kill a gunicorn worker with -9 this many times during the study")
    ap.add_argument("--ceiling-s", type=float, default=15.0, help="seconds of the /healthz ceiling run")
    ap.add_argument("--ceiling-users", type=int, default=32)
    ap.add_argument("--port", type=int, default=8765)
    ap.add_argument("--nginx", action="store_true",
                    help="put deploy/nginx/study.conf (TLS, X-Accel-Redirect media) in front of gunicorn")
    ap.add_argument("--db-url", default=os.environ.get("DATABASE_URL") or "postgres://postgres@127.0.0.1:5432/postgres")
    ap.add_argument("--time-limit", type=float, default=300.0,
                    help="seconds after the last arrival before clients stop")
    ap.add_argument("--keep-db", action="store_true", help="keep the scratch database")
    ap.add_argument("--in-process", type=int, default=2,
                    help="afterwards, participants taken in-process to measure each request's server time and queries")
    ap.add_argument("--in-process-only", action="store_true",
                    help="measure only the in-process costs (--in-process participants): no gunicorn, no Locust")
    ap.add_argument("--profile", default="", help="with --in-process-only: write cProfile stats to this file")
    ap.add_argument("--json", default="", help="also write the figures to this JSON file")
    args = ap.parse_args(argv)
    if not (1 if not args.burst else 0) <= args.participants <= 400 or not 0 <= args.burst * args.burst_size <= 400:
        raise SystemExit("--participants must be 1..400 (0 with --burst), --burst x --burst-size at most 400 "
                         "(bounded load test on loopback)")
    return args


def stop(proc: subprocess.Popen, grace_s: float = 40) -> None:
    """SIGTERM, then SIGKILL after grace_s (gunicorn's graceful timeout is 30 s)."""
    proc.send_signal(signal.SIGTERM)
    try:
        proc.wait(grace_s)
    except subprocess.TimeoutExpired:
        print(f"pid {proc.pid} did not stop within {grace_s} s of SIGTERM: killed", file=sys.stderr)
        for pid in [int(p) for p in subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True,
                                                    text=True).stdout.split()]:
            os.kill(pid, signal.SIGKILL)
        proc.kill()
        proc.wait()


def main(argv=None) -> dict:
    args = parse_args(argv)
    if args.in_process_only:
        result = in_process_only(args)
        print(json.dumps(result, indent=1))
        if args.json:
            Path(args.json).write_text(json.dumps(result, indent=1))
        return result
    postgres = args.database == "postgresql"
    out = Path(tempfile.mkdtemp(prefix="studybench-"))
    if postgres:
        db_url, name = scratch_db_url(args.db_url)
        recreate_db(args.db_url, name)
    else:
        db_url, name = "", ""
        os.environ.pop("DATABASE_URL", None)
        os.environ["DATA_DIR"] = str(out)            # a scratch SQLite file, out/db.sqlite3
    try:
        study = setup_django(db_url, out / "media")
        env = dict(os.environ, MEDIA_ROOT=str(out / "media"), DATA_DIR=str(out),
                   DJANGO_SETTINGS_MODULE="studyapp.settings", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1",
                   DB_CONNECTIONS=str(args.db_connections), WEB_CONCURRENCY=str(args.workers),
                   # every simulated participant comes from 127.0.0.1: the start rate limit (measured by
                   # bench_start_rate.py) would admit only its burst
                   START_RATE_BURST="0")
        if postgres:
            env["DATABASE_URL"] = db_url
        else:
            env.pop("DATABASE_URL", None)
        base, nginx = f"http://127.0.0.1:{args.port}", None
        if args.nginx:
            env["MEDIA_ACCEL_REDIRECT"] = "/protected-media/"
            base, nginx = start_local_nginx(args, out)
        gunicorn = start_gunicorn(args, env, out / "gunicorn.log")
        sampler = ConnectionSampler(args.db_url, name) if postgres else None
        burst: dict = {}
        try:
            wait_for_server(base)
            if sampler is not None:
                sampler.start()
            if args.burst:
                burst = run_burst(args, base, study.slug)
            ceiling, stats, meter, records = {}, {}, None, []
            if args.participants and args.driver == "locust":
                ceiling = run_ceiling(args, base, env, out)
                meter = CpuMeter(gunicorn.pid)
                records, stats = run_locust_study(args, base, env, out, study.slug, meter)
                meter.stop_servers()
            elif args.participants:
                records = run_threads(args, base, study.slug, gunicorn.pid)
        finally:
            for proc in (nginx, gunicorn):
                if proc is not None:
                    stop(proc)
        connections = sampler.result() if sampler is not None else {}
        result = {"server": args.server, "database": args.database, "workers": args.workers,
                  "db_connections_setting": args.db_connections if postgres else None, **connections, **burst}
        if records:
            result.update(summarise(args, records, database_checks(study, records), ceiling, stats))
        if meter is not None:
            result.update(meter.result, **cpu_per_answered_clip(meter.result, result))
        result["gunicorn_log"] = str(out / "gunicorn.log")
        result["gunicorn_log_tracebacks"] = (out / "gunicorn.log").read_text(errors="replace").count("Traceback")
        if args.in_process and records:
            result["in_process"] = in_process_costs(study.slug, args.in_process)
    finally:
        if postgres and not args.keep_db:
            drop_db(args.db_url, name)
    print(json.dumps(result, indent=1))
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1))
    return result


def passed(result: dict) -> bool:
    if any(w["status_5xx"] or w["failed"] for w in result.get("burst", [])):
        return False
    if "lost" not in result:                   # a burst only
        return True
    return (result["lost"] == 0 and result["status_5xx"] == 0 and result["duplicated_db"] == 0
            and result["duplicated_csv"] == 0
            and result["answered_without_rows"] == 0 and not result["errors"]
            and result["completed"] == result["participants"])


if __name__ == "__main__":
    res = main()
    if "in_process" in res and "lost" not in res and "burst" not in res:     # --in-process-only
        sys.exit(0)
    if not passed(res):
        print("FAILED: lost, duplicated, incomplete or failed requests", file=sys.stderr)
    sys.exit(0 if passed(res) else 1)
