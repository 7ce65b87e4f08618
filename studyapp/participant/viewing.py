"""The viewing record of one answered clip page: read from the answer's hidden fields, checked against what the
server knows, and marked with what it is worth.

static/studyapp/study.js measures how the clip was watched and posts each field of
``protocol.vocabulary.VIEWING_FIELDS`` as a hidden input named ``view_<field>`` (times in ms from the page's display,
counts as integers), and ``view_script=1`` to say that it ran. Every clip page ships the player, so the server
knows a record is due with every answer; nothing here rejects an answer, but the record says what happened
(``protocol.vocabulary.VIEWING_RECORDS``):

- ``missing``: the POST has none of the page's record fields (it did not come from the page);
- ``no_script``: the fields came back blank without ``view_script`` (the browser ran no JavaScript);
- ``implausible``: a field is not an integer within its bound, an end comes before the first play, a start-up time
  (first play request to first frame) is longer than the time to the first frame or comes without one, there
  are more plays than the time the page was shown fits (``max_plays``), or more than the section's player allows
  (1 + ``max_replays``; the player refuses them, so they did not come from it), or the record disagrees with the
  server's own evidence: a play or an end reported while the server never sent this session the clip
  (``Assignment.fetched_at``, set by the media view), or an end reported sooner than ENDED_FRACTION of the clip's
  duration after the page was shown (by the server's clock: the answer's time and the player's ``ended`` report)
  or after the reported first play (where the player cannot seek or change speed: controls other than ``full``):
  kept as sent, but not to be trusted;
- ``ok`` otherwise.

While the page is open the script also reports each play start and the clip's first end (``record_playback`` via
the ``playback`` view), stored on the assignment, so a reload keeps the plays (and ``max_replays`` holds) and an end
reached before a reload still counts. Stored on ``Assignment.viewing`` in the same UPDATE that marks the clip
answered.
"""
from __future__ import annotations

from protocol.pools import DEFAULT_PLAYER_CONTROLS, player_errors
from protocol.vocabulary import VIEWING_FIELDS, VIEWING_TIME_FIELDS

FIELD_PREFIX = "view_"
SCRIPT_FIELD = "view_script"
"""Set to "1" by the player's script when it attaches; blank in the page's markup."""
MAX_COUNT = 1000
"""Highest count accepted (plays, pauses, seeks, stalls, hidden); more in one clip page is not a measurement."""
PLAYBACK_EVENTS = ("play", "ended", "leave")
"""What the player reports while the page is open: a play from the start (first play or replay), the first end,
and, when the page is left without an answer (a reload), its counts so far (CARRIED_FIELDS)."""
ENDED_FRACTION = 0.8
"""An end is reported no sooner than this fraction of the clip's duration after the clip could start playing."""
SEEKING_CONTROLS = "full"
"""The player controls under which a participant may seek or change speed, so an early end proves nothing."""
CARRIED_FIELDS = ("pauses", "seeks", "stalls", "stall_ms", "hidden", "hidden_ms")
"""Record fields a display left without an answer hands on to the next (added up on the assignment)."""


def field_name(name: str) -> str:
    """The form field of a viewing-record field, e.g. ``view_plays``."""
    return FIELD_PREFIX + name


VIEWING_FORM_FIELDS = tuple(field_name(f) for f in VIEWING_FIELDS)


def player_options(options) -> dict:
    """The clip player of a section: {"controls": one of protocol.pools.PLAYER_CONTROLS, "max_replays": int or None
    (unlimited)}. Options that do not validate (a section saved before a check existed) fall back to the default
    player rather than breaking the participant's page."""
    options = options if isinstance(options, dict) else {}
    if player_errors(options):
        return {"controls": DEFAULT_PLAYER_CONTROLS, "max_replays": None}
    return {"controls": options.get("controls", DEFAULT_PLAYER_CONTROLS), "max_replays": options.get("max_replays")}


def plays_left(plays: int, max_replays: int | None) -> int | None:
    """Plays the participant may still start after ``plays`` (None: unlimited)."""
    return None if max_replays is None else max(0, 1 + max_replays - plays)


