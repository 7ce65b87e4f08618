"""Login-flood benchmark: wrong admin passwords (sequential, then from 8 threads) against the demo's server
configuration while participant pages are measured.

Uses the scratch study and server start of bench_slow_clients.py. For each setting of LOGIN_FAILURE_LIMIT
(--limit; 1000000 stands for "no throttling") it sends --attempts wrong passwords for the account "admin" from
one address, half one after another and half from 8 threads at once, and meanwhile GETs /s/demo/ and /healthz.
Prints how many attempts had their password checked (the login form again, 200) and how many were refused
(429), and the participant pages' p50 / p99 / max latency during the flood. Example:

    .venv/bin/python -m benchmarks.bench_login_flood --limit 1000000 --limit 5
"""
from __future__ import annotations

import argparse
import http.client
import re
import subprocess
import sys
import tempfile
import threading
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from benchmarks.bench_slow_clients import ROOT, free_port, measure, prepare, print_table, scratch_env, start_server

ADMIN = """
from django.contrib.auth.models import User
User.objects.create_superuser("admin", password="the-right-password-1")
"""


def wrong_login(port: int) -> int:
    """One admin login with a wrong password (CSRF cookie and token from a GET first); the POST's status."""
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    try:
        conn.request("GET", "/admin/login/")
        r = conn.getresponse()
        page = r.read().decode()
        cookie = re.search(r"csrftoken=([^;]+)", r.getheader("Set-Cookie") or "")
        token = re.search(r'name="csrfmiddlewaretoken" value="([^"]+)"', page)
        if not (cookie and token):
            return r.status
        body = f"csrfmiddlewaretoken={token.group(1)}&username=admin&password=wrong&next=/admin/"
        conn.request("POST", "/admin/login/", body=body, headers={
            "Content-Type": "application/x-www-form-urlencoded", "Cookie": f"csrftoken={cookie.group(1)}",
            "Referer": f"http://127.0.0.1:{port}/admin/login/"})
        r = conn.getresponse()
        r.read()
        return r.status
    except (OSError, http.client.HTTPException):
        return 0
    finally:
        conn.close()


def flood(port: int, attempts: int) -> list[int]:
    codes = [wrong_login(port) for _ in range(attempts // 2)]
    with ThreadPoolExecutor(8) as pool:
        codes += list(pool.map(lambda _: wrong_login(port), range(attempts - attempts // 2)))
    return codes


def run(limit: int, args, tmp: Path) -> dict:
    data = tmp / f"limit-{limit}"
    data.mkdir()
    env = scratch_env(data)
    env["LOGIN_FAILURE_LIMIT"] = str(limit)
    prepare(env)
    subprocess.run([sys.executable, str(ROOT / "manage.py"), "shell", "-c", ADMIN], env=env, cwd=ROOT, check=True)
    port = free_port()
    proc = start_server(args.server, port, env, tmp / f"gunicorn-{limit}.log")
    try:
        alone = measure(port, 5, 0.1, 25)
        result: dict = {}
        attack = threading.Thread(target=lambda: result.update(codes=flood(port, args.attempts)))
        attack.start()
        during = measure(port, args.seconds, 0.1, 25)
        attack.join()
    finally:
        proc.terminate()
        proc.wait(10)
    codes = result["codes"]
    return {"limit": limit, "checked": codes.count(200), "refused": codes.count(429),
            "other": len(codes) - codes.count(200) - codes.count(429), "alone_p50": alone["p50_ms"],
            "p50": during["p50_ms"], "p99": during["p99_ms"], "max": during["max_ms"], "failed": during["failed"]}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--limit", type=int, action="append", help="LOGIN_FAILURE_LIMIT values (default 1000000, 5)")
    ap.add_argument("--attempts", type=int, default=124)
    ap.add_argument("--seconds", type=float, default=15.0, help="participant-page measuring time from the start")
    ap.add_argument("--server", default="asgi", help="server configuration of bench_slow_clients.SERVERS")
    args = ap.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory(prefix="login-flood-") as tmp:
        for limit in args.limit or [1000000, 5]:
            rows.append(run(limit, args, Path(tmp)))
            print(rows[-1], flush=True)
    print_table(["LOGIN_FAILURE_LIMIT", "password checked", "refused (429)", "other", "pages alone p50 ms",
                 "during flood p50 / p99 / max ms", "failed"],
                [[r["limit"], r["checked"], r["refused"], r["other"], r["alone_p50"],
                  f"{r['p50']} / {r['p99']} / {r['max']}", r["failed"]] for r in rows])


if __name__ == "__main__":
    main()
