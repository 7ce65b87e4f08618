"""What the consent page's device check (static/studyapp/device_check.js) asks of a participant's browser before
the study starts: a viewport large enough for the clip player (the study's minimum, never below MIN_VIEWPORT_PX), a
video format it can play, and a kind of device the study admits (phones and tablets may be turned away).

The browser reports its viewport and kind with the consent form (hidden fields the script fills in); the server
records them on the participant and refuses a start the study does not admit with a page that says why. Without
the script the kind comes from the User-Agent header (DEVICE_PATTERNS) and the viewport is unknown (not checked).
"""
from __future__ import annotations

import re

from django.utils.translation import gettext

from ..models import Clip, Study

MIN_VIEWPORT_PX = (320, 300)
"""Smallest viewport (CSS pixels, width x height) that shows the 16:9 player with its controls and an answer."""
MP4_TYPE = 'video/mp4; codecs="avc1.640028"'
"""Every clip's MP4: H.264 High profile, level 4.0 (generation/render/encode.py, libx264 at 720p)."""
WEBM_TYPE = 'video/webm; codecs="vp9"'
"""The optional WebM beside it (VP9)."""

PHONE, TABLET, DESKTOP = "phone", "tablet", "desktop"
DEVICE_KINDS = (PHONE, TABLET, DESKTOP)
MAX_VIEWPORT_PX = 20_000
"""Larger reported viewports are not believed (not stored, not checked)."""

DEVICE_PATTERNS = (
    (TABLET, re.compile(r"iPad|Tablet|PlayBook|Silk|Kindle|Android(?!.*Mobile)", re.I)),
    (PHONE, re.compile(r"iPhone|iPod|Mobi|Windows Phone|BlackBerry|Opera Mini", re.I)),
)
"""User-Agent patterns, tried in order (an Android without "Mobile" is a tablet); anything else is a desktop."""


def playable_types() -> list[str]:
    """Video types any one of which plays every clip: the MP4 type, and the WebM type too when no clip of the
    catalogue in use (not retired) lacks a WebM file. One query."""
    every_clip_has_webm = not Clip.objects.filter(retired=False, webm="").exists()
    return [MP4_TYPE, WEBM_TYPE] if every_clip_has_webm else [MP4_TYPE]


def min_viewport(study: Study) -> tuple[int, int]:
    """The viewport (width, height in CSS pixels) the study needs: its own minimum, never below MIN_VIEWPORT_PX."""
    return (max(study.min_viewport_width, MIN_VIEWPORT_PX[0]), max(study.min_viewport_height, MIN_VIEWPORT_PX[1]))


def admitted_kinds(study: Study) -> list[str]:
    return [DESKTOP] + ([TABLET] if study.admit_tablets else []) + ([PHONE] if study.admit_phones else [])


def device_context(study: Study) -> dict:
    """Template context of the device check: the minimum viewport, the playable types and the kinds admitted."""
    width, height = min_viewport(study)
    return {"device_min_width": width, "device_min_height": height, "device_types": "|".join(playable_types()),
            "device_admits": "|".join(admitted_kinds(study))}


def kind_from_user_agent(user_agent: str) -> str:
    """phone, tablet or desktop from a User-Agent header (DEVICE_PATTERNS)."""
    return next((kind for kind, pattern in DEVICE_PATTERNS if pattern.search(user_agent or "")), DESKTOP)


def reported_size(raw) -> int | None:
    """A viewport side the browser reported: a whole number of CSS pixels 1..MAX_VIEWPORT_PX, else None."""
    text = str(raw or "").strip()
    return int(text) if text.isdigit() and 0 < int(text) <= MAX_VIEWPORT_PX else None


def device_record(post, user_agent: str) -> dict:
    """What the consent form says about the device: {"viewport_width", "viewport_height", "device_kind"} (sizes None
    when not reported; the kind the script reported, else the User-Agent's)."""
    kind = str(post.get("device_kind", ""))
    return {"viewport_width": reported_size(post.get("viewport_w")),
            "viewport_height": reported_size(post.get("viewport_h")),
            "device_kind": kind if kind in DEVICE_KINDS else kind_from_user_agent(user_agent)}


def refusal(study: Study, record: dict) -> str | None:
    """Why the study cannot be taken on this device (a message for the participant in the active language), or
    None when it can."""
    kind = record["device_kind"]
    if kind == PHONE and not study.admit_phones:
        if study.admit_tablets:
            return gettext("This study cannot be taken on a phone: its videos and questions need a larger screen. "
                           "Please open the study link on a computer or a tablet.")
        return gettext("This study cannot be taken on a phone: its videos and questions need a larger screen. "
                       "Please open the study link on a computer.")
    if kind == TABLET and not study.admit_tablets:
        return gettext("This study cannot be taken on a tablet. Please open the study link on a computer.")
    width, height = min_viewport(study)
    w, h = record["viewport_width"], record["viewport_height"]
    if w is not None and h is not None and (w < width or h < height):
        return gettext("This study needs a browser window of at least {min} pixels, and this window shows {size}. "
                       "Please make the window larger or use a larger screen, then open the study link "
                       "again.").format(min=f"{width} × {height}", size=f"{w} × {h}")
    return None
