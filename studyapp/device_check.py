"""What the consent page's device check (static/studyapp/device_check.js) asks of a participant's browser before
the study starts: a viewport large enough for the clip player and a video format it can play."""
from __future__ import annotations

from .models import Clip

MIN_VIEWPORT_PX = (320, 300)
"""Smallest viewport (CSS pixels, width x height) that shows the 16:9 player with its controls and an answer."""
MP4_TYPE = 'video/mp4; codecs="avc1.640028"'
"""Every clip's MP4: H.264 High profile, level 4.0 (generation/render/encode.py, libx264 at 720p)."""
WEBM_TYPE = 'video/webm; codecs="vp9"'
"""The optional WebM beside it (VP9)."""


def playable_types() -> list[str]:
    """Video types any one of which plays every clip: the MP4 type, and the WebM type too when no clip of the
    catalogue in use (not retired) lacks a WebM file. One query."""
    every_clip_has_webm = not Clip.objects.filter(retired=False, webm="").exists()
    return [MP4_TYPE, WEBM_TYPE] if every_clip_has_webm else [MP4_TYPE]


def device_context() -> dict:
    """Template context of the device check: {"device_min_width", "device_min_height", "device_types"}."""
    width, height = MIN_VIEWPORT_PX
    return {"device_min_width": width, "device_min_height": height, "device_types": "|".join(playable_types())}
