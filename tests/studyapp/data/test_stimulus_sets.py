"""Stimulus sets from the admin (generation.plans.stimulus_set, studyapp.admin.stimuli, studyapp.data.render_jobs): the
form's plan is the command line's plan (same clip ids), renders run as background jobs that outlive their process,
and a render killed mid-way resumes without rendering a finished clip again."""
from __future__ import annotations

import io
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from django.core.management import call_command
from django.test import Client
from django.urls import reverse

from generation.pipeline.jobs import plan_jobs
from generation.plans.schema import load_plan
from generation.plans.stimulus_set import (
    StimulusSet,
    StimulusSetError,
    build_plan,
    estimate_render,
    parse_condition,
    plan_yaml,
)
from studyapp.data import background, render_jobs
from studyapp.models import Clip

TINY = {"width": "96", "height": "64", "fps": "8", "duration_s": "1", "camera": "fixed", "body": "stick"}


def form_data(**over) -> dict:
    data = {"name": "my-walks", "description": "", "generator": "procedural_walk",
            "conditions": "happy\nhappy 0.8 + neutral 0.2\nsad to happy", "variants": "2", "seed": "5", "shared": "",
            **TINY, "sections": ["emotion_choice"], "fallback": "on"}
    data.update(over)
    return data


@pytest.fixture
def staff(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.DATA_DIR = tmp_path / "data"
    client = Client()
    client.force_login(User.objects.create_user("lead", password="pw-lead-12345", is_staff=True, is_superuser=True))
    return client


def test_condition_lines_follow_the_generators_fields():
    assert parse_condition("gait_net", "happy 0.8 + neutral 0.2") == {"emotion": {"happy": 0.8, "neutral": 0.2}}
    assert parse_condition("gait_net", "sad to happy") == {"transition": {"initial": {"sad": 1.0},
                                                                          "final": {"happy": 1.0}}}
    assert parse_condition("rbf", "tired -0.7") == {"theme": "tired", "weight": -0.7}
    assert parse_condition("procedural_gesture", "afraid") == {"emotion_label": "afraid"}
    assert parse_condition("captured", "turn_left0.txt") == {"clip": "turn_left0.txt"}
    assert parse_condition("gesture_net", "{emotion_label: calm, gender: female}") == {"emotion_label": "calm",
                                                                                        "gender": "female"}
    with pytest.raises(StimulusSetError, match="'joyful' is not an emotion"):
        parse_condition("gait_net", "joyful")
    with pytest.raises(StimulusSetError, match="built-in plan"):
        build_plan(StimulusSet(name="seed000", generator="gait_net", conditions=["happy"]))
    with pytest.raises(StimulusSetError, match="expected one of"):       # the plan schema's own check
        build_plan(StimulusSet(name="x", generator="rbf", conditions=["bouncy 0.4"]))


def test_variants_get_their_own_seed_and_path_and_the_estimate_counts_frames():
    data, plan = build_plan(StimulusSet(name="v", generator="gait_net", conditions=["happy", "sad"], variants=3,
                                        seed=10, render={"width": 640, "height": 480, "fps": 25, "duration_s": 10}))
    assert len(plan.entries) == 6 and [e.seed for e in plan.entries] == list(range(10, 16))
    assert [e.inputs["trajectory"]["kind"] for e in plan.entries[:3]] == ["curved", "sharp_turn", "curved"]
    assert all(e.fallback == "procedural_walk" for e in plan.entries)
    estimate = estimate_render(plan)
    assert estimate.frames == 6 * 250 and "benchmark" in estimate.basis
    assert estimate.seconds == pytest.approx(6 * (0.028 * 250 * 0.3072 + 3.0))
    past = [{"modality": "gait", "metadata": {"timing_s": {"total": 10.0}, "n_frames": 100,
                                              "render": {"width": 1000, "height": 1000}}}] * 3
    assert estimate_render(plan, past).seconds == pytest.approx(6 * 0.1 * 250 * 0.3072)
    assert "&id" not in plan_yaml(data) and "*id" not in plan_yaml(data)     # no YAML aliases


@pytest.mark.django_db
def test_the_form_shows_clips_titles_and_time_and_errors_next_to_their_field(staff):
    url = reverse("admin:studyapp_clip_stimuli")
    page = staff.get(url)
    assert page.status_code == 200 and b"seed000" in page.content and b"gait_net" in page.content
    checked = staff.post(url, {**form_data(), "action": "check"})
    assert checked.status_code == 200 and checked.context["checked"]["plan"].name == "my-walks"
    titles = dict(checked.context["checked"]["titles"])
    assert titles["happy_v1"] == "procedural walk, happy, path 1"
    assert titles["sad_to_happy_v2"] == "procedural walk, sad to happy, path 2"
    assert b"Expected render time" in checked.content
    bad = staff.post(url, {**form_data(conditions="happy\nglad 0.5"), "action": "check"})
    assert "line 2 ('glad 0.5')" in " ".join(bad.context["form"].errors["conditions"])
    short = staff.post(url, {**form_data(duration_s="0.5"), "action": "check"})
    assert "expected a number in [1.0, 120.0]" in " ".join(short.context["form"].errors["duration_s"])
    assert not render_jobs.renders_dir().exists()                        # checking starts nothing


@pytest.mark.django_db
def test_the_form_and_the_command_line_make_the_same_clips(staff, monkeypatch, tmp_path):
    started = []
    monkeypatch.setattr(background, "launch", lambda cmd, *a, **k: started.append(cmd) or 1)
    r = staff.post(reverse("admin:studyapp_clip_stimuli"), {**form_data(), "action": "render"})
    job = r["Location"].rstrip("/").rsplit("/", 1)[-1]
    assert r.status_code == 302 and started == [render_jobs.render_command(job)]
    plan_file = render_jobs.plan_file(job)
    assert started[0][started[0].index("--plan") + 1] == str(plan_file)
    _, form_plan = build_plan(StimulusSet(name="my-walks", generator="procedural_walk",
                                          conditions=["happy", "happy 0.8 + neutral 0.2", "sad to happy"],
                                          variants=2, seed=5, sections=["emotion_choice"],
                                          render={k: (float(v) if k in ("fps", "duration_s") else
                                                      int(v) if k in ("width", "height") else v)
                                                  for k, v in TINY.items()}))
    expected = sorted(j.clip_id for j in plan_jobs(form_plan)[0])
    assert sorted(j.clip_id for j in plan_jobs(load_plan(plan_file))[0]) == expected
    downloaded = staff.get(reverse("admin:studyapp_clip_render_plan", args=[job]))
    copy = tmp_path / "my-walks.yaml"
    copy.write_bytes(b"".join(downloaded.streaming_content))
    call_command("generate_clips", "--plan", str(copy), "--no-progress", stdout=io.StringIO(),
                 stderr=io.StringIO())
    assert sorted(Clip.objects.filter(plan="my-walks").values_list("clip_id", flat=True)) == expected
    assert Clip.objects.get(clip_id=expected[0]).title.startswith("procedural walk, ")


def _wait(predicate, timeout: float, what: str) -> None:
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.05)


