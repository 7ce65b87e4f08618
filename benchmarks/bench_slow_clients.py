"""Slow-client benchmark: participant page latency while slow clients trickle requests into the server.

Sets up a scratch SQLite study (synthetic catalogue, the "demo" preset at /s/demo/) in a temporary DATA_DIR,
starts gunicorn the way a configuration serves it (--server, see SERVERS), then

1. measures GET /s/demo/ and GET /healthz (a fresh connection each, --probe-interval apart) for --warmup s alone;
2. opens --clients slow connections (half send a request header, half a POST body of 1000 bytes, one byte every
   --interval s; each reconnects when the server closes it) and measures the same pages for --seconds s.

Prints per phase: probes, p50 / p99 / max latency in ms and the number that failed or took longer than
--probe-timeout (25 s, the probe of the security review). The target for a public study: p99 < 200 ms under
attack. Example:

    .venv/bin/python -m benchmarks.bench_slow_clients --server gthread --server asgi --seconds 30
"""
from __future__ import annotations

import argparse
import http.client
import os
import secrets
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

SERVERS = {
    # demo.sh before: threaded WSGI workers read each request in a worker thread, byte by byte
    "gthread": ["studyapp.wsgi", "-w", "2", "--worker-class", "gthread", "--threads", "4"],
    # asyncio workers read requests on the event loop; Django's views run in threads once a request is complete
    "asgi": ["studyapp.asgi:application", "-w", "2", "--worker-class", "asgi"],
}

SETUP = """
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue
from django.conf import settings
make_catalogue(settings.MEDIA_ROOT)
create_study_from_preset("demo", "demo", plan="test", status="open")
"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def scratch_env(data_dir: Path) -> dict:
    env = dict(os.environ, DATA_DIR=str(data_dir), SECRET_KEY=secrets.token_urlsafe(50), DEBUG="0",
               ALLOWED_HOSTS="127.0.0.1,localhost", OMP_NUM_THREADS="1")
    env.pop("DATABASE_URL", None)
    env.pop("PRODUCTION", None)
    return env


def prepare(env: dict) -> None:
    """Migrate the scratch database and create the demo study on a synthetic catalogue."""
    manage = [sys.executable, str(ROOT / "manage.py")]
    subprocess.run(manage + ["migrate", "--noinput", "-v", "0"], env=env, cwd=ROOT, check=True)
    subprocess.run(manage + ["shell", "-c", SETUP], env=env, cwd=ROOT, check=True)


def start_server(name: str, port: int, env: dict, log: Path) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "gunicorn", *SERVERS[name], "-b", f"127.0.0.1:{port}"]
    proc = subprocess.Popen(cmd, env=env, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=open(log, "wb"))
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise SystemExit(f"gunicorn ({name}) exited: see {log}")
        try:
            if probe(port, "/healthz", 2.0) is not None:
                return proc
        except OSError:
            pass
        time.sleep(0.3)
    proc.kill()
    raise SystemExit(f"gunicorn ({name}) did not answer within 60 s")


def probe(port: int, path: str, timeout: float) -> float | None:
    """Seconds for one GET on a fresh connection; None when it failed or timed out."""
    t0 = time.perf_counter()
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    try:
        conn.request("GET", path)
        r = conn.getresponse()
        r.read()
        return time.perf_counter() - t0 if r.status == 200 else None
    except (OSError, http.client.HTTPException):
        return None
    finally:
        conn.close()


def slow_client(port: int, body: bool, interval: float, stop: threading.Event, sent: list[int]) -> None:
    """Trickle one request a byte at a time: a header that never ends, or a POST whose body never completes."""
    head = b"GET /s/demo/ HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: "
    if body:
        head = (b"POST /s/demo/ HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/x-www-form-urlencoded\r\n"
                b"Content-Length: 1000\r\n\r\n")
    while not stop.is_set():
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
                if body:
                    s.sendall(head)
                    trickle = b"a" * 1000
                else:
                    s.sendall(head[:1])
                    trickle = head[1:] + b"x" * 10000
                for byte in trickle:
                    if stop.wait(interval):
                        return
                    s.sendall(bytes([byte]))
                    sent[0] += 1
        except OSError:
            stop.wait(0.2)       # closed by the server: come back


def measure(port: int, seconds: float, every: float, timeout: float) -> dict:
    times, failed = [], 0
    end = time.monotonic() + seconds
    paths = ["/s/demo/", "/healthz"]
    i = 0
    while time.monotonic() < end:
        t = probe(port, paths[i % 2], timeout)
        i += 1
        if t is None or t >= timeout:
            failed += 1
        else:
            times.append(t)
        time.sleep(every)
    times.sort()

    def pct(q: float) -> float:
        return round(1000 * times[min(len(times) - 1, int(q * len(times)))], 1) if times else float("nan")

    return {"probes": i, "p50_ms": pct(0.50), "p99_ms": pct(0.99),
            "max_ms": round(1000 * times[-1], 1) if times else float("nan"), "failed": failed}


def run(name: str, args, env: dict, log_dir: Path) -> list[dict]:
    port = free_port()
    proc = start_server(name, port, env, log_dir / f"gunicorn-{name}.log")
    try:
        rows = [dict(server=name, phase="alone", **measure(port, args.warmup, args.probe_interval,
                                                            args.probe_timeout))]
        stop, sent = threading.Event(), [0]
        threads = [threading.Thread(target=slow_client, args=(port, i % 2 == 1, args.interval, stop, sent),
                                    daemon=True) for i in range(args.clients)]
        for t in threads:
            t.start()
        time.sleep(args.interval * 2)       # the slow requests are in the server before measuring
        row = measure(port, args.seconds, args.probe_interval, args.probe_timeout)
        stop.set()
        rows.append(dict(server=name, phase=f"{args.clients} slow clients", **row, slow_bytes=sent[0]))
        return rows
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--server", action="append", choices=sorted(SERVERS),
                    help="gunicorn configuration(s) to measure (default: all)")
    ap.add_argument("--clients", type=int, default=10)
    ap.add_argument("--interval", type=float, default=2.0, help="seconds between two bytes of a slow client")
    ap.add_argument("--seconds", type=float, default=30.0, help="measuring time under attack")
    ap.add_argument("--warmup", type=float, default=5.0, help="measuring time without attack")
    ap.add_argument("--probe-interval", type=float, default=0.1)
    ap.add_argument("--probe-timeout", type=float, default=25.0)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="slow-clients-") as tmp:
        env = scratch_env(Path(tmp))
        prepare(env)
        rows = []
        for name in args.server or sorted(SERVERS):
            rows += run(name, args, env, Path(tmp))
            print(rows[-2], rows[-1], flush=True)
    print_table(["server", "phase", "probes", "p50 ms", "p99 ms", "max ms", "failed/timed out"],
                [[r[k] for k in ("server", "phase", "probes", "p50_ms", "p99_ms", "max_ms", "failed")] for r in rows])


def print_table(header: list[str], rows: list[list]) -> None:
    """A Markdown table of ``rows`` under ``header`` on stdout."""
    print("\n| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for row in rows:
        print("| " + " | ".join(str(v) for v in row) + " |")


if __name__ == "__main__":
    main()