def max_plays(page_ms: int, duration_s: float | None) -> int | None:
    """The most plays from the start that fit into page_ms (ms) of a clip of duration_s (s): one per full
    duration, plus the one under way. None when the duration is unknown."""
    if not duration_s or duration_s <= 0:
        return None
    return int(page_ms // (duration_s * 1000)) + 1


def carried_counts(post, page_ms: int, carried: dict | None) -> dict:
    """The assignment's carried counts plus those a page being left reports (``view_<field>`` of CARRIED_FIELDS):
    each an integer within its bound (times: page_ms, the ms since the page's first display; counts: MAX_COUNT),
    anything else is ignored; the sums are capped at the same bounds."""
    out = {k: v for k, v in (carried or {}).items() if k in CARRIED_FIELDS and isinstance(v, int)}
    for name in CARRIED_FIELDS:
        high = page_ms if name in VIEWING_TIME_FIELDS else MAX_COUNT
        value = _integer(post.get(field_name(name), ""), high)
        if value:
            out[name] = min(out.get(name, 0) + value, high)
    return out


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


def parse_viewing(post, page_ms: int, duration_s: float | None = None, playback: dict | None = None,
                  time_slack_ms: int = 5_000, max_replays: int | None = None, fetched: bool | None = None,
                  controls: str | None = None) -> dict:
    """The viewing record of an answer POST: every field of VIEWING_FIELDS (int or None) plus ``record`` (one of
    VIEWING_RECORDS), ``page_ms`` and ``shows``.

    page_ms: the time from the page's first display to the answer as the server measured it (ms); a posted time
    may exceed it by at most time_slack_ms. duration_s: the clip's duration (s), for the plays bound. playback:
    what the player reported while the page was open (``{"plays": int, "ended_ms": int | None, "shows": int,
    "carried": {field: int}}``, from the assignment): the plays count is at least its plays, an end reached before a
    reload of the page is kept as ``ended_ms`` 0 ("before this display"), and the counts of displays left without
    an answer are added to this display's. max_replays: the section player's limit (None: unlimited). fetched:
    whether the server sent this session the clip (None: not known, not checked). controls: the section player's
    controls (``full`` allows seeking, so an early end is not held against the record)."""
    playback = playback or {}
    record: dict = {name: None for name in VIEWING_FIELDS}
    record.update(page_ms=page_ms, shows=max(1, int(playback.get("shows") or 0)))
    if SCRIPT_FIELD not in post and not any(field_name(f) in post for f in VIEWING_FIELDS):
        return {**record, "record": "missing"}
    if post.get(SCRIPT_FIELD, "") != "1":
        return {**record, "record": "no_script"}
    implausible = False
    for name in VIEWING_FIELDS:
        raw = post.get(field_name(name), "")
        if raw == "":
            continue
        high = page_ms + time_slack_ms if name in VIEWING_TIME_FIELDS else MAX_COUNT
        value = _integer(raw, high)
        if value is None:
            implausible = True
            value = _integer(raw, 2**31 - 1)       # kept for the researcher to see, when it is a number at all
        record[name] = value
    first, ended, startup = record["first_play_ms"], record["ended_ms"], record["startup_ms"]
    if first is not None and ended is not None and ended < first:
        implausible = True                        # a clip ends after it starts
    if startup is not None and (first is None or startup > first):
        implausible = True                        # start-up ends with the first frame, timed from the page's display
    for name, value in (playback.get("carried") or {}).items():
        if name in CARRIED_FIELDS and isinstance(value, int) and value > 0:
            record[name] = (record[name] or 0) + value
    server_plays = int(playback.get("plays") or 0)
    if server_plays:
        record["plays"] = max(record["plays"] or 0, server_plays)
        if record["first_play_ms"] is None:
            record["first_play_ms"] = 0           # it played during an earlier display of the page
    if record["ended_ms"] is None and playback.get("ended_ms") is not None:
        record["ended_ms"] = 0                    # it ended during an earlier display of the page
    if record["ended_ms"] is not None:
        record["plays"] = max(record["plays"] or 0, 1)       # an end means it played, even if the start was missed
    bound = max_plays(page_ms + time_slack_ms, duration_s)
    if bound is not None and (record["plays"] or 0) > bound:
        implausible = True
    if max_replays is not None and (record["plays"] or 0) > 1 + max_replays:
        implausible = True                        # more plays than the player lets a participant start
    if fetched is False and ((record["plays"] or 0) > 0 or record["ended_ms"] is not None):
        implausible = True                        # a play of a clip the server never sent
    if _ended_too_soon(record, page_ms, duration_s, playback.get("ended_ms"), controls):
        implausible = True
    return {**record, "record": "implausible" if implausible else "ok"}


def _ended_too_soon(record: dict, page_ms: int, duration_s: float | None, server_ended_ms: int | None,
                    controls: str | None) -> bool:
    """An end sooner than ENDED_FRACTION of the duration after the page was shown (server clock: the answer's
    page_ms, the player's ``ended`` report) or after the reported first play, where the player cannot seek."""
    if not duration_s or duration_s <= 0 or controls == SEEKING_CONTROLS:
        return False
    shortest = ENDED_FRACTION * duration_s * 1000
    if server_ended_ms is not None and server_ended_ms < shortest:
        return True
    if record["ended_ms"] is None:
        return False
    if page_ms < shortest:
        return True
    first = record["first_play_ms"]
    return bool(record["ended_ms"] > 0 and first is not None and record["ended_ms"] - first < shortest)
