"""The generate_clips command: renders a plan once, resumes, refuses bad plans, catalogues what it made."""
from __future__ import annotations

import io
import json

import pytest
import yaml
from django.core.management import CommandError, call_command

from generation.plans.catalogue import CLIP_COLUMNS, check_catalogue, read_clips_csv
from protocol.vocabulary import CLIP_BODY_COLUMNS, CLIP_PROVENANCE_COLUMNS, QA_COLUMNS

TINY_RENDER = {"width": 160, "height": 120, "fps": 10, "duration_s": 1.0}
CLIPS = [
    {"id": "walk_happy", "generator": "gait_net", "fallback": "procedural_walk", "emotion": [1, 0, 0, 0],
     "trajectory": {"kind": "straight", "length_m": 3}, "seed": 1, "sections": ["emotion_choice"]},
    {"id": "walk_transition", "generator": "procedural_walk",
     "transition": {"initial": [0, 1, 0, 0], "final": [1, 0, 0, 0]}, "seed": 2},
    {"id": "source_walk", "generator": "captured", "origin": "source", "clip": "0walk_forward.txt"},
    {"id": "gesture_sad", "generator": "procedural_gesture", "origin": "source", "emotion_label": "sad",
     "duration_s": 1.0, "seed": 3},
]


@pytest.fixture
def media(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.DATA_DIR = tmp_path / "data"
    return tmp_path / "media"


def _write_plan(tmp_path, clips=CLIPS, name="tiny"):
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump({"name": name, "render": TINY_RENDER, "clips": clips}))
    return path


def _run(*args):
    out = io.StringIO()
    call_command("generate_clips", *args, "--no-progress", stdout=out, stderr=io.StringIO())
    return out.getvalue()


@pytest.mark.django_db
def test_plan_renders_once_then_nothing(media, tmp_path):
    from studyapp.models import Clip

    plan = _write_plan(tmp_path)
    out = _run("--plan", str(plan))
    assert "4 rendered, 0 already done, 0 failed" in out
    clips_dir = media / "clips"
    files = sorted(p.name for p in clips_dir.iterdir())
    assert len([f for f in files if f.endswith(".mp4")]) == 4
    assert not [f for f in files if f.startswith(".")]          # no temporary files left
    mtimes = {p.name: p.stat().st_mtime_ns for p in clips_dir.iterdir()}

    out2 = _run("--plan", str(plan))
    assert "0 rendered, 4 already done, 0 failed" in out2
    assert {p.name: p.stat().st_mtime_ns for p in clips_dir.iterdir()} == mtimes

    # The catalogue matches the files, in clips.csv and in the database.
    csv_path = media / "clips.csv"
    assert check_catalogue(csv_path, clips_dir) == []
    rows = read_clips_csv(csv_path)
    assert len(rows) == 4
    assert csv_path.read_text().splitlines()[0] == ",".join((*CLIP_COLUMNS, *QA_COLUMNS, *CLIP_PROVENANCE_COLUMNS,
                                                             *CLIP_BODY_COLUMNS))
    assert Clip.objects.count() == 4
    for row in rows:
        clip = Clip.objects.get(clip_id=row["clip_id"])
        assert (media / clip.video).is_file() and (media / clip.poster).is_file()
        assert clip.video == f"clips/{row['clip_id']}.mp4"
        assert row["duration_s"] == pytest.approx(1.0, abs=0.11)
    by_entry = {Clip.objects.get(clip_id=r["clip_id"]).metadata["entry_id"]: r for r in rows}
    happy = Clip.objects.get(clip_id=by_entry["walk_happy"]["clip_id"])
    assert by_entry["walk_happy"]["happy"] == 1.0 and by_entry["walk_happy"]["final_happy"] is None
    assert by_entry["walk_transition"]["sad"] == 1.0 and by_entry["walk_transition"]["final_happy"] == 1.0
    assert by_entry["source_walk"]["origin"] == "source" and by_entry["source_walk"]["happy"] is None
    assert by_entry["gesture_sad"]["emotion_label"] == "sad" and by_entry["gesture_sad"]["valence"] == 0.225
    # The human body is a clip field: the gesture's gender (female by default) picks its body, walks get the male one;
    # every record names the body's parameters, licence and citation.
    assert by_entry["gesture_sad"]["body"] == "female" and by_entry["walk_happy"]["body"] == "male"
    for row in rows:
        record = json.loads((media / "clip_records" / f"{row['clip_id']}.json").read_text())
        assert record["body"]["preset"] == row["body"]
        assert "CC0-1.0" in record["body"]["licence"]["assets"] and "2511.03589" in record["body"]["citation"]
    # Fallbacks are recorded, never passed off as the network's output (its weights are not shipped in tests).
    if happy.metadata["generator"] == "procedural_walk":
        assert happy.metadata["fallback_for"] == "gait_net" and happy.metadata["synthetic"] is True
    assert happy.plan == "tiny" and happy.loop is False
    # Readable titles in clips.csv and the catalogue: generator, condition (a source take by its file).
    titles = {entry: row["title"] for entry, row in by_entry.items()}
    assert titles["walk_transition"] == "procedural walk, sad to happy"
    assert titles["source_walk"] == "captured, take 0walk_forward"
    assert titles["walk_happy"].endswith(", happy") and happy.title == titles["walk_happy"]
    # File names reveal nothing about the condition.
    assert all(len(r["clip_id"]) == 16 and "happy" not in r["clip_id"] for r in rows)


