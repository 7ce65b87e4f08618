"""Imports under attack: ffmpeg reads only the demuxer the extension names (a DASH manifest saved as walk.mp4 is
refused, not followed to a video outside the upload), a BVH over the size limit is refused before it is parsed,
every malformed zip is a clear error on the upload page (never a 500) and leaves no folder, and the upload folder
is removed when the job ends (imported, failed or dry run).

The videos are synthetic test patterns made with the bundled ffmpeg
(tests/studyapp/data/test_import_clips.make_video)."""
from __future__ import annotations

import struct
import zipfile
from pathlib import Path

import pytest
from django.core.files.uploadedfile import SimpleUploadedFile
from django.urls import reverse

from generation.imports.probe import VideoProbeError, probe_video
from studyapp.data import clip_import
from tests.studyapp.data import test_import_clips as base
from tests.studyapp.data.test_import_clips import BVH, GOOD, make_video, read_report, run, write_manifest

media, lab, staff, inline_jobs = base.media, base.lab, base.staff, base.inline_jobs      # shared fixtures

DASH = """<?xml version="1.0"?>
<MPD xmlns="urn:mpeg:dash:schema:mpd:2011" type="static" mediaPresentationDuration="PT1S" minBufferTime="PT1S"
     profiles="urn:mpeg:dash:profile:isoff-on-demand:2011"><Period><AdaptationSet mimeType="video/mp4">
<Representation id="1" bandwidth="1000" codecs="avc1.42c01e" width="64" height="48">
<BaseURL>file://{outside}</BaseURL></Representation></AdaptationSet></Period></MPD>
"""
HLS = "#EXTM3U\n#EXT-X-TARGETDURATION:1\n#EXTINF:1.0,\nfile://{outside}\n#EXT-X-ENDLIST\n"


@pytest.fixture
def outside(tmp_path) -> Path:
    """A video outside any upload: what a reference format would make ffmpeg read."""
    return make_video(tmp_path / "elsewhere" / "secret.mp4")


@pytest.mark.parametrize("name, text", [("walk.mp4", DASH), ("walk.mkv", HLS), ("walk.mov", HLS)])
def test_a_reference_format_under_a_video_name_is_refused(tmp_path, outside, name, text):
    fake = tmp_path / "lab" / name
    fake.parent.mkdir()
    fake.write_text(text.format(outside=outside))
    with pytest.raises(VideoProbeError, match="cannot be decoded"):
        probe_video(fake)
    assert probe_video(outside).video_codec == "h264"            # the same ffmpeg reads the real video


def test_an_extension_outside_the_allow_list_is_refused(tmp_path, outside):
    from generation.imports.probe import input_args

    with pytest.raises(VideoProbeError, match="not a video type the import reads"):
        input_args(tmp_path / "walk.mpd")
    assert input_args(outside)[:2] == ["-f", "mov"]


@pytest.mark.django_db
def test_the_dash_manifest_is_an_error_row_and_no_clip(media, tmp_path, outside):
    from studyapp.models import Clip

    folder = tmp_path / "lab"
    folder.mkdir()
    (folder / "walk.mp4").write_text(DASH.format(outside=outside))
    run(write_manifest(folder, [{"path": "walk.mp4", "modality": "gait"}]), fail=True)
    (row,) = read_report(folder / "import_report.csv")
    assert row["status"] == "error" and "cannot be decoded" in row["message"]
    assert not Clip.objects.exists()


@pytest.mark.django_db
def test_a_100_mb_bvh_is_refused_before_parsing(media, tmp_path, monkeypatch):
    from generation.formats import bvh

    folder = tmp_path / "lab"
    folder.mkdir()
    with (folder / "huge.bvh").open("wb") as f:
        f.write(BVH.read_bytes())
        f.truncate(100 * 1000 * 1000)
    parsed = []
    monkeypatch.setattr(bvh, "_Tokens", lambda *a, **k: parsed.append(a) or pytest.fail("the BVH was parsed"))
    run(write_manifest(folder, [{"path": "huge.bvh", "modality": "gait"}]), fail=True)
    (row,) = read_report(folder / "import_report.csv")
    assert row["status"] == "error" and "larger than the BVH limit of 32 MiB" in row["message"], row
    assert parsed == []


# ---- zips ----------------------------------------------------------------------------------------------------
def _patch_zip(path: Path, *, method: int | None = None, file_size: int | None = None) -> None:
    """Rewrite the first member's compression method or declared size in both its headers."""
    data = bytearray(path.read_bytes())
    local = data.find(b"PK\x03\x04")
    central = data.find(b"PK\x01\x02")
    if method is not None:
        struct.pack_into("<H", data, local + 8, method)
        struct.pack_into("<H", data, central + 10, method)
    if file_size is not None:
        struct.pack_into("<I", data, local + 22, file_size)
        struct.pack_into("<I", data, central + 24, file_size)
    path.write_bytes(bytes(data))