def _progress(job: str) -> dict:
    try:
        return json.loads((render_jobs.job_dir(job) / render_jobs.PROGRESS_NAME).read_text())
    except (OSError, ValueError):
        return {}


@pytest.mark.django_db
def test_a_render_killed_midway_is_shown_failed_and_resumes_without_rendering_finished_clips(staff, settings,
                                                                                           monkeypatch):
    # The detached job runs on its own SQLite database in DATA_DIR (the test database is not reachable from
    # another process); under PostgreSQL, DATABASE_URL names an unmigrated server database, so the job goes without.
    monkeypatch.delenv("DATABASE_URL", raising=False)
    env = dict(os.environ, DATA_DIR=str(settings.DATA_DIR), MEDIA_ROOT=str(settings.MEDIA_ROOT))
    Path(settings.DATA_DIR).mkdir(parents=True)
    subprocess.run([sys.executable, "manage.py", "migrate", "-v", "0"], cwd=settings.BASE_DIR, env=env, check=True)
    data, plan = build_plan(StimulusSet(name="killed", generator="procedural_walk", conditions=["happy", "sad"],
                                        variants=3, render={"width": 320, "height": 240, "fps": 25.0,
                                                            "duration_s": 3.0, "camera": "fixed"}))
    job = render_jobs.new_job("killed", len(plan.entries), 1.0, "lead", plan_text=plan_yaml(data))
    pid = render_jobs.start(job)
    _wait(lambda: _progress(job).get("done", 0) >= 1, 240, "the first clip")
    os.killpg(pid, signal.SIGKILL)                        # the render job this test started, and its children
    _wait(lambda: render_jobs.render_state(job).status != render_jobs.RUNNING, 30, "the process to go")
    state = render_jobs.render_state(job)
    assert state.status == render_jobs.INTERRUPTED and state.resumable and 1 <= state.done < len(plan.entries)
    page = staff.get(reverse("admin:studyapp_clip_render", args=[job]))
    assert b"interrupted" in page.content and b'id="render-resume"' in page.content
    records = Path(settings.MEDIA_ROOT) / "clip_records"
    finished = {p.stem: (Path(settings.MEDIA_ROOT) / "clips" / f"{p.stem}.mp4").stat().st_mtime_ns
                for p in records.glob("*.json")}
    assert finished

    assert staff.post(reverse("admin:studyapp_clip_render", args=[job])).status_code == 302     # resume
    _wait(lambda: render_jobs.render_state(job).status != render_jobs.RUNNING, 300, "the resumed render")
    state = render_jobs.render_state(job)
    assert state.status == render_jobs.DONE, state.log
    assert state.skipped == len(finished) and state.done == len(plan.entries) - len(finished)
    assert {cid: (Path(settings.MEDIA_ROOT) / "clips" / f"{cid}.mp4").stat().st_mtime_ns
            for cid in finished} == finished                 # not rendered again
    assert sorted(_progress(job)["clip_ids"]) == sorted(j.clip_id for j in plan_jobs(plan)[0])
    assert render_jobs.sheet_file(job).stat().st_size > 0
    with sqlite3.connect(Path(settings.DATA_DIR) / "db.sqlite3") as db:        # the job's own database
        titles = db.execute("select title from studyapp_clip where plan = 'killed'").fetchall()
    assert len(titles) == len(plan.entries) and all(t.startswith("procedural walk, ") for (t,) in titles)


@pytest.mark.django_db
def test_a_study_from_a_preset_offers_to_render_the_presets_plan(staff):
    r = staff.post(reverse("studyapp:create_from_preset"), {"preset": "gait_ismar2020", "slug": "gaits"},
                   follow=True)
    text = r.content.decode()
    assert 'id="render-preset-plan"' in text and "the catalogue holds 0 of its 34" in text
    offered = reverse("admin:studyapp_clip_stimuli") + "?plan=seed000"
    assert offered in text
    page = staff.get(offered)
    assert page.context["initial_plan"] == "seed000" and b'class="selected" id="builtin-seed000"' in page.content
