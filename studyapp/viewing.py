"""The viewing record of one answered clip page: read from the answer's hidden fields, checked and bounded.

static/studyapp/study.js measures how the clip was watched and posts each field of
``study_protocol.VIEWING_FIELDS`` as a hidden input named ``view_<field>`` (times in ms from the page's display,
counts as integers). Nothing here rejects an answer: a field that is missing, not an integer, negative, beyond
its bound or inconsistent is stored as None (unknown), and a post without any usable field (no JavaScript: the
fields stay blank; a page from before: no fields) stores no record. Stored on ``Assignment.viewing`` in the same
UPDATE that marks the clip answered.
"""
from __future__ import annotations

from study_pools import DEFAULT_PLAYER_CONTROLS, player_errors
from study_protocol import VIEWING_FIELDS, VIEWING_TIME_FIELDS

FIELD_PREFIX = "view_"
MAX_COUNT = 1000
"""Highest count accepted (plays, pauses, seeks, stalls, hidden); more in one clip page is not a measurement."""


def field_name(name: str) -> str:
    """The form field of a viewing-record field, e.g. ``view_plays``."""
    return FIELD_PREFIX + name


VIEWING_FORM_FIELDS = tuple(field_name(f) for f in VIEWING_FIELDS)


def player_options(options) -> dict:
    """The clip player of a section: {"controls": one of study_pools.PLAYER_CONTROLS, "max_replays": int or None
    (unlimited)}. Options that do not validate (a section saved before a check existed) fall back to the default
    player rather than breaking the participant's page."""
    options = options if isinstance(options, dict) else {}
    if player_errors(options):
        return {"controls": DEFAULT_PLAYER_CONTROLS, "max_replays": None}
    return {"controls": options.get("controls", DEFAULT_PLAYER_CONTROLS), "max_replays": options.get("max_replays")}


def _integer(raw, high: int) -> int | None:
    """A decimal integer 0..high from a form value ("12", "12.0" from a JS number), else None."""
    text = str(raw).strip()[:16]
    try:
        value = float(text)
    except ValueError:
        return None
    if not value.is_integer() or not 0 <= value <= high:     # also rejects nan and inf
        return None
    return int(value)


def parse_viewing(post, page_ms: int) -> dict | None:
    """The viewing record of an answer POST: field -> int or None; None when no field has a usable value (the
    fields missing, or left blank because the page ran without JavaScript).

    page_ms: the longest a time may be (the time since the page was shown as the server measured it, plus slack):
    a time beyond it is not a measurement. ``ended_ms`` before ``first_play_ms`` is dropped (a clip ends after
    it starts), and so is a record claiming an end without any play."""
    record = {}
    for name in VIEWING_FIELDS:
        raw = post.get(field_name(name), "")
        high = page_ms if name in VIEWING_TIME_FIELDS else MAX_COUNT
        record[name] = _integer(raw, high) if raw != "" else None
    first, ended = record["first_play_ms"], record["ended_ms"]
    if ended is not None and (first is None or ended < first or record["plays"] == 0):
        record["ended_ms"] = None
    return record if any(v is not None for v in record.values()) else None
