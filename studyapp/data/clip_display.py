"""How a clip is shown to staff wherever clips are listed (clip list, progress monitor, norming monitor, pool
editor): a small poster and its readable title (protocol.titles), the 16-hex id beside it in small print.

The poster is the catalogue's own PNG served by its opaque media key; its size comes from the class ``clip-thumb``
of static/studyapp/admin_clips.css (the Content-Security-Policy of studyapp.security allows no inline style) and
from the image's width/height attributes, so a page that lacks the style sheet still shows it small.
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from django.urls import reverse
from django.utils.html import format_html
from django.utils.safestring import SafeString, mark_safe

from ..models import Clip

THUMB_WIDTH, THUMB_HEIGHT = 85, 48
"""Thumbnail size in CSS pixels (16:9, the renderer's posters)."""
STYLESHEET = "studyapp/admin_clips.css"


@dataclass(frozen=True)
class ClipCell:
    """One clip as staff see it: ``clip_id``, ``title`` ("" = none yet) and ``thumb_url`` ("" = no poster)."""

    clip_id: str
    title: str
    thumb_url: str

    def thumb(self) -> SafeString:
        if not self.thumb_url:
            return mark_safe('<span class="clip-thumb clip-thumb-none" aria-hidden="true"></span>')
        return format_html('<img class="clip-thumb" src="{}" alt="" width="{}" height="{}" loading="lazy">',
                           self.thumb_url, THUMB_WIDTH, THUMB_HEIGHT)

    def html(self) -> SafeString:
        return format_html('<span class="clip-cell">{}<span class="clip-name"><span class="clip-title">{}</span>'
                           '<code class="clip-id">{}</code></span></span>', self.thumb(),
                           self.title or self.clip_id, self.clip_id)


def poster_url(clip: Clip) -> str:
    return reverse("studyapp:media", args=[clip.media_key, "png"]) if clip.poster else ""


def clip_cell(clip: Clip) -> ClipCell:
    return ClipCell(clip.clip_id, clip.title, poster_url(clip))


def clip_cells(clip_ids: Iterable[str]) -> dict[str, ClipCell]:
    """clip_id -> ClipCell for the catalogue clips among ``clip_ids`` (one query)."""
    clips = Clip.objects.filter(clip_id__in=set(clip_ids)).only("clip_id", "title", "poster", "media_key")
    return {c.clip_id: clip_cell(c) for c in clips}
