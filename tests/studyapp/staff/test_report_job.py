"""Report zips built outside the request (studyapp.staff.reports, manage.py build_report): the button returns at once,
one build per data version at a time, the finished zip is reused until the data change, failures are shown."""
from __future__ import annotations

import io
import os
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from django.core.management import CommandError, call_command
from django.test import Client
from django.urls import reverse

from studyapp.models import Participant, Response
from studyapp.staff import reports
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

# The team's helper that takes a participant through a study with library calls (no HTTP).
from tests.studyapp.staff.test_study_admin import finish

pytestmark = pytest.mark.django_db

ROOT = Path(__file__).resolve().parents[3]
# A stand-in build that holds the inherited lock until its gate file exists (or 60 s pass), and writes no zip.
GATED = "import os, sys, time\nend = time.time() + 60\nwhile not os.path.exists(sys.argv[1]) and time.time() < end:\n" \
        "    time.sleep(0.05)"


@pytest.fixture
def staff():
    user = User.objects.create_user("researcher", password="pw-researcher-1", is_staff=True, is_superuser=True)
    client = Client()
    client.force_login(user)
    return client


@pytest.fixture
def gait_study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    return create_study_from_preset("gait_ismar2020", "gaits", plan="test", status="open")


@pytest.fixture(autouse=True)
def reports_dir(settings, tmp_path):
    settings.REPORTS_DIR = tmp_path / "reports"
    return settings.REPORTS_DIR


class FakeBuilds(list):
    """The calls of the stand-in build command; ``release()`` lets the waiting builds end."""

    def __init__(self, gate: Path):
        super().__init__()
        self.gate = gate

    def release(self) -> None:
        self.gate.touch()


@pytest.fixture
def fake_builds(monkeypatch, tmp_path):
    """Replace the spawned command by a process that waits for a gate file (holding the inherited lock)."""
    calls = FakeBuilds(tmp_path / "gate")

    def command(study_id, version, lock_fd):
        calls.append((study_id, version, lock_fd))
        return [sys.executable, "-c", GATED, str(calls.gate)]

    monkeypatch.setattr(reports, "build_command", command)
    yield calls
    calls.release()


def _wait_not_running(study, version, timeout=20.0):
    end = time.time() + timeout
    while (state := reports.report_state(study, version)).status == "running" and time.time() < end:
        time.sleep(0.1)
    return state


def test_data_version_follows_the_data(gait_study):
    v0 = reports.data_version(gait_study)
    assert v0 == reports.data_version(gait_study) and len(v0) == 16
    p = Participant.objects.create(study=gait_study)
    v1 = reports.data_version(gait_study)
    assert v1 != v0
    finish(p)
    v2 = reports.data_version(gait_study)
    assert v2 != v1
    Response.objects.filter(participant=p).order_by("-id").first().delete()
    assert reports.data_version(gait_study) != v2            # fewer answers is new data too
    gait_study.exclusion_rules = {"min_rt_fraction": 0.25}
    gait_study.save()
    assert reports.data_version(gait_study) not in (v0, v1, v2)


def test_starting_a_build_does_not_wait_for_it_and_never_starts_two(gait_study, fake_builds):
    state = reports.start_build(gait_study)
    # start_build returned while the build still waits for its gate (it cannot end before release()); how fast it
    # returns is measured by benchmarks/bench_report_start.py
    assert state.status == "running" and not fake_builds.gate.exists()
    assert reports.report_state(gait_study).status == "running"
    again = reports.start_build(gait_study)
    assert again.status == "running" and len(fake_builds) == 1       # the lock is held: no second build
    with pytest.raises(CommandError, match="already running"):
        call_command("build_report", str(gait_study.pk), stdout=io.StringIO())
    fake_builds.release()
    done = _wait_not_running(gait_study, state.version)
    assert done.status == "failed" and "stopped without finishing" in done.error     # the stand-in wrote no zip


def test_command_builds_the_zip_and_the_button_reuses_it(gait_study, staff, fake_builds, reports_dir):
    for _ in range(3):
        finish(Participant.objects.create(study=gait_study))
    out = io.StringIO()
    call_command("build_report", str(gait_study.pk), stdout=out)
    state = reports.report_state(gait_study)
    assert state.status == "ready" and state.zip_path.parent.parent == reports_dir / str(gait_study.pk)
    names = zipfile.ZipFile(state.zip_path).namelist()
    assert "report.json" in names and "report.html" in names and "data/responses.csv" in names
    r = staff.post(reverse("studyapp:report_zip", args=[gait_study.pk]))
    assert r.status_code == 302 and fake_builds == []                 # unchanged data: nothing rebuilt
    page = staff.get(reverse("studyapp:progress", args=[gait_study.pk]))
    assert 'data-status="ready"' in page.content.decode()
    download = staff.get(reverse("studyapp:report_zip", args=[gait_study.pk]))
    assert download.status_code == 200 and download["Content-Type"] == "application/zip"
    assert b"".join(download.streaming_content) == state.zip_path.read_bytes()
    assert "already built" in _call("build_report", gait_study.slug)


