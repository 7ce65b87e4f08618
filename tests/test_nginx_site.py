"""deploy/nginx/study.conf in front of gunicorn: TLS, X-Accel-Redirect clip media (Range 206 with the right bytes,
304 on If-None-Match), static files, internal location not reachable from outside, tokens out of the access log.

Runs when nginx and openssl are installed (Debian: `apt-get install -y nginx-light`), skips with the reason
otherwise. The site file is templated to temporary folders and free ports; gunicorn serves a temporary SQLite
database with one synthetic clip, with PRODUCTION=1 and MEDIA_ACCEL_REDIRECT=/protected-media/. The templating
(deploy/nginx/local_site.py) fails loudly when an EDIT value of the site file changes.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from deploy.nginx.local_site import free_port, nginx_binary, start_nginx, write_local_site

ROOT = Path(__file__).resolve().parent.parent

PAYLOAD = bytes((i * 7) % 251 for i in range(200_000))      # synthetic clip bytes, not a video

pytestmark = [pytest.mark.slow,     # the test's certificate is self-signed
              pytest.mark.filterwarnings("ignore::urllib3.exceptions.InsecureRequestWarning")]

SETUP_SCRIPT = """
import django, sys
django.setup()
from django.core.management import call_command
call_command("migrate", verbosity=0)
from studyapp.data.catalogue import upsert_clips
from studyapp.models import Clip
from studyapp.testing import write_media
from django.conf import settings
rel = write_media(settings.MEDIA_ROOT, bytes.fromhex(sys.stdin.read().strip()))
upsert_clips([{"clip_id": "gait_synthetic_nginx", "modality": "gait", "origin": "generated", "video": rel,
               "happy": 1, "sad": 0, "angry": 0, "neutral": 0}])
# clips need a session that may see them (studyapp.participant.views.media_allowed): a superuser's
from django.contrib.auth import BACKEND_SESSION_KEY, HASH_SESSION_KEY, SESSION_KEY, get_user_model
from django.contrib.sessions.backends.db import SessionStore
user = get_user_model().objects.create_superuser("nginx-test", password="pw-nginx-test-1")
session = SessionStore()
session.update({SESSION_KEY: str(user.pk), BACKEND_SESSION_KEY: "django.contrib.auth.backends.ModelBackend",
                HASH_SESSION_KEY: user.get_session_auth_hash()})
