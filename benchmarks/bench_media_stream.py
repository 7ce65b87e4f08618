"""Clip serving under ASGI: a 500 MB SYNTHETIC video (random bytes, made in a temporary folder, never kept) sent to
20 concurrent range readers; the server's peak memory and the time to the first byte.

Starts the demo's server configuration (gunicorn ``studyapp.asgi:application -k asgi``, 2 workers, a scratch SQLite
database with one clip row and a superuser session that may fetch it) from ``--code`` (default: this checkout; give
an extracted older commit, e.g. ``git archive <commit> | tar -x -C /tmp/before``, for the "before" row). Each reader
sends one open-ended range request, as a browser does when it seeks, ``Range: bytes=<start>-`` with start 64 + i
MiB before the end (64-83 MiB each, 1.4 GiB in all), and reads it to the end. Meanwhile the resident memory of the
server's processes (master and workers, summed) is sampled every 20 ms. Prints one JSON object. Example:

    .venv/bin/python -m benchmarks.bench_media_stream --code /tmp/before --label before
    .venv/bin/python -m benchmarks.bench_media_stream --label after
"""
from __future__ import annotations

import argparse
import http.client
import json
import os
import secrets
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import psutil

from benchmarks.local_server import free_port, wait_for_server

ROOT = Path(__file__).resolve().parent.parent
MiB = 1024 * 1024

SETUP = """
from django.contrib.auth.models import User
from django.test import Client
from studyapp.data.catalogue import upsert_clips
from studyapp.models import Clip
upsert_clips([{"clip_id": "synthetic_500mb", "modality": "other", "origin": "imported",
               "video": "clips/synthetic_500mb.mp4", "metadata": {"synthetic": True}}])
user = User.objects.create_superuser("bench", "b@example.org", "pw-bench-123456")
c = Client()
c.force_login(user)
print(Clip.objects.get().media_key, c.cookies["sessionid"].value)
"""


def synthetic_video(path: Path, size: int) -> None:
    """``size`` random bytes (not a playable video: serving does not look inside)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("wb") as f:
        left = size
        while left:
            n = min(8 * MiB, left)
            f.write(os.urandom(n))
            left -= n


def tree_rss(proc: psutil.Process) -> int:
    total = 0
    for p in [proc, *proc.children(recursive=True)]:
        try:
            total += p.memory_info().rss
        except psutil.Error:
            pass
    return total


def read_range(port: int, path: str, cookie: str, start: int) -> dict:
    """One open-ended range request read to the end: status, bytes, time to first byte and to the end (s)."""
    t0 = time.perf_counter()
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=300)
    try:
        conn.request("GET", path, headers={"Range": f"bytes={start}-", "Cookie": f"sessionid={cookie}"})
        r = conn.getresponse()
        first = r.read(1)
        ttfb = time.perf_counter() - t0
        n = len(first)
        while chunk := r.read(MiB):
            n += len(chunk)
        return {"status": r.status, "bytes": n, "ttfb_s": ttfb, "total_s": time.perf_counter() - t0}
    finally:
        conn.close()


def run(code: Path, size: int, readers: int, workers: int) -> dict:
    with tempfile.TemporaryDirectory(prefix="bench-media-") as tmp:
        data = Path(tmp)
        video = data / "media" / "clips" / "synthetic_500mb.mp4"
        synthetic_video(video, size)
        env = dict(os.environ, DATA_DIR=str(data), MEDIA_ROOT=str(data / "media"), DEBUG="0",
                   SECRET_KEY=secrets.token_urlsafe(50), ALLOWED_HOSTS="127.0.0.1", OMP_NUM_THREADS="1",
                   PYTHONWARNINGS="default")
        env.pop("DATABASE_URL", None)
        env.pop("MEDIA_ACCEL_REDIRECT", None)
        manage = [sys.executable, str(code / "manage.py")]
        subprocess.run(manage + ["migrate", "--noinput", "-v", "0"], env=env, cwd=code, check=True)
        key, cookie = subprocess.run(manage + ["shell", "-c", SETUP], env=env, cwd=code, check=True,
                                     capture_output=True, text=True).stdout.split()[-2:]
        port = free_port()
        log = data / "gunicorn.log"
        server = subprocess.Popen([sys.executable, "-m", "gunicorn", "studyapp.asgi:application", "-k", "asgi",
                                   "-w", str(workers), "-b", f"127.0.0.1:{port}", "--timeout", "300"],
                                  env=env, cwd=code, stdout=subprocess.DEVNULL, stderr=log.open("wb"))
        try:
            proc = psutil.Process(server.pid)
            wait_for_server(server, port, log)
            path = f"/m/{key}.mp4"
            for _ in range(workers * 2):                  # warm every worker (imports, first request)
                read_range(port, path, cookie, size - 1024)
            idle = tree_rss(proc)
            peak = [idle]
            stop = threading.Event()

            def sample():
                while not stop.is_set():
                    peak[0] = max(peak[0], tree_rss(proc))
                    time.sleep(0.02)

            sampler = threading.Thread(target=sample)
            sampler.start()
            t0 = time.perf_counter()
            with ThreadPoolExecutor(readers) as pool:
                results = list(pool.map(lambda i: read_range(port, path, cookie, size - (64 + i) * MiB),
                                        range(readers)))
            wall = time.perf_counter() - t0
            stop.set()
            sampler.join()
        finally:
            server.terminate()
            server.wait(30)
        warning = "must consume synchronous iterators" in log.read_text(errors="replace")
    ttfb = sorted(r["ttfb_s"] for r in results)
    return {"readers": readers, "file_mib": size / MiB, "workers": workers,
            "ok": sum(r["status"] == 206 and r["bytes"] == (64 + i) * MiB for i, r in enumerate(results)),
            "served_mib": sum(r["bytes"] for r in results) / MiB,
            "idle_rss_mib": round(idle / MiB, 1), "peak_rss_mib": round(peak[0] / MiB, 1),
            "ttfb_p50_ms": round(statistics.median(ttfb) * 1000, 1), "ttfb_max_ms": round(ttfb[-1] * 1000, 1),
            "wall_s": round(wall, 2), "sync_iterator_warning": warning}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--code", type=Path, default=ROOT, help="the checkout whose server is measured")
    ap.add_argument("--label", default="", help="a name for this run in the output")
    ap.add_argument("--size-mb", type=int, default=500, help="the synthetic video's size in MiB (default 500)")
    ap.add_argument("--readers", type=int, default=20)
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args(argv)
    out = run(args.code.resolve(), args.size_mb * MiB, args.readers, args.workers)
    print(json.dumps({"label": args.label, **out}))


if __name__ == "__main__":
    main()
