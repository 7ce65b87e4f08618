"""The import_clips command: researchers' own videos and BVH files become clips with origin ``imported``.

The videos are synthetic test patterns made here with the bundled ffmpeg (testsrc2 / sine sources); the BVH is the
shipped Bandai Namco take (CC BY-NC 4.0, generation/data/mocap/bandai-namco).
"""
from __future__ import annotations

import contextlib
import csv
import io
import os
import subprocess
from pathlib import Path

import imageio_ffmpeg
import pandas as pd
import pytest
from django.core.management import CommandError, call_command

from generation.imports import read_manifest
from generation.imports.manifest import MANIFEST_COLUMNS
from generation.imports.run import REPORT_COLUMNS
from generation.plans.catalogue import read_clips_csv

REPO = Path(__file__).resolve().parents[3]
BVH = (REPO / "generation/data/mocap/bandai-namco/Bandai-Namco-Research-Motiondataset-1/data"
       / "dataset-1_walk_happy_001.bvh")
BANDAI_LICENCE = "CC BY-NC 4.0"
BANDAI_CITATION = ("M. Kobayashi et al. Motion Capture Dataset for Practical Use of AI-based Motion Editing and "
                   "Stylization. arXiv:2306.08861, 2023")


def make_video(path: Path, codec: str = "libx264", seconds: float = 1.0, size: str = "64x48", audio: bool = False,
               pattern: str = "testsrc2") -> Path:
    """A synthetic test video (ffmpeg's test pattern, optionally a 440 Hz tone)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-v", "error", "-y", "-f", "lavfi", "-i",
           f"{pattern}=size={size}:rate=15:duration={seconds}"]
    if audio:
        cmd += ["-f", "lavfi", "-i", f"sine=frequency=440:duration={seconds}", "-c:a", "aac", "-shortest"]
    cmd += ["-c:v", codec, *(["-pix_fmt", "yuv420p"] if codec == "libx264" else ["-deadline", "realtime"]),
            str(path)]
    subprocess.run(cmd, check=True)
    return path


def write_manifest(folder: Path, rows: list[dict], name: str = "manifest.csv") -> Path:
    path = folder / name
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=MANIFEST_COLUMNS)
        w.writeheader()
        for row in rows:
            w.writerow(row)
    return path


def read_report(path: Path) -> list[dict]:
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert rows and tuple(rows[0]) == REPORT_COLUMNS
    return rows


def run(manifest: Path, *args, fail: bool = False) -> str:
    out = io.StringIO()
    if fail:
        with pytest.raises(CommandError, match="row\\(s\\) failed"):
            call_command("import_clips", str(manifest), "--no-observer", *args, stdout=out)
    else:
        call_command("import_clips", str(manifest), "--no-observer", *args, stdout=out)
    return out.getvalue()


@pytest.fixture
def media(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.DATA_DIR = tmp_path / "data"
    return tmp_path / "media"


@pytest.fixture
def lab(tmp_path):
    """A lab's folder: an H.264 MP4 with sound, a VP9 WebM (needs transcoding) and the Bandai Namco BVH."""
    folder = tmp_path / "lab"
    make_video(folder / "videos/walk.mp4", audio=True)
    make_video(folder / "videos/face.webm", codec="libvpx-vp9", pattern="testsrc")
    (folder / "mocap").mkdir()
    (folder / "mocap/walk_happy.bvh").write_bytes(BVH.read_bytes())
    return folder


GOOD = [
    {"path": "videos/walk.mp4", "modality": "gait", "origin": "imported", "happy": "0.6", "sad": "0", "angry": "0",
     "neutral": "0.2", "title": "lab walk", "licence": "CC0", "citation": "Our lab 2026"},
    {"path": "videos/face.webm", "modality": "other", "valence": "0.8", "arousal": "0.3", "dominance": "0.5",
     "title": "face", "licence": "CC BY 4.0", "keep_audio": "no"},
    {"path": "mocap/walk_happy.bvh", "modality": "gait", "happy": "1", "sad": "0", "angry": "0", "neutral": "0",
     "licence": BANDAI_LICENCE, "citation": BANDAI_CITATION, "body": "stick"},
]
TINY = ("--render-size", "96x64")


