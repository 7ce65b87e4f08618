"""Video encoding with imageio-ffmpeg's bundled ffmpeg, written atomically.

MP4: H.264, yuv420p, ``+faststart`` (the index at the front, so browsers start before the end
arrives). WebM: VP9. Every file is written under a temporary name in the same folder and renamed
into place only when complete, so a crash never leaves a half file under a final name.
"""
from __future__ import annotations

import os
from pathlib import Path

import imageio_ffmpeg
import numpy as np
from PIL import Image


def temp_path(final: Path) -> Path:
    """Hidden temporary name next to ``final`` that keeps its extension (ffmpeg picks the format by it)."""
    return final.with_name(f".{final.stem}.tmp{os.getpid()}{final.suffix}")


def codec_params(kind: str, crf: int = 23, preset: str = "veryfast", threads: int = 0) -> tuple[str, list[str]]:
    """(ffmpeg encoder, output options) of a delivery format, ``kind`` "mp4" (H.264) or "webm" (VP9): the settings
    of every clip the platform serves, generated or imported."""
    thread_args = ["-threads", str(threads)] if threads else []
    if kind == "mp4":
        return "libx264", ["-preset", preset, "-crf", str(crf), "-movflags", "+faststart", *thread_args]
    if kind == "webm":
        # Constant quality VP9 (-b:v 0 with -crf); realtime deadline keeps it close to H.264's speed.
        return "libvpx-vp9", ["-b:v", "0", "-crf", str(min(63, crf + 12)), "-deadline", "realtime",
                              "-cpu-used", "8", "-row-mt", "1", *thread_args]
    raise ValueError(f"unknown video kind {kind!r}; expected 'mp4' or 'webm'")


class VideoWriter:
    """Stream RGB frames (H, W, 3) uint8 into one video file; ``commit()`` renames it into place.

    Args:
        path: final file name (.mp4 or .webm).
        width, height: pixels (even).
        fps: frames per second.
    """

    def __init__(self, path: str | Path, width: int, height: int, fps: float, crf: int = 23,
                 preset: str = "veryfast", threads: int = 0):
        self.path = Path(path)
        self.kind = self.path.suffix.lstrip(".").lower()
        self.tmp = temp_path(self.path)
        codec, params = codec_params(self.kind, crf, preset, threads)
        self.size = (width, height)
        self._gen = imageio_ffmpeg.write_frames(
            str(self.tmp), (width, height), fps=fps, codec=codec, pix_fmt_in="rgb24", pix_fmt_out="yuv420p",
            macro_block_size=2, ffmpeg_log_level="error", output_params=params, quality=None)
        self._gen.send(None)
        self.frames = 0

    def write(self, frame: np.ndarray) -> None:
        if frame.shape != (self.size[1], self.size[0], 3) or frame.dtype != np.uint8:
            raise ValueError(f"{self.path.name}: frame must be ({self.size[1]}, {self.size[0]}, 3) uint8, "
                             f"got {frame.shape} {frame.dtype}")
        self._gen.send(np.ascontiguousarray(frame))
        self.frames += 1

    def commit(self) -> Path:
        """Finish encoding and move the file to its final name."""
        self._gen.close()
        if not self.tmp.exists() or self.tmp.stat().st_size == 0:
            raise RuntimeError(f"{self.path}: ffmpeg wrote no data")
        os.replace(self.tmp, self.path)
        return self.path

    def abort(self) -> None:
        try:
            self._gen.close()
        except Exception:  # noqa: BLE001 - best effort on the error path
            pass
        self.tmp.unlink(missing_ok=True)


def write_png_atomic(image: np.ndarray, path: str | Path) -> Path:
    """Write an RGB image (H, W, 3) uint8 to ``path`` through a temporary name."""

    path = Path(path)
    tmp = temp_path(path)
    Image.fromarray(image).save(tmp, format="PNG", optimize=True)
    os.replace(tmp, path)
    return path


def probe_video(path: str | Path) -> tuple[int, float]:
    """(frame count, seconds) of a video file by decoding it with the bundled ffmpeg."""

    return imageio_ffmpeg.count_frames_and_secs(str(path))