@pytest.mark.django_db
def test_resume_renders_only_missing_clips(media, tmp_path):
    plan = _write_plan(tmp_path, CLIPS[2:])
    _run("--plan", str(plan), "--no-db")
    rows = read_clips_csv(media / "clips.csv")
    victim = media / "clips" / f"{rows[0]['clip_id']}.mp4"
    victim.unlink()
    stale = media / "clips" / f".{rows[0]['clip_id']}.tmp999.mp4"
    stale.write_bytes(b"half a file")  # what a crashed render leaves
    out = _run("--plan", str(plan), "--no-db")
    assert "1 rendered, 1 already done" in out
    assert victim.is_file() and not stale.exists()
    assert check_catalogue(media / "clips.csv", media / "clips") == []


@pytest.mark.django_db
def test_bad_plan_is_refused_before_rendering(media, tmp_path):
    bad = [CLIPS[2], {"id": "x", "generator": "rbf", "theme": "happy", "weight": "abc"}]
    plan = _write_plan(tmp_path, bad)
    with pytest.raises(CommandError) as exc:
        _run("--plan", str(plan))
    assert "entry 2 (id 'x'): field 'weight': expected a number, got 'abc'" in str(exc.value)
    assert not (media / "clips").exists()
    with pytest.raises(CommandError, match="no plan 'nonsense'"):
        _run("--plan", "nonsense")


@pytest.mark.django_db
def test_an_unmigrated_database_is_refused_before_rendering(media, tmp_path, monkeypatch):
    from django.db.migrations.executor import MigrationExecutor

    monkeypatch.setattr(MigrationExecutor, "migration_plan", lambda self, targets: [("studyapp.0001", False)])
    with pytest.raises(CommandError, match=r"1 unapplied migration\(s\): run `python manage.py migrate` first"):
        _run("--plan", str(_write_plan(tmp_path)))
    assert not (media / "clips").exists()


@pytest.mark.django_db
def test_limit_webm_and_contact_sheet(media, tmp_path):
    plan = _write_plan(tmp_path, CLIPS[2:])
    sheet = tmp_path / "sheet.png"
    out = _run("--plan", str(plan), "--limit", "1", "--webm", "--contact-sheet", str(sheet))
    assert "1 rendered" in out and sheet.is_file()
    rows = read_clips_csv(media / "clips.csv")
    assert len(rows) == 1
    assert check_catalogue(media / "clips.csv", media / "clips", webm=True) == []
    record = json.loads((media / "clip_records" / f"{rows[0]['clip_id']}.json").read_text())
    assert record["webm"] == f"clips/{rows[0]['clip_id']}.webm"
    assert record["metadata"]["entry_id"] == "source_walk" and record["metadata"]["synthetic"] is False


@pytest.mark.slow
@pytest.mark.django_db
def test_two_workers(media, tmp_path):
    plan = _write_plan(tmp_path)
    out = _run("--plan", str(plan), "--workers", "2", "--no-db")
    assert "4 rendered, 0 already done, 0 failed" in out
    assert check_catalogue(media / "clips.csv", media / "clips") == []


@pytest.mark.django_db
def test_unavailable_generator_fails_only_its_entries(media, tmp_path, monkeypatch):
    from generation.plans.generators import gesture_net

    missing = tmp_path / "no_such_weights.pt"
    monkeypatch.setattr(gesture_net, "WEIGHTS_FILE", missing)
    gesture = {"id": "g", "generator": "gesture_net", "sentence": "I did it.", "emotion_label": "proud"}
    plan = _write_plan(tmp_path, [gesture, dict(gesture, id="g_fb", fallback="procedural_gesture", seed=1), CLIPS[2]])
    err = io.StringIO()
    with pytest.raises(CommandError, match="1 clip\\(s\\) of plan tiny failed"):
        call_command("generate_clips", "--plan", str(plan), "--no-progress", stdout=io.StringIO(), stderr=err)
    assert f"entry 1 (id 'g'): generator 'gesture_net' is not available: weights file {missing} is missing" \
        in err.getvalue()
    from studyapp.models import Clip

    clips = {c.metadata["entry_id"]: c for c in Clip.objects.all()}
    assert set(clips) == {"g_fb", "source_walk"}
    fb = clips["g_fb"]
    assert fb.metadata["generator"] == "procedural_gesture" and fb.metadata["fallback_for"] == "gesture_net"
    assert fb.metadata["synthetic"] is True and fb.origin == "generated" and fb.emotion_label == "proud"