def _files(media: Path) -> set[str]:
    return {str(p.relative_to(media)) for p in media.rglob("*") if p.is_file()} if media.exists() else set()


@pytest.mark.django_db
def test_good_rows_become_first_class_clips(media, lab):
    from studyapp.data.catalogue import pool_queryset
    from studyapp.models import Clip

    out = run(write_manifest(lab, GOOD), *TINY)
    assert "3 of 3 row(s) imported" in out
    report = read_report(lab / "import_report.csv")
    assert [r["status"] for r in report] == ["ok"] * 3, report
    assert "remux h264" in report[0]["message"] and "audio stripped" in report[0]["message"]
    assert "transcode vp9" in report[1]["message"]
    ids = [r["clip_id"] for r in report]
    assert all(len(i) == 16 for i in ids) and len(set(ids)) == 3
    clips = {c.clip_id: c for c in Clip.objects.all()}
    assert set(clips) == set(ids) and {c.origin for c in clips.values()} == {"imported"}
    walk, face, bvh = (clips[i] for i in ids)
    assert (walk.happy, walk.neutral, walk.licence, walk.citation) == (0.75, 0.25, "CC0", "Our lab 2026")
    assert face.modality == "other" and face.valence == 0.8 and face.duration_s == pytest.approx(1.0, abs=0.1)
    assert bvh.licence == BANDAI_LICENCE and bvh.citation == BANDAI_CITATION and bvh.qa.get("foot_skate_cm_s")
    assert bvh.metadata["import"]["status"] == "ok" and bvh.metadata["render"]["body"] == "stick"
    for cid in ids:
        assert (media / "clips" / f"{cid}.mp4").stat().st_size > 0 and (media / "clips" / f"{cid}.png").is_file()
        assert (media / "clip_records" / f"{cid}.json").is_file()
    assert (media / "motions" / f"{ids[2]}.bvh").is_file()
    # the delivered files: H.264 yuv420p MP4, no sound unless asked
    from generation.imports.probe import probe_video

    for cid in ids:
        p = probe_video(media / "clips" / f"{cid}.mp4")
        assert (p.video_codec, p.pix_fmt, p.has_audio) == ("h264", "yuv420p", False)
    rows = {r["clip_id"]: r for r in read_clips_csv(media / "clips.csv")}
    assert rows[ids[2]]["origin"] == "imported" and rows[ids[2]]["licence"] == BANDAI_LICENCE
    assert not [p for p in _files(media) if "/." in p or p.startswith(".")]     # no staging or temporary files
    # in pools: by origin, and by modality for the sections that take either modality
    assert set(pool_queryset({"origin": "imported"}).values_list("clip_id", flat=True)) == set(ids)
    assert list(pool_queryset({"modality": "other"}).values_list("clip_id", flat=True)) == [ids[1]]


@pytest.mark.django_db
def test_keep_audio(media, lab):
    from generation.imports.probe import probe_video

    run(write_manifest(lab, [{**GOOD[0], "keep_audio": "yes"}]))
    cid = read_report(lab / "import_report.csv")[0]["clip_id"]
    p = probe_video(media / "clips" / f"{cid}.mp4")
    assert p.has_audio and p.audio_codec == "aac"