def malformed_zips(folder: Path, manifest: Path) -> dict[str, tuple[Path, str]]:
    """name -> (archive, words its error must say)."""
    out = {}

    def new(name: str) -> zipfile.ZipFile:
        path = folder / f"{name}.zip"
        out[name] = (path, "")
        return zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED)

    with new("file_and_folder") as zf:
        zf.write(manifest, "manifest.csv")
        zf.writestr("videos", b"a file")
        zf.writestr("videos/walk.mp4", b"a file in a folder of the same name")
    out["file_and_folder"] = (out["file_and_folder"][0], "a file and a folder of the same name")
    with new("long_name") as zf:
        zf.write(manifest, "manifest.csv")
        zf.writestr("v" * 300 + ".mp4", b"x")
    out["long_name"] = (out["long_name"][0], "longer than 255 bytes")
    path = folder / "method_99.zip"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as zf:
        zf.writestr("manifest.csv", "path,modality\nwalk.mp4,gait\n")
    _patch_zip(path, method=99)
    out["method_99"] = (path, "compression method 99 is not supported")
    path = folder / "false_size.zip"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("manifest.csv", "path,modality\n" + "walk.mp4,gait\n" * 2000)
    _patch_zip(path, file_size=10)
    out["false_size"] = (path, "cannot be unpacked")
    with new("too_many") as zf:
        zf.write(manifest, "manifest.csv")
        for i in range(clip_import.MAX_ZIP_MEMBERS):
            zf.writestr(f"empty/{i}.txt", b"")
    out["too_many"] = (out["too_many"][0], f"more than {clip_import.MAX_ZIP_MEMBERS}")
    with new("bomb") as zf:
        zf.write(manifest, "manifest.csv")
        zf.writestr("walk.mp4", bytes(64 * 2**20))
    out["bomb"] = (out["bomb"][0], "not an archive of stimuli")
    (folder / "not_a.zip").write_bytes(b"PK\x03\x04 but nothing else")
    out["not_a_zip"] = (folder / "not_a.zip", "not a zip file")
    return out


@pytest.mark.django_db
def test_every_malformed_zip_is_a_clear_error_and_leaves_no_folder(media, lab, staff, tmp_path):
    folder = tmp_path / "zips"
    folder.mkdir()
    url = reverse("admin:studyapp_clip_import")
    for name, (archive, words) in malformed_zips(folder, write_manifest(lab, GOOD[:1])).items():
        resp = staff.post(url, {"archive": SimpleUploadedFile(archive.name, archive.read_bytes())})
        page = resp.content.decode()
        assert resp.status_code == 200, (name, resp.status_code)
        assert words in page.replace("&#x27;", "'"), (name, page[page.find("errornote"):][:600])
        jobs = clip_import.imports_dir()
        assert not jobs.exists() or not any(jobs.iterdir()), f"{name}: a job folder stayed"


@pytest.mark.django_db
def test_an_upload_over_the_size_limit_is_refused_before_it_is_saved(media, staff, monkeypatch):
    monkeypatch.setattr(clip_import, "MAX_UPLOAD_BYTES", 1000)
    resp = staff.post(reverse("admin:studyapp_clip_import"),
                      {"manifest": SimpleUploadedFile("m.csv", b"path,modality\n" + b"x.mp4,gait\n" * 200)})
    assert resp.status_code == 200 and "larger than the upload limit" in resp.content.decode()
    assert not clip_import.imports_dir().exists() or not any(clip_import.imports_dir().iterdir())


@pytest.mark.django_db
@pytest.mark.parametrize("case", ["imported", "failed", "dry_run"])
def test_the_upload_folder_is_gone_after_the_job(media, lab, staff, inline_jobs, case):
    rows = [{**GOOD[0], "path": "walk.mp4"}] if case != "failed" else [{"path": "missing.mp4", "modality": "gait"}]
    manifest = write_manifest(lab, rows, "spring.csv")
    data = {"manifest": SimpleUploadedFile(manifest.name, manifest.read_bytes()),
            "files": [SimpleUploadedFile("walk.mp4", (lab / "videos/walk.mp4").read_bytes())]}
    if case == "dry_run":
        data["dry_run"] = "on"
    resp = staff.post(reverse("admin:studyapp_clip_import"), data)
    assert resp.status_code == 302
    job = resp["Location"].rstrip("/").split("/")[-1]
    folder = clip_import.job_dir(job)
    assert not (folder / clip_import.FILES_DIR).exists(), f"{case}: the upload stayed"
    page = staff.get(resp["Location"]).content.decode()
    assert ("row(s) failed" in page or "missing.mp4" in page) if case == "failed" else "1 of 1 row(s)" in page


@pytest.mark.django_db
def test_a_killed_jobs_upload_is_removed_when_its_status_is_read(media, lab):
    import subprocess

    manifest = write_manifest(lab, GOOD[:1])
    job, _ = clip_import.save_upload(SimpleUploadedFile("manifest.csv", manifest.read_bytes()))
    dead = subprocess.Popen(["true"])
    dead.wait()
    (clip_import.job_dir(job) / clip_import.PID_NAME).write_text(str(dead.pid))
    assert (clip_import.job_dir(job) / clip_import.FILES_DIR).is_dir()
    assert clip_import.import_state(job).status == "failed"
    assert not (clip_import.job_dir(job) / clip_import.FILES_DIR).exists()


@pytest.mark.django_db
def test_a_manifest_over_its_limit_is_refused_before_it_is_read(media, tmp_path, monkeypatch):
    from django.core.management import CommandError

    from generation.imports import manifest as manifest_module

    folder = tmp_path / "lab"
    folder.mkdir()
    path = write_manifest(folder, [{"path": f"walk{i}.mp4", "modality": "gait"} for i in range(50)])
    monkeypatch.setattr(manifest_module, "MAX_MANIFEST_BYTES", 100)
    with pytest.raises(CommandError, match="larger than the manifest limit"):
        run(path)
