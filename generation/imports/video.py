"""A researcher's video -> the platform's delivery formats and a poster, in a staging folder.

Delivery formats (the same as generated clips, :func:`generation.render.encode.codec_params`): an MP4 of H.264
video in yuv420p with ``+faststart`` (every browser plays it; the index first, so playback starts before the end
has arrived) and, when asked, a VP9 WebM. A file whose video is already H.264 yuv420p (an MP4, a MOV or an MKV of
it) is remuxed without re-encoding and then decoded once in full, to be sure every frame decodes; anything else
(VP8/VP9 WebM, ProRes or MPEG-4 part 2 MOV, 4:2:2 or 10-bit H.264...) is transcoded. Audio is dropped unless
``keep_audio``: then AAC is copied and other audio is encoded to AAC 128 kb/s. Frame sizes are kept (odd sizes
rounded down to even: yuv420p needs them). The poster is the frame at half the duration, as for rendered clips.
"""
from __future__ import annotations

import subprocess
from dataclasses import dataclass
from pathlib import Path

from generation.render.encode import codec_params

from .probe import (
    VideoProbe,
    VideoProbeError,
    count_video_packets,
    decode_check,
    ffmpeg_exe,
    input_args,
    probe_video,
)

PLAYABLE_CODECS = ("h264",)
PLAYABLE_PIX_FMTS = ("yuv420p", "yuvj420p")
POSTER_FRACTION = 0.5


class VideoImportError(ValueError):
    """A video that cannot become a clip (undecodable, empty, too long, too large); the message says why."""


@dataclass(frozen=True)
class VideoLimits:
    """The largest video accepted: ``max_duration_s`` seconds and ``max_bytes`` bytes (the file as given)."""

    max_duration_s: float = 300.0
    max_bytes: int = 1024 * 1024 * 1024


@dataclass(frozen=True)
class StagedVideo:
    """Files made in the staging folder (mp4, png, optional webm) and the facts of the delivered clip.

    ``probe``: the source file; ``delivered``: the MP4 as written; ``action``: "remux" or "transcode"; duration_s
    and n_frames of the delivered video; ``audio``: "kept", "stripped" or "none"."""

    mp4: Path
    poster: Path
    webm: Path | None
    probe: VideoProbe
    delivered: VideoProbe
    action: str
    duration_s: float
    n_frames: int
    audio: str


def check_video(path: Path, limits: VideoLimits) -> VideoProbe:
    """Probe ``path``, check it against ``limits`` and that its video stream holds frames, without writing;
    VideoImportError says what is wrong."""
    size = path.stat().st_size
    if size == 0:
        raise VideoImportError("empty file (0 bytes)")
    if size > limits.max_bytes:
        raise VideoImportError(f"file is {size / 2**20:.1f} MiB, larger than the limit of "
                               f"{limits.max_bytes / 2**20:.0f} MiB")
    try:
        probe = probe_video(path)
    except VideoProbeError as exc:
        raise VideoImportError(str(exc).removeprefix(f"{path.name}: ")) from None
    if probe.duration_s > limits.max_duration_s:
        raise VideoImportError(f"{probe.duration_s:.1f} s long, longer than the limit of "
                               f"{limits.max_duration_s:g} s")
    if probe.width and probe.height and (probe.width < 16 or probe.height < 16):
        raise VideoImportError(f"frame size {probe.width}x{probe.height} is too small (at least 16x16)")
    try:
        frames = count_video_packets(path)
    except VideoProbeError as exc:
        raise VideoImportError(str(exc).removeprefix(f"{path.name}: ")) from None
    if frames == 0:
        raise VideoImportError("the video stream holds no frames (an empty video)")
    return probe


def needs_transcode(probe: VideoProbe) -> bool:
    """True unless the video is H.264 in 8-bit 4:2:0 (then the stream is copied into an MP4 as it is)."""
    return probe.video_codec not in PLAYABLE_CODECS or probe.pix_fmt not in PLAYABLE_PIX_FMTS