def _bad_folder(tmp_path: Path) -> tuple[Path, list[dict]]:
    folder = tmp_path / "lab"
    make_video(folder / "ok.mp4")
    (folder / "broken.mp4").write_bytes(os.urandom(4096))             # not a video at all
    (folder / "empty.mp4").write_bytes(b"")                           # zero-length
    make_video(tmp_path / "outside.mp4")
    (folder / "link.mp4").symlink_to(tmp_path / "outside.mp4")        # a symlink out of the folder
    rows = [
        {"path": "broken.mp4", "modality": "gait"},
        {"path": "empty.mp4", "modality": "gait"},
        {"path": "../outside.mp4", "modality": "gait"},
        {"path": str(tmp_path / "outside.mp4"), "modality": "gait"},
        {"path": "link.mp4", "modality": "gait"},
        {"path": "ok.mp4", "modality": "dance"},
        {"path": "ok.mp4", "modality": "gesture", "valence": "1.5"},
        {"path": "ok.mp4", "modality": "gait", "happy": "-1", "sad": "0", "angry": "0", "neutral": "0"},
        {"path": "ok.mp4", "modality": "gesture", "emotion_label": "bored"},
    ]
    return folder, rows


@pytest.mark.django_db
def test_every_bad_row_is_an_error_and_leaves_nothing(media, tmp_path):
    from studyapp.models import Clip

    folder, rows = _bad_folder(tmp_path)
    run(write_manifest(folder, rows), fail=True)
    report = read_report(folder / "import_report.csv")
    assert [r["status"] for r in report] == ["error"] * len(rows) and all(not r["clip_id"] for r in report)
    msg = [r["message"] for r in report]
    assert "cannot be decoded" in msg[0] and "Invalid data" in msg[0]
    assert "empty file (0 bytes)" in msg[1]
    assert "field 'path'" in msg[2] and "leaves the manifest's folder" in msg[2]
    assert "absolute path" in msg[3]
    assert "leads outside the manifest's folder" in msg[4]
    assert "field 'modality'" in msg[5] and "'dance'" in msg[5]
    assert "field 'valence'" in msg[6] and "0..1" in msg[6]
    assert "field 'happy'" in msg[7] and "0..1" in msg[7]
    assert "field 'emotion_label'" in msg[8] and "'bored'" in msg[8]
    assert all("row " in m for m in msg[2:])             # manifest errors name the row
    assert Clip.objects.count() == 0
    assert _files(media) == set()                          # no media, no record, no poster, no clips.csv