def _call(*args) -> str:
    out = io.StringIO()
    call_command(*args, stdout=out)
    return out.getvalue()


def test_new_data_makes_a_new_version_and_drops_the_old(gait_study, staff, fake_builds):
    for _ in range(3):
        finish(Participant.objects.create(study=gait_study))
    _call("build_report", str(gait_study.pk))
    old = reports.report_state(gait_study)
    finish(Participant.objects.create(study=gait_study))
    new = reports.report_state(gait_study)
    assert new.version != old.version and new.status == "none"
    r = staff.get(reverse("studyapp:report_zip", args=[gait_study.pk]))
    assert r.status_code == 302 and r["Location"].endswith("#report")   # no stale report served as current
    r = staff.post(reverse("studyapp:report_zip", args=[gait_study.pk]))
    assert r.status_code == 302 and len(fake_builds) == 1 and fake_builds[0][1] == new.version
    assert 'data-status="running"' in staff.get(r["Location"]).content.decode()
    fake_builds.release()
    _wait_not_running(gait_study, new.version)
    _call("build_report", str(gait_study.pk), "--force")
    assert reports.report_state(gait_study).status == "ready"
    assert not old.zip_path.parent.exists()                              # the superseded version is pruned


def test_a_failed_build_shows_its_error(gait_study, staff):
    finish(Participant.objects.create(study=gait_study))
    Response.objects.filter(question="torso").update(answer="9")      # out of the Likert range
    with pytest.raises(CommandError, match="did not validate"):
        _call("build_report", str(gait_study.pk))
    state = reports.report_state(gait_study)
    assert state.status == "failed" and "did not validate" in state.error
    page = staff.get(reverse("studyapp:progress", args=[gait_study.pk])).content.decode()
    assert 'data-status="failed"' in page and "did not validate" in page and "Build again" in page


def test_unknown_study_and_bad_version():
    with pytest.raises(CommandError, match="no study"):
        _call("build_report", "999999")
    with pytest.raises(ValueError, match="not a data version"):
        reports.version_dir(1, "../../etc")


@pytest.mark.slow
def test_the_real_detached_command_runs(tmp_path):
    """start_build spawns the real `manage.py build_report` (own session, inherited lock) against a scratch
    SQLite database in a separate DATA_DIR; a study without answers fails with the analysis' reason."""
    env = dict(os.environ, DATA_DIR=str(tmp_path / "data"), MEDIA_ROOT=str(tmp_path / "data" / "media"),
               DJANGO_SETTINGS_MODULE="studyapp.settings", OMP_NUM_THREADS="1")
    env.pop("DATABASE_URL", None)
    env.pop("REPORTS_DIR", None)
    script = (
        "import django, time\n"
        "django.setup()\n"
        "from django.core.management import call_command\n"
        "call_command('migrate', verbosity=0)\n"
        "from studyapp.models import Study\n"
        "from studyapp.staff import reports\n"
        "study = Study.objects.create(slug='empty', title='synthetic empty study')\n"
        "state = reports.start_build(study)\n"
        "print('first', state.status)\n"
        "end = time.time() + 120\n"
        "while reports.report_state(study).status == 'running' and time.time() < end: time.sleep(0.2)\n"
        "final = reports.report_state(study)\n"
        "print('final', final.status)\n"
        "print('error', final.error.replace(chr(10), ' '))\n")
    out = subprocess.run([sys.executable, "-c", script], env=env, cwd=ROOT, capture_output=True, text=True,
                         timeout=240)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = dict(line.split(" ", 1) for line in out.stdout.splitlines() if " " in line)
    assert lines["first"] == "running"
    assert lines["final"] in ("ready", "failed")
    if lines["final"] == "failed":
        assert "stopped without finishing" not in lines["error"] and lines["error"].strip()


def test_progress_page_offers_a_build_and_reports_a_start_failure(gait_study, staff, monkeypatch):
    page = staff.get(reverse("studyapp:progress", args=[gait_study.pk])).content.decode()
    assert 'data-status="none"' in page and 'value="Build report"' in page

    def refuse(study):
        raise PermissionError("[Errno 13] Permission denied: '/srv/studies/reports'")

    monkeypatch.setattr("studyapp.staff.views.start_build", refuse)
    r = staff.post(reverse("studyapp:report_zip", args=[gait_study.pk]), follow=True)
    assert r.status_code == 200 and "Could not start the report build" in r.content.decode()
