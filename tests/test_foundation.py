"""Foundation: settings come from the environment, pages are served, production passes check --deploy."""
from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _settings_in_subprocess(env: dict[str, str], expr: str) -> object:
    """Evaluate ``expr`` on django.conf.settings in a fresh interpreter with ``env`` set."""
    code = (
        "import json, django; from django.conf import settings; django.setup(); "
        f"print(json.dumps({expr}, default=str))"
    )
    full_env = {k: v for k, v in os.environ.items() if k not in {"DATABASE_URL", "DEBUG", "PRODUCTION"}}
    full_env.update({"DJANGO_SETTINGS_MODULE": "studyapp.settings"}, **env)
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=full_env, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_debug_is_off_unless_asked():
    assert _settings_in_subprocess({}, "settings.DEBUG") is False
    assert _settings_in_subprocess({"DEBUG": "1"}, "settings.DEBUG") is True


def test_sqlite_by_default_in_wal_mode(tmp_path):
    db = _settings_in_subprocess({"DATA_DIR": str(tmp_path)}, "settings.DATABASES['default']")
    assert db["ENGINE"] == "django.db.backends.sqlite3"
    assert db["NAME"] == str(tmp_path / "db.sqlite3")
    assert "journal_mode=WAL" in db["OPTIONS"]["init_command"]


def test_database_url_selects_postgresql():
    db = _settings_in_subprocess({"DATABASE_URL": "postgres://alice@127.0.0.1:5432/studies"},
                                 "settings.DATABASES['default']")
    assert db["ENGINE"] == "django.db.backends.postgresql"
    assert (db["NAME"], db["USER"], db["HOST"], db["PORT"]) == ("studies", "alice", "127.0.0.1", 5432)


def test_hosts_media_and_secret_from_environment(tmp_path):
    got = _settings_in_subprocess(
        {"ALLOWED_HOSTS": "study.example.org, other.example.org", "MEDIA_ROOT": str(tmp_path / "clips"),
         "SECRET_KEY": "s" * 60},
        "[settings.ALLOWED_HOSTS, str(settings.MEDIA_ROOT), settings.SECRET_KEY]",
    )
    assert got == [["study.example.org", "other.example.org"], str(tmp_path / "clips"), "s" * 60]


def test_production_requires_secret_key():
    env = {k: v for k, v in os.environ.items() if k != "SECRET_KEY"}
    env.update(PRODUCTION="1", DJANGO_SETTINGS_MODULE="studyapp.settings")
    out = subprocess.run([sys.executable, "-c", "import django; django.setup()"], cwd=ROOT, env=env,
                         capture_output=True, text=True, timeout=120)
    assert out.returncode != 0
    assert "SECRET_KEY must be set" in out.stderr


def test_production_settings_pass_check_deploy(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in {"DEBUG", "DATABASE_URL"}}
    env.update(PRODUCTION="1", SECRET_KEY="k" * 64 + "-production-test-key-with-enough-entropy",
               ALLOWED_HOSTS="study.example.org", DATA_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "manage.py", "check", "--deploy", "--fail-level", "WARNING"], cwd=ROOT,
                         env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "no issues" in out.stdout


@pytest.mark.django_db
def test_home_page_through_test_client(client):
    response = client.get("/")
    assert response.status_code == 200
    html = response.content.decode()
    assert "<h1>Perceptual study of virtual-agent motion</h1>" in html
    assert "No study is open at the moment." in html          # an empty database lists no study
    assert 'href="/admin/"' in html


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.browser
def test_real_server_page_in_headless_chromium(chromium, tmp_path):
    """Start gunicorn on a fresh SQLite database and load the home page in headless Chromium."""
    env = {k: v for k, v in os.environ.items() if k not in {"DATABASE_URL", "PRODUCTION"}}
    env.update(DATA_DIR=str(tmp_path), DJANGO_SETTINGS_MODULE="studyapp.settings")
    subprocess.run([sys.executable, "manage.py", "migrate", "--noinput"], cwd=ROOT, env=env, check=True,
                   capture_output=True, timeout=300)
    port = _free_port()
    server = subprocess.Popen([sys.executable, "-m", "gunicorn", "studyapp.wsgi", "-b", f"127.0.0.1:{port}",
                               "-w", "1"], cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        url = f"http://127.0.0.1:{port}/"
        deadline = time.monotonic() + 60
        while True:
            try:
                urllib.request.urlopen(url, timeout=2)
                break
            except OSError:
                if time.monotonic() > deadline or server.poll() is not None:
                    raise AssertionError("gunicorn did not come up") from None
                time.sleep(0.3)
        chromium.get(url)
        assert "Perceptual study of virtual-agent motion" in chromium.page_source
        assert "No study is open at the moment." in chromium.page_source
        assert chromium.title == "Perceptual study"
    finally:
        server.terminate()
        server.wait(timeout=30)
