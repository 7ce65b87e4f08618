"""Start rate limit (studyapp.participant.start_throttle) against the demo's server configuration: 200 Prolific-like
starts in one minute, each from its own address, and a scripted flood of starts from one address.

Starts gunicorn ``studyapp.asgi:application -k asgi`` (2 workers, TRUSTED_PROXY_COUNT=1 as behind nginx, the default
START_RATE_BURST / START_RATE_INTERVAL_S unless given) on a scratch SQLite database with an open study. A start is
what a participant's browser does: GET the consent page from the study link (PROLIFIC_PID, STUDY_ID, SESSION_ID),
then POST the consent form with its CSRF token and consent key; admitted = 302 to the participant's pages, slowed =
429. The Prolific phase spreads 200 starts evenly over --prolific-seconds (default 55), each with its own
X-Forwarded-For address and PID; the flood phase then sends --flood starts from one address, 4 at a time, as fast
as the server answers. Prints one JSON object. Example:

    .venv/bin/python -m benchmarks.bench_start_rate
"""
from __future__ import annotations

import argparse
import http.client
import json
import os
import re
import secrets
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from benchmarks.local_server import free_port, wait_for_server

ROOT = Path(__file__).resolve().parent.parent
SETUP = """
from studyapp.staff.presets import create_study_from_preset
create_study_from_preset("rbf_thms2016", "rate", plan="test", status="open")
"""


def start(port: int, address: str, pid: str) -> tuple[int, float]:
    """One participant's consent from the study link: (status of the consent POST, its seconds)."""
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
    link = f"/s/rate/?PROLIFIC_PID={pid}&STUDY_ID=bench&SESSION_ID=s-{pid}"
    headers = {"X-Forwarded-For": address}
    try:
        conn.request("GET", link, headers=headers)
        r = conn.getresponse()
        page = r.read().decode()
        cookies = "; ".join(c.split(";")[0] for c in r.headers.get_all("Set-Cookie") or [])
        token = re.search(r'name="csrfmiddlewaretoken" value="([^"]+)"', page)
        key = re.search(r'name="consent_key" value="([^"]+)"', page)
        if r.status != 200 or not token:
            return r.status, 0.0
        body = (f"csrfmiddlewaretoken={token.group(1)}&consent=on&consent_key={key.group(1) if key else ''}"
                f"&PROLIFIC_PID={pid}&STUDY_ID=bench&SESSION_ID=s-{pid}")
        t0 = time.perf_counter()
        conn.request("POST", link, body=body, headers={
            **headers, "Content-Type": "application/x-www-form-urlencoded", "Cookie": cookies,
            "Referer": f"http://127.0.0.1:{port}{link}"})
        r = conn.getresponse()
        r.read()
        return r.status, time.perf_counter() - t0
    except (OSError, http.client.HTTPException):
        return 0, 0.0
    finally:
        conn.close()


def summary(results: list[tuple[int, float]], seconds: float) -> dict:
    times = sorted(t for s, t in results if s in (302, 429))
    return {"starts": len(results), "admitted": sum(s == 302 for s, _ in results),
            "slowed_429": sum(s == 429 for s, _ in results),
            "other": sum(s not in (302, 429) for s, _ in results), "seconds": round(seconds, 1),
            "post_p50_ms": round(statistics.median(times) * 1000, 1) if times else None,
            "post_p99_ms": round(times[min(len(times) - 1, int(0.99 * len(times)))] * 1000, 1) if times else None}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--prolific", type=int, default=200)
    ap.add_argument("--prolific-seconds", type=float, default=55.0)
    ap.add_argument("--flood", type=int, default=100)
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bench-start-") as tmp:
        env = dict(os.environ, DATA_DIR=tmp, SECRET_KEY=secrets.token_urlsafe(50), DEBUG="0",
                   ALLOWED_HOSTS="127.0.0.1", TRUSTED_PROXY_COUNT="1", OMP_NUM_THREADS="1")
        env.pop("DATABASE_URL", None)
        manage = [sys.executable, str(ROOT / "manage.py")]
        subprocess.run(manage + ["migrate", "--noinput", "-v", "0"], env=env, cwd=ROOT, check=True)
        subprocess.run(manage + ["shell", "-c", SETUP], env=env, cwd=ROOT, check=True)
        port = free_port()
        log = Path(tmp) / "gunicorn.log"
        server = subprocess.Popen([sys.executable, "-m", "gunicorn", "studyapp.asgi:application", "-k", "asgi",
                                   "-w", str(args.workers), "-b", f"127.0.0.1:{port}"], env=env, cwd=ROOT,
                                  stdout=subprocess.DEVNULL, stderr=log.open("wb"))
        try:
            wait_for_server(server, port, log)
            gap = args.prolific_seconds / args.prolific
            t0 = time.perf_counter()

            def arrive(i: int):
                time.sleep(max(0.0, t0 + i * gap - time.perf_counter()))
                return start(port, f"10.{i // 250}.{i % 250}.{1 + i % 200}", f"prolific{i:04d}")

            with ThreadPoolExecutor(32) as pool:
                prolific = list(pool.map(arrive, range(args.prolific)))
            prolific_s = time.perf_counter() - t0
            t1 = time.perf_counter()
            with ThreadPoolExecutor(4) as pool:
                flood = list(pool.map(lambda i: start(port, "203.0.113.66", f"script{i:04d}"), range(args.flood)))
            flood_s = time.perf_counter() - t1
        finally:
            server.terminate()
            server.wait(30)
    print(json.dumps({"prolific": summary(prolific, prolific_s), "flood_one_address": summary(flood, flood_s),
                      "burst": int(env.get("START_RATE_BURST", 6)),
                      "interval_s": int(env.get("START_RATE_INTERVAL_S", 20)), "workers": args.workers}))


if __name__ == "__main__":
    main()