def _run(cmd: list[str], what: str, timeout_s: float) -> None:
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, errors="replace", timeout=timeout_s)
    except subprocess.TimeoutExpired:
        raise VideoImportError(f"{what} took longer than {timeout_s:g} s") from None
    if proc.returncode != 0:
        lines = [ln.strip() for ln in proc.stderr.splitlines() if ln.strip()]
        raise VideoImportError(f"{what} failed: cannot be decoded ({lines[-1] if lines else 'no reason given'})")


def _audio_args(probe: VideoProbe, keep_audio: bool) -> tuple[list[str], str]:
    if not probe.has_audio:
        return ["-an"], "none"
    if not keep_audio:
        return ["-an"], "stripped"
    return (["-c:a", "copy"] if probe.audio_codec == "aac" else ["-c:a", "aac", "-b:a", "128k"]), "kept"


def stage_video(path: Path, stage: Path, stem: str, limits: VideoLimits, keep_audio: bool = False,
                webm: bool = False, threads: int = 0, timeout_s: float = 3600.0) -> StagedVideo:
    """Make ``stage/<stem>.mp4``, ``.png`` (and ``.webm``) from the video at ``path``.

    Args:
        path: the source video (checked with :func:`check_video` first).
        stage: an existing folder for the new files (the caller moves them into place or deletes them).
        stem: file stem, the clip id.
        limits: the longest and largest video accepted.
        keep_audio: keep the sound track (AAC); otherwise the delivered files are silent.
        webm: also write a VP9 WebM.
        threads: ffmpeg threads per encode (0: ffmpeg decides).
    Raises VideoImportError naming the cause; files already made in ``stage`` are left for the caller to remove.
    """
    probe = check_video(path, limits)
    mp4 = stage / f"{stem}.mp4"
    audio_args, audio = _audio_args(probe, keep_audio)
    base = [ffmpeg_exe(), "-hide_banner", "-nostdin", "-v", "error", "-y", "-xerror", *input_args(path),
            "-map", "0:v:0", *(["-map", "0:a:0"] if audio == "kept" else []), "-map_metadata", "-1", "-sn", "-dn"]
    if needs_transcode(probe):
        action = "transcode"
        codec, params = codec_params("mp4", threads=threads)
        _run([*base, "-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2,format=yuv420p", "-c:v", codec, *params,
              *audio_args, str(mp4)], "transcoding to H.264", timeout_s)
    else:
        action = "remux"
        _run([*base, "-c:v", "copy", "-movflags", "+faststart", *audio_args, str(mp4)], "remuxing to MP4", timeout_s)
    try:
        delivered = probe_video(mp4)
        n_frames, secs = decode_check(mp4, timeout_s)
    except VideoProbeError as exc:
        raise VideoImportError(str(exc).removeprefix(f"{mp4.name}: ")) from None
    duration = delivered.duration_s or secs
    if not duration > 0:
        raise VideoImportError("the video has no duration (zero frames)")
    poster = stage / f"{stem}.png"
    _run([ffmpeg_exe(), "-hide_banner", "-nostdin", "-v", "error", "-y", "-ss", f"{POSTER_FRACTION * duration:.3f}",
          *input_args(mp4), "-frames:v", "1", "-update", "1", str(poster)], "making the poster", 120.0)
    if not poster.is_file() or poster.stat().st_size == 0:
        _run([ffmpeg_exe(), "-hide_banner", "-nostdin", "-v", "error", "-y", *input_args(mp4), "-frames:v", "1",
              "-update", "1", str(poster)], "making the poster", 120.0)
    out_webm = None
    if webm:
        out_webm = stage / f"{stem}.webm"
        codec, params = codec_params("webm", threads=threads)
        webm_audio = ["-c:a", "libopus", "-b:a", "96k"] if audio == "kept" else ["-an"]
        _run([ffmpeg_exe(), "-hide_banner", "-nostdin", "-v", "error", "-y", *input_args(mp4), "-c:v", codec, *params,
              *webm_audio, str(out_webm)], "encoding the WebM", timeout_s)
    return StagedVideo(mp4, poster, out_webm, probe, delivered, action, round(duration, 4), n_frames, audio)
