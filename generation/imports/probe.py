"""What a video file holds, as the bundled ffmpeg (imageio-ffmpeg) reads it: container, codecs, duration, frame
size, frame rate and audio. ``ffmpeg -i`` prints the streams of its input on stderr; ffprobe is not bundled.

ffmpeg never chooses its reader from a file's content: :func:`input_args` names the demuxer from the file's extension
(:data:`DEMUXERS`, an allow-list of self-contained containers: no dash, hls, concat or other formats that refer to
further files or URLs) and allows only the ``file`` protocol, so a playlist saved as ``walk.mp4`` is a decoding
error, not a read of a video outside the upload. A file ffmpeg cannot open raises :class:`VideoProbeError` with
ffmpeg's reason; :func:`decode_check` decodes every
video frame (``-xerror``: the first corrupt packet fails) for files whose streams are kept as they are.
"""
from __future__ import annotations

import re
import subprocess
from dataclasses import asdict, dataclass
from pathlib import Path

import imageio_ffmpeg

_INPUT = re.compile(r"^Input #0, (?P<formats>[^,]+(?:,[^,\s]+)*), from ", re.M)
_DURATION = re.compile(r"Duration: (?P<h>\d+):(?P<m>\d\d):(?P<s>\d\d(?:\.\d+)?)")
_VIDEO = re.compile(r"Stream #0:\d+[^:]*: Video: (?P<codec>[\w-]+)(?P<rest>.*)$", re.M)
_AUDIO = re.compile(r"Stream #0:\d+[^:]*: Audio: (?P<codec>[\w-]+)", re.M)
_SIZE = re.compile(r"(?<![\w.])(?P<w>\d{2,5})x(?P<h>\d{2,5})(?![\w.])")
_FPS = re.compile(r"(?P<fps>\d+(?:\.\d+)?) (?:fps|tbr)")


DEMUXERS = {".mp4": "mov", ".m4v": "mov", ".mov": "mov", ".webm": "matroska", ".mkv": "matroska", ".avi": "avi"}
"""File extension -> the one ffmpeg demuxer that may read it (``mov`` reads no external data references unless
asked: ``enable_drefs`` stays off)."""


class VideoProbeError(ValueError):
    """A video ffmpeg cannot open or decode; the message names the file and ffmpeg's reason."""


def input_args(path: Path) -> list[str]:
    """ffmpeg input options for ``path``: its demuxer named from the extension (:data:`DEMUXERS`), only local files,
    then ``-i path``; VideoProbeError for an extension outside the allow-list."""
    demuxer = DEMUXERS.get(Path(path).suffix.lower())
    if demuxer is None:
        raise VideoProbeError(f"{Path(path).name}: not a video type the import reads ({', '.join(DEMUXERS)})")
    return ["-f", demuxer, "-protocol_whitelist", "file", "-i", str(path)]


@dataclass(frozen=True)
class VideoProbe:
    """The facts of one video file.

    container: ffmpeg's demuxer names (``mov,mp4,m4a,3gp,3g2,mj2``, ``matroska,webm``...); video_codec and
    pix_fmt of the first video stream (``h264``, ``yuv420p``); width, height in pixels; fps (frames/s, 0 when
    unknown); duration_s (seconds, 0 when unknown); audio_codec ("" without audio); size_bytes of the file."""

    container: str
    video_codec: str
    pix_fmt: str
    width: int
    height: int
    fps: float
    duration_s: float
    audio_codec: str
    size_bytes: int

    @property
    def has_audio(self) -> bool:
        return bool(self.audio_codec)

    def as_dict(self) -> dict:
        return {**asdict(self), "has_audio": self.has_audio}


def ffmpeg_exe() -> str:
    return imageio_ffmpeg.get_ffmpeg_exe()


def _reason(stderr: str) -> str:
    """ffmpeg's own complaint: the last meaningful line of its log."""
    lines = [ln.strip() for ln in stderr.splitlines() if ln.strip()
             and not ln.startswith(("At least one output file", "Use -h", "  "))]
    return lines[-1] if lines else "ffmpeg gave no reason"