session.create()
print(Clip.objects.get(clip_id="gait_synthetic_nginx").media_key, session.session_key)
"""


def _wait(url: str, timeout: float = 40.0, **kw) -> None:
    import requests

    end = time.time() + timeout
    while time.time() < end:
        try:
            requests.get(url, timeout=2, allow_redirects=False, **kw)
            return
        except requests.RequestException:
            time.sleep(0.2)
    raise AssertionError(f"nothing answered on {url} within {timeout} s")


@pytest.fixture(scope="module")
def stack(tmp_path_factory):
    if not nginx_binary():
        pytest.skip("nginx is not installed (Debian: apt-get install -y nginx-light)")
    if not shutil.which("openssl"):
        pytest.skip("openssl is not installed (needed for the test's self-signed certificate)")
    tmp = tmp_path_factory.mktemp("nginx-site")
    for sub in ("data/media", "data/static"):
        (tmp / sub).mkdir(parents=True)
    (tmp / "data" / "static" / "site.css").write_text("body{}")
    app_port, http_port, https_port = free_port(), free_port(), free_port()
    env = dict(os.environ, DATA_DIR=str(tmp / "data"), MEDIA_ROOT=str(tmp / "data" / "media"), PRODUCTION="1",
               SECRET_KEY="test-only-" + "x" * 60, ALLOWED_HOSTS="127.0.0.1,localhost",
               MEDIA_ACCEL_REDIRECT="/protected-media/", DJANGO_SETTINGS_MODULE="studyapp.settings",
               OMP_NUM_THREADS="1")
    env.pop("DATABASE_URL", None)
    key, session = subprocess.run([sys.executable, "-c", SETUP_SCRIPT], input=PAYLOAD.hex(), env=env, cwd=ROOT,
                                  check=True, capture_output=True, text=True).stdout.strip().splitlines()[-1].split()
    SESSION_COOKIE["sessionid"] = session
    conf = write_local_site(tmp, tmp / "data", app_port, http_port, https_port)   # runs nginx -t
    app = subprocess.Popen([sys.executable, "-m", "gunicorn", "studyapp.wsgi", "-b", f"127.0.0.1:{app_port}", "-w", "1",
                            "--worker-class", "gthread", "--threads", "4", "--log-level", "warning"], cwd=ROOT, env=env)
    web = start_nginx(conf)
    try:
        _wait(f"http://127.0.0.1:{app_port}/healthz")
        _wait(f"https://127.0.0.1:{https_port}/healthz", verify=False)
        yield {"app": f"http://127.0.0.1:{app_port}", "https": f"https://127.0.0.1:{https_port}",
               "http": f"http://127.0.0.1:{http_port}", "key": key, "tmp": tmp}
    finally:
        for proc in (web, app):
            proc.terminate()
        for proc in (web, app):
            proc.wait(20)


SESSION_COOKIE: dict[str, str] = {}
"""The staff session the clip requests carry (set by the stack fixture)."""


def get(url: str, **kw):
    import requests

    kw.setdefault("cookies", SESSION_COOKIE)
    return requests.get(url, verify=False, allow_redirects=False, timeout=20, **kw)


def test_the_app_hands_clips_to_nginx(stack):
    r = get(f"{stack['app']}/m/{stack['key']}.mp4", headers={"X-Forwarded-Proto": "https", "Range": "bytes=0-9"})
    assert r.status_code == 200 and r.content == b""
    assert r.headers["X-Accel-Redirect"].startswith("/protected-media/clips/")


def test_range_through_nginx(stack):
    r = get(f"{stack['https']}/m/{stack['key']}.mp4", headers={"Range": "bytes=1000-1999"})
    assert r.status_code == 206, r.text[:300]
    assert r.content == PAYLOAD[1000:2000]
    assert r.headers["Content-Range"] == f"bytes 1000-1999/{len(PAYLOAD)}"
    assert r.headers["Content-Type"] == "video/mp4"
    assert "X-Accel-Redirect" not in r.headers
    assert r.headers["Cache-Control"] == "private, no-cache"             # revalidated: answered clips stop
    assert get(f"{stack['https']}/m/{stack['key']}.mp4", cookies={}).status_code == 403     # no session
    assert r.headers["X-Content-Type-Options"] == "nosniff" and "Server" in r.headers
    assert r.headers["Server"] == "nginx"                               # server_tokens off: no version
    suffix = get(f"{stack['https']}/m/{stack['key']}.mp4", headers={"Range": "bytes=-100"})
    assert suffix.status_code == 206 and suffix.content == PAYLOAD[-100:]


def test_whole_file_and_304_through_nginx(stack):
    r = get(f"{stack['https']}/m/{stack['key']}.mp4")
    assert r.status_code == 200 and r.content == PAYLOAD and r.headers["Accept-Ranges"] == "bytes"
    etag, modified = r.headers["ETag"], r.headers["Last-Modified"]
    again = get(f"{stack['https']}/m/{stack['key']}.mp4", headers={"If-None-Match": etag})
    assert again.status_code == 304 and again.content == b""
    since = get(f"{stack['https']}/m/{stack['key']}.mp4", headers={"If-Modified-Since": modified})
    assert since.status_code == 304
    stale = get(f"{stack['https']}/m/{stack['key']}.mp4", headers={"If-None-Match": '"not-this-one"'})
    assert stale.status_code == 200 and stale.content == PAYLOAD


def test_unknown_key_and_internal_location_are_404(stack):
    assert get(f"{stack['https']}/m/{'0' * 32}.mp4").status_code == 404
    direct = get(f"{stack['https']}/protected-media/" + get(
        f"{stack['app']}/m/{stack['key']}.mp4", headers={"X-Forwarded-Proto": "https"}
    ).headers["X-Accel-Redirect"].removeprefix("/protected-media/"))
    assert direct.status_code == 404                  # internal: only the app's redirect reaches it


def test_static_proxy_and_https_redirect(stack):
    css = get(f"{stack['https']}/static/site.css")
    assert css.status_code == 200 and css.text == "body{}" and "immutable" in css.headers["Cache-Control"]
    health = get(f"{stack['https']}/healthz")
    assert health.status_code == 200 and health.text == "ok"       # X-Forwarded-Proto: https reached Django
    plain = get(f"{stack['http']}/healthz")
    assert plain.status_code == 301 and plain.headers["Location"].startswith("https://")


def test_body_size_limit(stack):
    import requests

    r = requests.post(f"{stack['https']}/s/any/", data=b"x" * (3 * 1024 * 1024), verify=False, timeout=20)
    assert r.status_code == 413


def _location_body_sizes() -> dict[str, str]:
    """{location (with its '= ' when exact): client_max_body_size in it} of the site file's locations."""
    import re

    text = (ROOT / "deploy/nginx/study.conf").read_text()
    return {m["where"]: size["value"]
            for m in re.finditer(r"location\s+(?P<where>(?:=\s+)?\S+)\s*\{(?P<body>[^}]*)\}", text)
            if (size := re.search(r"client_max_body_size\s+(?P<value>\S+);", m["body"]))}