def _zero_frame_videos(folder: Path) -> None:
    """Containers with sound but no picture: an MP4 of an audio stream only, and a Matroska file whose H.264 video
    stream holds zero frames beside one second of audio (ffmpeg's ``select=0`` drops every frame)."""
    folder.mkdir(parents=True, exist_ok=True)
    ffmpeg = [imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-v", "error", "-y"]
    sine = ["-f", "lavfi", "-i", "sine=frequency=440:duration=1"]
    subprocess.run([*ffmpeg, *sine, "-c:a", "aac", str(folder / "sound_only.mp4")], check=True)
    subprocess.run([*ffmpeg, "-f", "lavfi", "-i", "testsrc2=size=64x48:rate=15:duration=1", *sine, "-map", "0:v",
                    "-map", "1:a", "-vf", "select=0", "-c:v", "libx264", "-pix_fmt", "yuv420p", "-c:a", "aac",
                    str(folder / "zero_frames.mkv")], check=True)


@pytest.mark.django_db
@pytest.mark.parametrize("dry_run", [False, True])
def test_a_video_of_zero_frames_is_an_error_and_leaves_nothing(media, tmp_path, dry_run):
    from studyapp.models import Clip

    folder = tmp_path / "lab"
    _zero_frame_videos(folder)
    rows = [{"path": "sound_only.mp4", "modality": "other"}, {"path": "zero_frames.mkv", "modality": "gait"}]
    report = tmp_path / "report.csv"
    with pytest.raises(CommandError, match="2 row\\(s\\) failed"):
        run(write_manifest(folder, rows), "--report", str(report), *(["--dry-run"] if dry_run else []))
    sound_only, zero_frames = read_report(report)
    assert (sound_only["status"], zero_frames["status"]) == ("error", "error")
    assert not sound_only["clip_id"] and not zero_frames["clip_id"]
    assert sound_only["message"] == ("sound_only.mp4: no video stream (the file holds mov,mp4,m4a,3gp,3g2,mj2 "
                                     "without pictures)")
    assert zero_frames["message"] == "zero_frames.mkv: the video stream holds no frames (an empty video)"
    assert Clip.objects.count() == 0 and _files(media) == set()          # no media, no poster, no record, no row


@pytest.mark.django_db
def test_a_too_long_or_too_large_video_is_an_error(media, tmp_path):
    folder = tmp_path / "lab"
    make_video(folder / "long.mp4", seconds=3.0)
    manifest = write_manifest(folder, [{"path": "long.mp4", "modality": "other"}])
    run(manifest, "--max-duration", "2", fail=True)
    assert "longer than the limit of 2 s" in read_report(folder / "import_report.csv")[0]["message"]
    run(manifest, "--max-size-mb", "0.001", fail=True)
    assert "larger than the limit" in read_report(folder / "import_report.csv")[0]["message"]
    assert _files(media) == set()


@pytest.mark.django_db
def test_reimport_is_idempotent(media, lab):
    from studyapp.models import Clip

    manifest = write_manifest(lab, GOOD[:2])
    run(manifest)
    first = read_report(lab / "import_report.csv")
    mtimes = {p: (media / p).stat().st_mtime_ns for p in _files(media) if p != "clips.csv"}
    keys = dict(Clip.objects.values_list("clip_id", "media_key"))
    run(manifest)
    second = read_report(lab / "import_report.csv")
    assert [r["clip_id"] for r in second] == [r["clip_id"] for r in first]
    assert all("already imported" in r["message"] for r in second)
    assert {p: (media / p).stat().st_mtime_ns for p in _files(media) if p != "clips.csv"} == mtimes
    assert dict(Clip.objects.values_list("clip_id", "media_key")) == keys and Clip.objects.count() == 2
    assert len(read_clips_csv(media / "clips.csv")) == 2


@pytest.mark.django_db
def test_a_changed_file_is_a_new_clip_and_retires_the_old_one(media, lab):
    from studyapp.models import Clip

    manifest = write_manifest(lab, GOOD[:1])
    run(manifest)
    old = read_report(lab / "import_report.csv")[0]["clip_id"]
    make_video(lab / "videos/walk.mp4", pattern="testsrc", audio=True)          # the lab re-exported its video
    run(manifest)
    row = read_report(lab / "import_report.csv")[0]
    new = row["clip_id"]
    assert new != old and f"retired {old}" in row["message"]
    assert Clip.objects.get(clip_id=old).retired and not Clip.objects.get(clip_id=new).retired
    assert (media / "clips" / f"{old}.mp4").is_file()                            # retired, never deleted
    assert {r["clip_id"] for r in read_clips_csv(media / "clips.csv")} == {old, new}


@pytest.mark.django_db
def test_dry_run_writes_nothing(media, lab):
    from studyapp.models import Clip

    out = run(write_manifest(lab, GOOD), "--dry-run", *TINY)
    assert "dry run: 3 of 3 row(s) checked and would import, nothing written" in out and "would transcode vp9" in out
    assert "row(s) imported" not in out and "no report written" in out
    assert Clip.objects.count() == 0 and _files(media) == set() and not (lab / "import_report.csv").exists()


@pytest.mark.django_db
def test_a_failing_dry_run_says_nothing_was_imported_and_where_the_report_is(media, lab, tmp_path):
    manifest = write_manifest(lab, [GOOD[0], {"path": "missing.mp4", "modality": "gait"}])
    with pytest.raises(CommandError) as failed:
        run(manifest, "--dry-run")
    assert str(failed.value) == "1 row(s) failed the check (see the rows above); dry run: nothing was imported"
    report = tmp_path / "checked.csv"
    with pytest.raises(CommandError) as failed:
        run(manifest, "--dry-run", "--report", str(report))
    assert f"(see the report {report}); dry run: nothing was imported" in str(failed.value)
    assert [r["status"] for r in read_report(report)] == ["ok", "error"] and _files(media) == set()


def test_a_dry_run_says_a_long_take_will_be_cut(lab):
    from generation.imports import ImportSettings, import_manifest
    from generation.render.settings import RenderSettings

    settings = ImportSettings(render=RenderSettings(duration_s=2.0))
    (out,) = import_manifest(write_manifest(lab, GOOD[2:]), lab / "media", settings, dry_run=True)
    assert out.status == "ok" and not (lab / "media").exists()
    assert "would render the first 2.00 s of 7.10 s of motion (cut to the render length, 2 s)" in out.message


@pytest.mark.django_db
def test_a_failing_catalogue_step_undoes_the_row(media, lab, monkeypatch):
    from studyapp.data import catalogue
    from studyapp.models import Clip

    run(write_manifest(lab, GOOD[1:2]))
    before = _files(media)
    csv_before = (media / "clips.csv").read_bytes()

    def broken(records):
        raise RuntimeError("database went away")

    monkeypatch.setattr("studyapp.management.commands.import_clips.upsert_clips", broken)
    run(write_manifest(lab, GOOD[:1]), fail=True)
    assert "database went away" in read_report(lab / "import_report.csv")[0]["message"]
    assert _files(media) == before and (media / "clips.csv").read_bytes() == csv_before
    assert Clip.objects.count() == 1 and catalogue.Clip is Clip


def test_manifest_refuses_unknown_columns(tmp_path):
    from generation.imports import ManifestError

    (tmp_path / "m.csv").write_text("path,modality,hapy\na.mp4,gait,1\n")
    with pytest.raises(ManifestError, match="'hapy': not a manifest column"):
        read_manifest(tmp_path / "m.csv")


@pytest.mark.parametrize("delimiter", [";", "\t"])
def test_a_semicolon_or_tab_separated_manifest_is_read(tmp_path, delimiter):
    """As a spreadsheet in a decimal-comma locale saves CSV: semicolons (or tabs) between cells, decimal commas in
    the labels, commas inside text cells."""
    (tmp_path / "walk.mp4").write_bytes(b"not probed here")
    header = ["path", "modality", "happy", "sad", "angry", "neutral", "valence", "citation"]
    cells = ["walk.mp4", "gait", "0,75", "0", "0", "0,25", "0,6", "Doe, J. and Roe, R. (2026)"]
    (tmp_path / "m.csv").write_text(f"{delimiter.join(header)}\n{delimiter.join(cells)}\n", encoding="utf-8")
    (row,) = read_manifest(tmp_path / "m.csv")
    assert row.labels == {"happy": 0.75, "sad": 0.0, "angry": 0.0, "neutral": 0.25, "valence": 0.6}
    assert row.text["citation"] == "Doe, J. and Roe, R. (2026)" and row.modality == "gait"


def test_column_names_that_differ_in_case_name_the_expected_column(tmp_path):
    from generation.imports import ManifestError

    (tmp_path / "m.csv").write_text("path,modality,Title\na.mp4,gait,walk\n")
    with pytest.raises(ManifestError, match="'Title': not a manifest column .*; column names are lower case: "
                                            "write 'title'"):
        read_manifest(tmp_path / "m.csv")
    (tmp_path / "m.csv").write_text("Path;Modality\na.mp4;gait\n")
    with pytest.raises(ManifestError, match="'path': missing column .*write 'path' for 'Path'"):
        read_manifest(tmp_path / "m.csv")
    (tmp_path / "m.csv").write_text("path,modality,hapy\na.mp4,gait,1\n")
    with pytest.raises(ManifestError, match="did you mean 'happy'"):
        read_manifest(tmp_path / "m.csv")


@pytest.mark.django_db
def test_imported_clips_in_the_naturalness_analysis(media, lab):
    from analysis.io import read_clips
    from analysis.naturalness import naturalness

    run(write_manifest(lab, GOOD[:2]))
    clips = read_clips(media / "clips.csv")
    gait, other = (clips.index[clips["modality"] == m][0] for m in ("gait", "other"))
    responses = pd.DataFrame({"participant_id": ["p1", "p1", "p2"], "section_type": ["naturalness"] * 3,
                              "clip_id": [gait, other, gait], "value": [4, 2, 5]})
    table = naturalness(responses, clips)
    assert set(table["origin"]) == {"imported"} and set(table["modality"]) == {"gait", "other"}
    assert table.set_index("modality").loc["gait", "n"] == 2


# ---- the admin upload ------------------------------------------------------------------------------------
@pytest.fixture
def staff(db):
    from django.contrib.auth.models import User
    from django.test import Client

    user = User.objects.create_superuser("importer", "i@example.org", "pw")
    client = Client()
    client.force_login(user)
    return client


@pytest.fixture
def inline_jobs(monkeypatch):
    """Run the import job in this process (the admin starts it detached; the test waits for nothing)."""
    from studyapp.data import clip_import

    def launch(cmd, job):
        assert cmd[2] == "import_clips" and cmd[1].endswith("manage.py")
        out = io.StringIO()
        with contextlib.suppress(CommandError):
            call_command(*cmd[2:], "--no-observer", "--render-size", "96x64", stdout=out)
        (clip_import.job_dir(job) / clip_import.LOG_NAME).write_text(out.getvalue())

    monkeypatch.setattr(clip_import, "launch", launch)


def _upload(path: Path, name: str | None = None):
    from django.core.files.uploadedfile import SimpleUploadedFile

    return SimpleUploadedFile(name or path.name, path.read_bytes())


@pytest.mark.django_db
def test_admin_upload_of_a_manifest_and_its_files(media, lab, staff, inline_jobs):
    from django.urls import reverse

    from studyapp.models import Clip

    changelist = staff.get(reverse("admin:studyapp_clip_changelist")).content.decode()
    assert reverse("admin:studyapp_clip_import") in changelist
    rows = [{**GOOD[0], "path": "walk.mp4"}, {**GOOD[1], "path": "face.webm"}, {"path": "missing.mp4",
                                                                                "modality": "gait"}]
    manifest = write_manifest(lab, rows, "lab_stimuli.csv")
    resp = staff.post(reverse("admin:studyapp_clip_import"), {
        "manifest": _upload(manifest), "files": [_upload(lab / "videos/walk.mp4"), _upload(lab / "videos/face.webm")],
        "collection": "spring"})
    assert resp.status_code == 302, resp.content.decode()[:2000]
    page = staff.get(resp["Location"]).content.decode()
    assert "Status: <strong>done</strong>" in page and "2 of 3 row(s) imported" in page
    assert "no such file &#x27;missing.mp4&#x27;" in page
    from django.conf import settings
    assert str(settings.DATA_DIR) not in page and str(media) not in page       # no server layout shown
    clips = Clip.objects.filter(origin="imported")
    assert clips.count() == 2 and {c.plan for c in clips} == {"import:upload/importer/spring"}
    assert {c.licence for c in clips} == {"CC0", "CC BY 4.0"}


@pytest.mark.django_db
def test_admin_dry_run_says_what_would_be_imported(media, lab, staff, inline_jobs):
    from django.urls import reverse

    from studyapp.models import Clip

    manifest = write_manifest(lab, [{**GOOD[0], "path": "walk.mp4"}], "spring.csv")
    resp = staff.post(reverse("admin:studyapp_clip_import"), {
        "manifest": _upload(manifest), "files": [_upload(lab / "videos/walk.mp4")], "dry_run": "on"})
    page = staff.get(resp["Location"]).content.decode()
    assert "(dry run: every row is checked, nothing is imported)" in page
    assert "1 of 1 row(s) checked and would import" in page and "row(s) imported" not in page
    assert "Collection: <code>import:upload/importer/spring</code>" in page and not Clip.objects.exists()


@pytest.mark.django_db
def test_admin_upload_of_a_zip(media, lab, staff, inline_jobs, tmp_path):
    import zipfile

    from django.urls import reverse

    from studyapp.models import Clip

    manifest = write_manifest(lab, GOOD)
    archive = tmp_path / "stimuli.zip"
    with zipfile.ZipFile(archive, "w") as zf:
        zf.write(manifest, "manifest.csv")
        for rel in ("videos/walk.mp4", "videos/face.webm", "mocap/walk_happy.bvh"):
            zf.write(lab / rel, rel)
    resp = staff.post(reverse("admin:studyapp_clip_import"), {"archive": _upload(archive)})
    assert resp.status_code == 302
    page = staff.get(resp["Location"]).content.decode()
    assert "3 of 3 row(s) imported" in page and Clip.objects.filter(origin="imported").count() == 3

    evil = tmp_path / "evil.zip"
    with zipfile.ZipFile(evil, "w") as zf:
        zf.write(manifest, "manifest.csv")
        zf.writestr("../escape.mp4", b"x")
    resp = staff.post(reverse("admin:studyapp_clip_import"), {"archive": _upload(evil)})
    assert resp.status_code == 200 and "must stay inside the upload" in resp.content.decode()
    assert not (media.parent / "data" / "escape.mp4").exists()


def _zip_of(manifest: Path, files: dict[str, Path], archive: Path) -> Path:
    import zipfile

    archive.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(archive, "w") as zf:
        zf.write(manifest, "manifest.csv")
        for arcname, path in files.items():
            zf.write(path, arcname)
    return archive


def _client_of(username: str):
    from django.contrib.auth.models import User
    from django.test import Client

    client = Client()
    client.force_login(User.objects.create_superuser(username, f"{username}@example.org", "pw"))
    return client


@pytest.mark.django_db
def test_uploads_of_two_users_never_retire_each_others_clips(media, lab, tmp_path, inline_jobs):
    """Two labs upload a stimuli.zip with a manifest.csv naming walk.mp4, each its own video: each upload is its
    own collection (the user's, named after the zip), so neither retires the other's clip; within one collection
    a changed file still retires the older clip."""
    from django.urls import reverse

    from studyapp.models import Clip

    manifest = write_manifest(lab, GOOD[:1])
    videos = {"lab-a": lab / "videos/walk.mp4", "lab-b": make_video(tmp_path / "other/walk.mp4", pattern="testsrc")}
    clients = {user: _client_of(user) for user in videos}
    url = reverse("admin:studyapp_clip_import")

    def upload(user: str):
        archive = _zip_of(manifest, {"videos/walk.mp4": videos[user]}, tmp_path / user / "stimuli.zip")
        resp = clients[user].post(url, {"archive": _upload(archive)})
        assert resp.status_code == 302, resp.content.decode()[:2000]
        return Clip.objects.get(plan=f"import:upload/{user}/stimuli", retired=False)

    clip_of = {user: upload(user) for user in videos}
    assert clip_of["lab-a"].clip_id != clip_of["lab-b"].clip_id
    assert not Clip.objects.filter(retired=True).exists()

    make_video(videos["lab-a"], pattern="smptebars")                               # lab A re-exports its video
    assert upload("lab-a").clip_id != clip_of["lab-a"].clip_id
    retired = set(Clip.objects.filter(retired=True).values_list("clip_id", flat=True))
    assert retired == {clip_of["lab-a"].clip_id}                                   # lab B's clip stays


@pytest.mark.django_db
def test_a_file_of_another_collection_is_refused_not_taken_over(media, lab, staff, inline_jobs, tmp_path):
    """The same file uploaded after the command imported it stays the command's clip, labels and collection."""
    from django.urls import reverse

    from studyapp.models import Clip

    run(write_manifest(lab, GOOD[:1]))
    clip = Clip.objects.get()
    catalogue = (media / "clips.csv").read_bytes()
    archive = _zip_of(write_manifest(tmp_path, [{**GOOD[0], "citation": "another lab"}]),
                      {"videos/walk.mp4": lab / "videos/walk.mp4"}, tmp_path / "mine.zip")
    resp = staff.post(reverse("admin:studyapp_clip_import"), {"archive": _upload(archive)})
    page = staff.get(resp["Location"]).content.decode()
    assert "0 of 1 row(s) imported" in page
    assert f"already clip {clip.clip_id} of the collection &#x27;import:lab/manifest&#x27;" in page
    clip.refresh_from_db()
    assert clip.plan == "import:lab/manifest" and clip.citation == "Our lab 2026" and not clip.retired
    assert (media / "clips.csv").read_bytes() == catalogue


@pytest.mark.django_db
def test_a_dry_run_already_says_a_file_belongs_to_another_collection(media, lab):
    from studyapp.models import Clip

    run(write_manifest(lab, GOOD[:1]))
    clip_id = Clip.objects.get().clip_id
    out = run(write_manifest(lab, GOOD[:1]), "--dry-run", "--name", "other", fail=True)
    assert f"already clip {clip_id} of the collection 'import:lab/manifest'" in out
    assert Clip.objects.get().plan == "import:lab/manifest"


@pytest.mark.django_db
def test_admin_import_needs_the_add_clip_permission(db):
    from django.contrib.auth.models import User
    from django.test import Client
    from django.urls import reverse

    user = User.objects.create_user("viewer", password="pw", is_staff=True)
    client = Client()
    client.force_login(user)
    assert client.get(reverse("admin:studyapp_clip_import")).status_code == 403


@pytest.mark.django_db
def test_webm_delivery_and_a_file_given_twice(media, lab):
    from studyapp.models import Clip

    manifest = write_manifest(lab, [GOOD[1], {**GOOD[1], "title": "again"}])
    run(manifest, "--webm", fail=True)
    first, second = read_report(lab / "import_report.csv")
    assert first["status"] == "ok" and second["status"] == "error" and "the same clip as row 1" in second["message"]
    clip = Clip.objects.get()
    assert clip.webm == f"clips/{clip.clip_id}.webm" and (media / clip.webm).stat().st_size > 0


def test_other_clips_only_in_sections_that_take_either_modality():
    from protocol.pools import pool_errors

    assert pool_errors({"origin": "imported", "modality": "other"}, "naturalness") == []
    assert any("gait clips" in e for e in pool_errors({"modality": "other"}, "emotion_choice"))
    assert any("'origin'" in e for e in pool_errors({"origin": "uploaded"}, "naturalness"))


def test_zip_members_that_leave_the_upload_are_refused(tmp_path):
    import zipfile

    from studyapp.data.clip_import import UploadError, unpack_zip

    archive = tmp_path / "a.zip"
    with zipfile.ZipFile(archive, "w") as zf:
        info = zipfile.ZipInfo("videos/link.mp4")
        info.external_attr = (0o120777 << 16)                       # a symlink member
        zf.writestr(info, "/etc/passwd")
    with pytest.raises(UploadError, match="links are not imported"):
        unpack_zip(archive, tmp_path / "out")
    with zipfile.ZipFile(archive, "w") as zf:
        zf.writestr("/abs.mp4", b"x")
    with pytest.raises(UploadError, match="must stay inside"):
        unpack_zip(archive, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_staging_left_by_a_killed_import_is_removed(tmp_path):
    from generation.imports.run import STAGING_DIR, remove_stale_staging

    dead = subprocess.Popen(["true"])
    dead.wait()
    stale = tmp_path / STAGING_DIR / f"{dead.pid}-abcd1234"
    stale.mkdir(parents=True)
    (stale / "x.mp4").write_bytes(b"half a file")
    mine = tmp_path / STAGING_DIR / f"{os.getpid()}-abcd1234"
    mine.mkdir()
    assert remove_stale_staging(tmp_path) == [stale] and mine.is_dir()


@pytest.mark.django_db
def test_a_collection_too_long_for_the_plan_field_is_refused_not_cut(media, lab):
    from studyapp.data.clip_import import UploadError, collection_name

    with pytest.raises(CommandError, match="too long"):
        call_command("import_clips", str(write_manifest(lab, GOOD[:1])), "--name", "x" * 200, stdout=io.StringIO())
    with pytest.raises(UploadError, match="too long"):
        collection_name("u" * 150, "spring")
    assert collection_name("ann", "spring") == "upload/ann/spring"
