"""Render a Motion into clip files: MP4 (+ optional WebM) and a poster PNG.

The renderer draws what the Motion says and nothing else: it resamples to the video frame rate,
cuts at ``settings.duration_s`` and never stretches or pads motion.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from protocol.vocabulary import GENDERS

from .bodies import BY_GENDER, DEFAULT_PRESET, load_body
from .body import head_top
from .camera import body_outline, choose_cameras, facing_direction
from .encode import VideoWriter, write_png_atomic
from .human import HumanScene, human_figure, seat_fit
from .scene import GROUND_MARGIN_M, SCENES, chair_boxes
from .settings import RenderSettings


@dataclass(frozen=True)
class RenderResult:
    """Files of one rendered clip; paths are absolute, ``webm`` is None unless asked for."""

    mp4: Path
    webm: Path | None
    poster: Path
    n_frames: int
    fps: float
    camera: dict = field(default_factory=dict)  # rule ("fixed"/"follow"), figure height fractions, body
    body: dict | None = None  # the human body shown: preset, parameters, height, source, licence, citation

    @property
    def camera_rule(self) -> str | None:
        return self.camera.get("rule")

    @property
    def duration_s(self) -> float:
        return self.n_frames / self.fps


def is_seated(motion: Motion) -> bool:
    """Seated gestures get a chair (seed 003 section 5.6: agents sit on a chair)."""
    if "seated" in motion.metadata:
        return bool(motion.metadata["seated"])
    return motion.skeleton.name == "gesture"


def prepare(motion: Motion, settings: RenderSettings) -> tuple[Motion, np.ndarray]:
    """Motion at the video frame rate, cut to the clip length, and its (T, J, 3) positions."""
    clip = motion.resample(settings.fps)
    if clip.num_frames > settings.max_frames:
        clip = clip.slice(0, settings.max_frames)
    return clip, clip.positions()


def body_skeleton(motion: Motion):
    """The skeleton whose build shapes the body: the motion's, relabelled when its metadata names another
    build ("build" or "gender": male/female; the bone lengths stay the motion's own)."""
    skel = motion.skeleton
    build = motion.metadata.get("build") or motion.metadata.get("gender")
    if build in GENDERS and build != skel.build:
        skel = dataclasses.replace(skel, build=build)
    return skel


def figure_outline(skel, positions: np.ndarray, body: str) -> np.ndarray:
    """(T, K, 3) points around the drawn figure (for framing; see :func:`camera.body_outline`)."""
    s = skel.height / 1.75
    if body == "points":
        return body_outline(positions, None, 0.035 * s)
    return body_outline(positions, head_top(skel, positions), 0.06 * s)


def body_preset_for(motion: Motion, settings: RenderSettings) -> str:
    """The human body preset of a clip: the settings' ``body_preset``, else the one of the Motion's gender
    (metadata "gender" or "build", else its skeleton's build; seed 003: the agent's gender picks its body), else
    the default preset."""
    if settings.body_preset:
        return settings.body_preset
    gender = motion.metadata.get("gender") or motion.metadata.get("build") or motion.skeleton.build
    return BY_GENDER.get(gender, DEFAULT_PRESET)


def human_figure_for(motion: Motion, settings: RenderSettings):
    """The posed human body of a prepared clip (:class:`generation.render.human.HumanFigure`)."""
    return human_figure(motion, body_preset_for(motion, settings), settings.face, settings.skin_tone)


def plan_cameras(motion: Motion, positions: np.ndarray, settings: RenderSettings, figure=None
                 ) -> tuple[list, dict, tuple]:
    """Per-frame camera poses of a prepared clip without rendering: (poses, info, (skeleton, ground_y, chair,
    figure)), ``figure`` the posed human body or None.

    ``info`` holds the camera rule and the projected figure height fractions (``min_figure_fraction``...), the
    body look and build (and the human body's ``body_preset``), and ``seated``. ``figure``: the clip's posed human
    body (made here when the look is "human" and none is given)."""
    skel = body_skeleton(motion)
    s = skel.height / 1.75
    ground_y = float(positions[..., 1].min() - 0.03 * s)
    chair = None
    extra = None
    seated = is_seated(motion)
    if settings.body == "human" and figure is None:
        figure = human_figure_for(motion, settings)
    if seated:
        facing = facing_direction(motion.rotations[0, 0])
        seat = None
        if figure is not None:
            seat = seat_fit(figure, facing)
        chair = chair_boxes(positions, skel, facing, ground_y, seat)
        if settings.body != "points":
            extra = np.concatenate([np.stack([c + h * np.array(sgn) for sgn in ((1, 1, 1), (-1, -1, -1))])
                                    for c, h, _ in chair])
    root = positions[:, 0]
    extent = (root[:, 0].min() - GROUND_MARGIN_M, root[:, 0].max() + GROUND_MARGIN_M,
              root[:, 2].min() - GROUND_MARGIN_M, root[:, 2].max() + GROUND_MARGIN_M)
    outline = figure.outline if figure is not None else figure_outline(skel, positions, settings.body)
    cams, cam_info = choose_cameras(positions, motion.rotations[0, 0], outline, settings.fps, settings.width,
                                    settings.height, settings.camera, seated, extra)
    cam_info.update(body=settings.body, build=skel.build, seated=seated, extent=extent)
    if figure is not None:
        cam_info.update(body_preset=figure.body.name)
    return cams, cam_info, (skel, ground_y, chair, figure)


def anti_aliasing_for(setting: str, cams: list, seated: bool = True) -> str:
    """The anti-aliasing a clip gets: ``setting``, or for "auto" FXAA for a seated body seen by a fixed camera (a
    large, slowly moving figure whose edges show; patch rendering keeps the pass to the moving limbs) and none for
    walks (a small, fast figure; with a follow camera FXAA would run over every whole frame, several times the
    cost of the frame itself in software GL)."""
    if setting != "auto":
        return setting
    return "fxaa" if seated and all(c is cams[0] for c in cams) else "none"


def build_scene(motion: Motion, positions: np.ndarray, settings: RenderSettings, info: dict | None = None):
    """The scene and per-frame camera poses for a prepared clip; ``info`` (when given) receives the camera
    rule and the projected figure height fractions."""
    cams, cam_info, (skel, ground_y, chair, figure) = plan_cameras(motion, positions, settings)
    extent = cam_info.pop("extent")
    aa = anti_aliasing_for(settings.anti_aliasing, cams, cam_info["seated"])
    cam_info["anti_aliasing"] = aa
    if figure is not None:
        scene = HumanScene(skel, settings.width, settings.height, aa, extent, ground_y, chair, figure=figure)
    else:
        scene = SCENES[settings.body](skel, settings.width, settings.height, aa, extent, ground_y, chair)
    if info is not None:
        info.update(cam_info)
    return scene, cams


def _frames(clip: Motion, positions: np.ndarray, settings: RenderSettings, patches: bool = True,
            info: dict | None = None) -> Iterator[np.ndarray]:
    scene, cams = build_scene(clip, positions, settings, info)
    try:
        fixed = all(c is cams[0] for c in cams)
        use_patches = patches and fixed and scene.plan_patches(positions, cams[0])
        last_cam = None
        for t in range(len(positions)):
            if not use_patches and cams[t] is not last_cam:
                scene.set_camera(cams[t])
                last_cam = cams[t]
            scene.set_frame(t, positions[t])
            yield scene.frame_patch(t) if use_patches else scene.frame()
    finally:
        scene.close()


def render_frames(motion: Motion, settings: RenderSettings, patches: bool = True) -> Iterator[np.ndarray]:
    """Yield the clip's frames as (height, width, 3) uint8 images.

    With a fixed camera and a figure small in the frame, only the figure's patch is re-rendered per frame
    (:meth:`StickFigureScene.plan_patches`; same pictures, a few differently rasterised pixels);
    ``patches=False`` renders every frame whole.
    """
    clip, positions = prepare(motion, settings)
    yield from _frames(clip, positions, settings, patches)


def render_frames_at(motion: Motion, settings: RenderSettings, indices) -> list[tuple[int, np.ndarray]]:
    """(frame index, (height, width, 3) uint8 image) for the wanted frame indices (at ``settings.fps``) that the
    clip reaches, in index order; every frame rendered whole, none after the last wanted one (contact sheets)."""
    wanted = sorted(set(int(k) for k in indices))
    out = []
    if not wanted:
        return out
    for k, img in enumerate(render_frames(motion, settings, patches=False)):
        if k in wanted:
            out.append((k, img.copy()))
        if k >= wanted[-1]:
            break
    return out


def render_clip(motion: Motion, out_dir: str | Path, name: str, settings: RenderSettings | None = None,
                progress: Callable[[int, int], None] | None = None) -> RenderResult:
    """Render ``motion`` to ``out_dir/name.mp4`` (+ ``.webm``) and ``name.png``.

    Files appear under their final names only when complete (temporary names, then rename); the
    poster is written last, so a complete set is mp4 [+ webm] + png.

    Args:
        motion: any skeleton; positions from forward kinematics, metres, y-up.
        out_dir: folder for the files (created if missing).
        name: file stem, e.g. the content hash.
        settings: render settings (defaults: 1280x720, 30 fps, at most 10 s, mannequin, auto camera, FXAA).
        progress: called as progress(frames_done, frames_total) after every frame.
    """
    settings = settings or RenderSettings()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    clip, positions = prepare(motion, settings)
    n = len(positions)
    poster_index = min(n - 1, int(settings.poster_fraction * (n - 1) + 0.5))
    writers = [VideoWriter(out_dir / f"{name}.mp4", settings.width, settings.height, settings.fps, settings.crf,
                           settings.preset, settings.encoder_threads)]
    if settings.webm:
        writers.append(VideoWriter(out_dir / f"{name}.webm", settings.width, settings.height, settings.fps,
                                   settings.crf, settings.preset, settings.encoder_threads))
    poster = None
    info: dict = {}
    frames = _frames(clip, positions, settings, info=info)
    try:
        for t, img in enumerate(frames):
            for w in writers:
                w.write(img)
            if t == poster_index:
                poster = img.copy()
            if progress is not None:
                progress(t + 1, n)
        for w in reversed(writers):  # the mp4 is committed last of the videos
            w.commit()
    except BaseException:
        for w in writers:
            w.abort()
        raise
    finally:
        frames.close()  # closes the offscreen window
    write_png_atomic(poster, out_dir / f"{name}.png")
    body = None
    if info.get("body_preset"):
        body = load_body(info["body_preset"]).record()
    return RenderResult(out_dir / f"{name}.mp4", out_dir / f"{name}.webm" if settings.webm else None,
                        out_dir / f"{name}.png", n, settings.fps, info, body)


def clip_files_complete(out_dir: str | Path, name: str, webm: bool) -> bool:
    """True when every file of a clip exists under its final name and is non-empty."""
    out_dir = Path(out_dir)
    needed = [out_dir / f"{name}.mp4", out_dir / f"{name}.png"] + ([out_dir / f"{name}.webm"] if webm else [])
    return all(p.is_file() and p.stat().st_size > 0 for p in needed)