def probe_video(path: str | Path, timeout_s: float = 60.0) -> VideoProbe:
    """Read the streams of ``path`` with ``ffmpeg -i``; VideoProbeError when it is no video ffmpeg can open."""
    path = Path(path)
    size = path.stat().st_size
    if size == 0:
        raise VideoProbeError(f"{path.name}: empty file (0 bytes)")
    try:
        proc = subprocess.run([ffmpeg_exe(), "-hide_banner", "-nostdin", *input_args(path)], capture_output=True,
                              text=True, errors="replace", timeout=timeout_s)
    except subprocess.TimeoutExpired:
        raise VideoProbeError(f"{path.name}: ffmpeg did not finish reading the header in {timeout_s:g} s") from None
    err = proc.stderr
    head = _INPUT.search(err)
    video = _VIDEO.search(err)
    if head is None:
        raise VideoProbeError(f"{path.name}: cannot be decoded ({_reason(err)})")
    if video is None:
        raise VideoProbeError(f"{path.name}: no video stream (the file holds {head.group('formats')} without "
                              "pictures)")
    rest = video.group("rest")
    size_m = _SIZE.search(rest)
    fps_m = _FPS.search(rest)
    pix_m = re.search(r"\b(yuv\w+|yuvj\w+|rgb\w+|bgr\w+|gbr\w+|gray\w*|nv\d+\w*|argb|abgr|rgba|bgra|p0\d+\w*)\b",
                      rest)
    dur_m = _DURATION.search(err)
    duration = (int(dur_m["h"]) * 3600 + int(dur_m["m"]) * 60 + float(dur_m["s"])) if dur_m else 0.0
    audio = _AUDIO.search(err)
    return VideoProbe(container=head.group("formats"), video_codec=video.group("codec"),
                      pix_fmt=pix_m.group(1) if pix_m else "", width=int(size_m["w"]) if size_m else 0,
                      height=int(size_m["h"]) if size_m else 0, fps=float(fps_m["fps"]) if fps_m else 0.0,
                      duration_s=duration, audio_codec=audio.group("codec") if audio else "", size_bytes=size)


def _video_to_null(path: Path, timeout_s: float, doing: str, input_options=(), output_options=()
                   ) -> subprocess.CompletedProcess:
    """Run ffmpeg on the first video stream of ``path`` into the null muxer with progress statistics on stderr;
    VideoProbeError when ``doing`` (e.g. "decoding") takes longer than ``timeout_s``."""
    cmd = [ffmpeg_exe(), "-hide_banner", "-nostdin", "-v", "error", "-stats", *input_options, *input_args(path),
           "-map", "0:v:0", *output_options, "-f", "null", "-"]
    try:
        return subprocess.run(cmd, capture_output=True, text=True, errors="replace", timeout=timeout_s)
    except subprocess.TimeoutExpired:
        raise VideoProbeError(f"{path.name}: {doing} took longer than {timeout_s:g} s") from None


def _last_frame_count(stderr: str) -> int:
    """The last ``frame=`` count of ffmpeg's progress statistics (0 when there is none)."""
    frames = re.findall(r"frame=\s*(\d+)", stderr)
    return int(frames[-1]) if frames else 0


def count_video_packets(path: str | Path, timeout_s: float = 600.0) -> int:
    """Frames (packets) in the first video stream of ``path``, counted by reading the file without decoding it.

    A container can declare a video stream and hold no frame of it (a sound track beside an empty picture track):
    the header alone cannot tell, so :func:`probe_video` does not; this is the cheap check that can."""
    path = Path(path)
    proc = _video_to_null(path, timeout_s, "reading the video stream", output_options=("-c", "copy"))
    if proc.returncode != 0:
        raise VideoProbeError(f"{path.name}: cannot be decoded ({_reason(proc.stderr)})")
    return _last_frame_count(proc.stderr)


def decode_check(path: str | Path, timeout_s: float = 1800.0) -> tuple[int, float]:
    """Decode every video frame of ``path``: (frames, seconds of video). VideoProbeError names the first decoding
    error, or a file without a single frame."""
    path = Path(path)
    proc = _video_to_null(path, timeout_s, "decoding", input_options=("-xerror",))
    errors = [ln for ln in proc.stderr.splitlines() if ln.strip() and not ln.lstrip().startswith("frame=")
              and "frame=" not in ln]
    if proc.returncode != 0 or errors:
        raise VideoProbeError(f"{path.name}: cannot be decoded ({_reason(chr(10).join(errors) or proc.stderr)})")
    times = re.findall(r"time=(\d+):(\d\d):(\d\d(?:\.\d+)?)", proc.stderr)
    n = _last_frame_count(proc.stderr)
    secs = (int(times[-1][0]) * 3600 + int(times[-1][1]) * 60 + float(times[-1][2])) if times else 0.0
    if n == 0:
        raise VideoProbeError(f"{path.name}: no video frames could be decoded")
    return n, secs
