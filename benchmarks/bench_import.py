"""Benchmark of ``import_clips``: import time per minute of 1080p video, and of one BVH take.

Synthetic 1080p30 test videos (ffmpeg's testsrc2 pattern with a 440 Hz tone; made first, not timed) go through
the Django-free import (:func:`generation.imports.import_manifest`, no catalogue step: the Clip row costs
milliseconds) into a temporary MEDIA_ROOT:
- an H.264 MP4 with AAC: remuxed (stream copy, audio stripped), then every frame decoded once, and a poster;
- an MPEG-4 part 2 MOV and a VP9 WebM: transcoded to H.264 (x264 veryfast, CRF 23, as generated clips), a poster;
- one Bandai Namco BVH take (the shipped dataset-1 walk, CC BY-NC 4.0): the importer's checks, a 10 s 1280x720
  mannequin render and the quality record (observer included).
Reported per file: wall seconds, seconds per minute of video, and the speed as a multiple of real time.

Usage: python -m benchmarks.bench_import [--seconds 60] [--no-vp9] [--md docs/benchmarks/import.md]
"""
from __future__ import annotations

import argparse
import csv
import json
import subprocess
import tempfile
import time
from pathlib import Path

import imageio_ffmpeg

from benchmarks.bench_record import commit_label, machine_label, record
from generation.imports import ImportSettings, import_manifest
from generation.imports.manifest import MANIFEST_COLUMNS
from generation.render.offscreen import prepare_render_process

ROOT = Path(__file__).resolve().parents[1]
BVH = (ROOT / "generation/data/mocap/bandai-namco/Bandai-Namco-Research-Motiondataset-1/data"
       / "dataset-1_walk_happy_001.bvh")
SOURCES = {
    "h264_mp4": ("video.mp4", ["-c:v", "libx264", "-preset", "veryfast", "-pix_fmt", "yuv420p", "-c:a", "aac"]),
    "mpeg4_mov": ("video.mov", ["-c:v", "mpeg4", "-q:v", "4", "-c:a", "aac"]),
    "vp9_webm": ("video.webm", ["-c:v", "libvpx-vp9", "-deadline", "realtime", "-cpu-used", "8", "-b:v", "4M",
                                "-row-mt", "1", "-c:a", "libopus"]),
}


def make_source(folder: Path, kind: str, seconds: float) -> Path:
    name, args = SOURCES[kind]
    path = folder / kind / name
    path.parent.mkdir(parents=True)
    subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-v", "error", "-y", "-f", "lavfi", "-i",
                    f"testsrc2=size=1920x1080:rate=30:duration={seconds}", "-f", "lavfi", "-i",
                    f"sine=frequency=440:duration={seconds}", *args, "-shortest", str(path)], check=True)
    return path


def time_import(file: Path, modality: str, media: Path, settings: ImportSettings) -> dict:
    manifest = file.parent / "manifest.csv"
    with manifest.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=MANIFEST_COLUMNS)
        w.writeheader()
        w.writerow({"path": file.name, "modality": modality})
    t0 = time.perf_counter()
    [out] = import_manifest(manifest, media, settings)
    seconds = time.perf_counter() - t0
    if out.status != "ok":
        raise RuntimeError(f"{file.name}: {out.message}")
    rec = out.record
    duration = rec["duration_s"]
    return {"file": file.name, "action": rec["metadata"]["action"], "message": out.message,
            "source_mib": round(file.stat().st_size / 2**20, 1), "video_s": duration,
            "delivered_mib": round((media / rec["video"]).stat().st_size / 2**20, 1),
            "import_s": round(seconds, 1), "s_per_video_minute": round(60.0 * seconds / duration, 1),
            "x_realtime": round(duration / seconds, 2)}


def markdown(result: dict) -> str:
    lines = [f"## Import time ({result['date']})", "",
             f"`python -m benchmarks.bench_import --seconds {result['seconds']:g}` on {result['machine_label']} "
             f"(1-minute load average {result['load_average_1m']} when it finished; {result['commit']}). Synthetic "
             "1080p30 test videos (ffmpeg testsrc2 + a 440 Hz tone), ffmpeg threads: automatic.", "",
             "| file | what the import does | source MiB | video s | delivered MiB | import s | s per minute of "
             "video | x real time |", "|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['file']} | {r['message']} | {r['source_mib']} | {r['video_s']:g} | "
                     f"{r['delivered_mib']} | {r['import_s']} | {r['s_per_video_minute']} | {r['x_realtime']} |")
    lines += ["", "A remux is a stream copy, one full decode of the delivered MP4 (every frame must decode) and the "
              "poster: the decode is most of its time. A transcode decodes the source and encodes H.264 at 1080p; "
              "the BVH row is the importer's checks, a 1280x720 mannequin render (software GL) and the quality "
              "record, per clip (its \"per minute\" is per minute of rendered clip). On a machine shared with other "
              "jobs (a load average well above the CPU count) times are upper bounds and vary between runs."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="length of each test video (default 60)")
    ap.add_argument("--no-vp9", action="store_true", help="skip the VP9 WebM (its source is slow to make)")
    ap.add_argument("--no-bvh", action="store_true", help="skip the BVH take")
    ap.add_argument("--md", default=str(ROOT / "docs/benchmarks/import.md"), help="markdown file to write")
    ap.add_argument("--json", default=str(ROOT / "docs/benchmarks/import.json"), help="JSON record to write")
    ap.add_argument("--from-json", default=None, help="only write the markdown of an earlier JSON record")
    args = ap.parse_args(argv)
    if args.from_json:
        write_markdown(json.loads(Path(args.from_json).read_text()), args.md)
        return 0
    prepare_render_process()
    settings = ImportSettings()
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-import-") as tmp:
        tmp = Path(tmp)
        kinds = [k for k in SOURCES if not (args.no_vp9 and k == "vp9_webm")]
        for kind in kinds:
            src = make_source(tmp / "src", kind, args.seconds)
            rows.append(time_import(src, "other", tmp / f"media-{kind}", settings))
            print(rows[-1], flush=True)
        if not args.no_bvh:
            folder = tmp / "src" / "bvh"
            folder.mkdir(parents=True)
            (folder / BVH.name).write_bytes(BVH.read_bytes())
            rows.append(time_import(folder / BVH.name, "gait", tmp / "media-bvh", settings))
            print(rows[-1], flush=True)
    result = record({"benchmark": "bench_import", "seconds": args.seconds, "machine_label": machine_label(),
                     "commit": commit_label(), "rows": rows}, args.json)
    write_markdown(result, args.md)
    return 0


def write_markdown(result: dict, path: str | Path) -> None:
    text = markdown(result)
    Path(path).write_text("# Import benchmark\n\nImporting researchers' own stimuli (`manage.py import_clips`, "
                          "docs/study.md \"Bring your own stimuli\").\n\n" + text)
    print(text)


if __name__ == "__main__":
    raise SystemExit(main())
