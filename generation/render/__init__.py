"""PyVista offscreen renderer: a mannequin (or stick figure, or point-lights) to MP4/WebM clips with a poster,
and contact sheets.

Public interface:
    RenderSettings        resolution (1280x720), fps, duration, body look, camera rule, anti-aliasing, codecs
    render_clip(motion, out_dir, name, settings, progress) -> RenderResult (.camera: rule and figure fractions)
    render_frames(motion, settings) -> iterator of (H, W, 3) uint8 frames
    clip_files_complete(out_dir, name, webm) -> bool
    contact_sheet(poster_paths, labels, out_png) -> Path
    prepare_render_process(threads)   once per rendering process, at its edge (CLI, worker initializer)
"""
from .clip import RenderResult, clip_files_complete, is_seated, render_clip, render_frames
from .contact_sheet import contact_sheet
from .offscreen import prepare_render_process
from .settings import RenderSettings, RenderSettingsError

__all__ = ["RenderResult", "RenderSettings", "RenderSettingsError", "clip_files_complete", "contact_sheet",
           "is_seated", "prepare_render_process", "render_clip", "render_frames"]