def test_the_clip_import_url_alone_takes_uploads_of_the_import_limit():
    """The admin's clip import URL (exactly, not its status pages) allows the import's file limit."""
    from django.urls import reverse

    from generation.imports.video import VideoLimits

    sizes = _location_body_sizes()
    assert sizes == {f"= {reverse('admin:studyapp_clip_import')}": f"{VideoLimits.max_bytes // 2**20}m"}


def test_an_upload_passes_on_the_import_url_only(stack):
    import requests
    from django.urls import reverse

    body = b"x" * (3 * 1024 * 1024)
    upload = requests.post(f"{stack['https']}{reverse('admin:studyapp_clip_import')}", data=body, verify=False,
                           allow_redirects=False, timeout=20)
    assert upload.status_code != 413 and upload.headers["Server"] == "nginx"      # the app's answer (CSRF)
    status_page = reverse("admin:studyapp_clip_import_status", args=["20260101-000000-abcd1234"])
    assert requests.post(f"{stack['https']}{status_page}", data=body, verify=False, timeout=20).status_code == 413


def test_login_requests_are_rate_limited(stack):
    """The admin login allows a burst of 5 beyond the 10/minute rate per address; nginx answers 429 after that,
    while the participant pages stay open."""
    codes = [get(f"{stack['https']}/admin/login/").status_code for _ in range(12)]
    # the app's own answer (this stack has no collected admin static files) for 1 + burst, nginx's 429 after
    assert 429 not in codes[:6] and set(codes[6:]) == {429}, codes
    assert get(f"{stack['https']}/healthz").status_code == 200


def test_tokens_stay_out_of_the_access_log(stack):
    get(f"{stack['https']}/p/SECRETTOKEN123/clip/1/?PROLIFIC_PID=SECRETPID")
    log = stack["tmp"] / "log" / "study.access.log"
    for _ in range(50):                       # nginx writes the line after the response
        if log.exists() and "/p/***/clip/1/" in log.read_text():
            break
        time.sleep(0.1)
    text = log.read_text()
    assert "/p/***/clip/1/" in text
    assert "SECRETTOKEN123" not in text and "SECRETPID" not in text


def test_form_posts_pass_csrf_through_nginx(stack):
    """Behind nginx on any port, a form POST with a valid CSRF token passes Django's HTTPS Referer check: the
    proxy forwards the Host header with its port ($http_host)."""
    import requests

    token = "a" * 32
    r = requests.post(f"{stack['https']}/s/no-such-study/", data={"csrfmiddlewaretoken": token},
                      cookies={"csrftoken": token}, headers={"Referer": f"{stack['https']}/s/no-such-study/"},
                      verify=False, allow_redirects=False, timeout=20)
    assert r.status_code == 404, r.text[:300]            # past the CSRF check, no such study
    forged = requests.post(f"{stack['https']}/s/no-such-study/", data={"csrfmiddlewaretoken": token},
                           cookies={"csrftoken": token}, headers={"Referer": "https://evil.example/"},
                           verify=False, allow_redirects=False, timeout=20)
    assert forged.status_code == 403
