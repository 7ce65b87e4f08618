"""PyVista offscreen renderer: stick figures to MP4/WebM clips with a poster, and contact sheets.

Public interface:
    RenderSettings        resolution, fps, duration, camera, anti-aliasing, codecs
    render_clip(motion, out_dir, name, settings, progress) -> RenderResult
    render_frames(motion, settings) -> iterator of (H, W, 3) uint8 frames
    clip_files_complete(out_dir, name, webm) -> bool
    contact_sheet(poster_paths, labels, out_png) -> Path
"""
from .clip import RenderResult, clip_files_complete, is_seated, render_clip, render_frames
from .contact_sheet import contact_sheet
from .settings import RenderSettings, RenderSettingsError

__all__ = ["RenderResult", "RenderSettings", "RenderSettingsError", "clip_files_complete", "contact_sheet",
           "is_seated", "render_clip", "render_frames"]
