"""Run deploy/nginx/study.conf locally: the site file with its EDIT values replaced by local ports and folders,
a minimal main nginx.conf around it, and a self-signed certificate. Used by tests/test_nginx_site.py and
benchmarks/bench_study_load.py --nginx; by hand:

    python -m deploy.nginx.local_site --app-port 8000 --https-port 8443 --data-dir var --out /tmp/study-nginx
    nginx -c /tmp/study-nginx/nginx.conf -g 'daemon off;'     # then https://127.0.0.1:8443/ (self-signed)

Run the app with MEDIA_ACCEL_REDIRECT=/protected-media/ and MEDIA_ROOT / STATIC_ROOT under --data-dir
(media/ and static/).
"""
from __future__ import annotations

import argparse
import os
import shutil
import socket
import subprocess
from pathlib import Path

SITE = Path(__file__).resolve().parent / "study.conf"


def nginx_binary() -> str | None:
    return shutil.which("nginx") or next((p for p in ("/usr/sbin/nginx", "/sbin/nginx") if os.path.exists(p)), None)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def templated_site(out: Path, data_dir: Path, app_port: int, http_port: int, https_port: int) -> str:
    """The production site file with its EDIT values replaced (IPv6 listeners dropped)."""
    text = SITE.read_text()
    replacements = {
        "server 127.0.0.1:8000;": f"server 127.0.0.1:{app_port};",
        "listen 80;": f"listen 127.0.0.1:{http_port};",
        "listen 443 ssl http2;": f"listen 127.0.0.1:{https_port} ssl http2;",
        "/etc/letsencrypt/live/study.example.org/fullchain.pem": str(out / "cert.pem"),
        "/etc/letsencrypt/live/study.example.org/privkey.pem": str(out / "key.pem"),
        "/srv/studies/": f"{Path(data_dir).resolve()}/",
        "/var/log/nginx/": f"{out}/log/",
    }
    for old, new in replacements.items():
        if old not in text:
            raise ValueError(f"{SITE} no longer contains {old!r}: update deploy/nginx/local_site.py")
        text = text.replace(old, new)
    return "\n".join(line for line in text.splitlines() if "listen [::]" not in line) + "\n"


def main_conf(out: Path, nginx: str, workers: int = 1) -> str:
    """A main nginx.conf (pid, logs and temp folders under out) that includes out/study.conf."""
    mime = Path("/etc/nginx/mime.types")
    user = "user root;\n" if os.geteuid() == 0 else ""        # workers must read root-owned temp folders
    temps = "\n".join(f"    {k}_temp_path {out}/temp/{k};" for k in ("client_body", "proxy", "fastcgi", "uwsgi",
                                                                      "scgi"))
    return (f"{user}worker_processes {workers};\npid {out}/nginx.pid;\nerror_log {out}/log/error.log warn;\n"
            f"events {{ worker_connections 1024; }}\nhttp {{\n    include {mime};\n"
            f"    default_type application/octet-stream;\n{temps}\n    include {out}/study.conf;\n}}\n")


def write_local_site(out: Path, data_dir: Path, app_port: int, http_port: int, https_port: int,
                     workers: int = 1) -> Path:
    """Write cert.pem/key.pem (self-signed, openssl), study.conf and nginx.conf into out; returns nginx.conf.
    Raises RuntimeError when nginx or openssl is missing."""
    nginx = nginx_binary()
    if not nginx or not shutil.which("openssl"):
        raise RuntimeError("nginx and openssl are needed (Debian: apt-get install -y nginx-light openssl)")
    for sub in ("log", "temp"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    if not (out / "cert.pem").exists():
        subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj",
                        "/CN=localhost", "-keyout", str(out / "key.pem"), "-out", str(out / "cert.pem")],
                       check=True, capture_output=True)
    (out / "study.conf").write_text(templated_site(out, data_dir, app_port, http_port, https_port))
    (out / "nginx.conf").write_text(main_conf(out, nginx, workers))
    check = subprocess.run([nginx, "-t", "-c", str(out / "nginx.conf"), "-e", str(out / "log" / "error.log")],
                           capture_output=True, text=True)
    if check.returncode != 0:
        raise RuntimeError(f"nginx -t failed:\n{check.stderr}")
    return out / "nginx.conf"


def start_nginx(conf: Path) -> subprocess.Popen:
    return subprocess.Popen([nginx_binary(), "-c", str(conf), "-e", str(conf.parent / "log" / "error.log"),
                             "-g", "daemon off;"])


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--app-port", type=int, default=8000)
    ap.add_argument("--http-port", type=int, default=8080)
    ap.add_argument("--https-port", type=int, default=8443)
    ap.add_argument("--data-dir", default="var")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    conf = write_local_site(Path(a.out).resolve(), Path(a.data_dir), a.app_port, a.http_port, a.https_port)
    print(f"{nginx_binary()} -c {conf} -g 'daemon off;'")
