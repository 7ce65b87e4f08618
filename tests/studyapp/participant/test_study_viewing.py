"""Clip player options and the viewing record: option validation, the record's server-side checks and bounds,
its storage with the answer (no extra query), viewing.csv, and the player markup each option gives."""
from __future__ import annotations

import csv
import io

import pytest
from django.db import connection
from django.test import Client
from django.test.utils import CaptureQueriesContext
from django.urls import reverse

from protocol.pools import options_errors, player_errors
from protocol.vocabulary import VIEWING_COLUMNS, VIEWING_FIELDS
from studyapp.data.export import stream_csv
from studyapp.models import Assignment, Participant, Study
from studyapp.participant.assignment import current_step
from studyapp.participant.viewing import MAX_COUNT, SCRIPT_FIELD, carried_counts, field_name, max_plays, parse_viewing
from tests.studyapp.participant import test_study_flow as flow
from tests.studyapp.participant.test_study_flow import answer_for, consent, cur, demographics

GOOD_RECORD = {"first_play_ms": 120, "ended_ms": 2400, "plays": 2, "pauses": 1, "seeks": 3, "stalls": 1,
               "stall_ms": 250, "hidden": 1}


def posted(record: dict) -> dict:
    """The record's fields as the player's script posts them."""
    return {SCRIPT_FIELD: "1", **{field_name(k): str(v) for k, v in record.items()}}


# ---- options ---------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("options", [{"controls": "replay-only"}, {"controls": "full", "max_replays": None},
                                     {"controls": "none", "max_replays": 0}, {"max_replays": 100}])
def test_good_player_options(options):
    assert player_errors(options) == []
    assert options_errors("emotion_choice", options, 6) == []
    assert options_errors("naturalness", options, 6) == []


@pytest.mark.parametrize("options,words", [
    ({"controls": "scrub"}, ["'controls'", "replay-only, full, none", "'scrub'"]),
    ({"controls": True}, ["'controls'"]),
    ({"max_replays": -1}, ["'max_replays'", "0 to 100", "unlimited"]),
    ({"max_replays": 2.5}, ["'max_replays'", "integer"]),
    ({"max_replays": "3"}, ["'max_replays'", "integer"]),
    ({"max_replays": True}, ["'max_replays'"]),
    ({"max_replays": 101}, ["'max_replays'", "0 to 100"]),
])
def test_bad_player_options_name_the_key(options, words):
    message = " | ".join(player_errors(options))
    assert message, options
    for word in words:
        assert word in message, (word, message)
    assert options_errors("gesture_emotion", {**options, "categories": ["proud", "sad", "afraid", "happy"]})


@pytest.mark.parametrize("stype,options", [("emotion_choice", {"controls": "full", "max_replays": 2}),
                                           ("naturalness", {"controls": "none", "max_replays": 0}),
                                           ("gesture_emotion", {"controls": "replay-only"})])
def test_pool_editor_shows_and_writes_the_player_options(stype, options):
    from studyapp.admin import pool_editor as pe

    values, leftover = pe.options_to_fields(options)
    assert leftover == {} and values[pe.OPTIONS_PREFIX + "controls"] == options["controls"]
    assert pe.fields_to_options(values, leftover, stype) == options
    blank = pe.fields_to_options({pe.OPTIONS_PREFIX + "controls": "", pe.OPTIONS_PREFIX + "max_replays": None}, {},
                                 stype)
    assert "controls" not in blank and "max_replays" not in blank      # blank: the default player, unlimited
    fields = pe.form_fields()
    assert not fields[pe.OPTIONS_PREFIX + "max_replays"].clean(None) and fields[pe.OPTIONS_PREFIX + "controls"]


# ---- parsing ---------------------------------------------------------------------------------------------------

def test_parse_keeps_a_plausible_record():
    record = parse_viewing(posted(GOOD_RECORD), page_ms=10_000)
    assert record == {**GOOD_RECORD, "startup_ms": None, "hidden_ms": None, "record": "ok", "page_ms": 10_000,
                      "shows": 1}
    assert parse_viewing({**posted(GOOD_RECORD), field_name("plays"): "2.0"}, 10_000)["plays"] == 2


def test_a_post_without_record_is_missing_and_a_page_without_script_says_so():
    missing = parse_viewing({"perceived": "sad", "rt": "900"}, page_ms=10_000)
    assert missing["record"] == "missing" and all(missing[f] is None for f in VIEWING_FIELDS)
    assert missing["page_ms"] == 10_000 and missing["shows"] == 1
    blank_form = {field_name(f): "" for f in VIEWING_FIELDS} | {SCRIPT_FIELD: ""}   # the page without JavaScript
    assert parse_viewing(blank_form, page_ms=10_000)["record"] == "no_script"
    no_script = parse_viewing({**blank_form, field_name("plays"): "4"}, page_ms=10_000)
    assert no_script["record"] == "no_script" and no_script["plays"] is None       # not the script's: not kept
    assert parse_viewing({SCRIPT_FIELD: "1"}, page_ms=10_000)["record"] == "ok"


def test_start_up_must_end_by_the_first_frame():
    """startup_ms runs from the first play request to the first frame, both in ms from the page's display: it
    cannot be longer than first_play_ms, nor come without it."""
    assert parse_viewing(posted({**GOOD_RECORD, "startup_ms": 120}), page_ms=10_000)["record"] == "ok"
    assert parse_viewing(posted({**GOOD_RECORD, "startup_ms": 121}), page_ms=10_000)["record"] == "implausible"
    no_frame = {**GOOD_RECORD, "first_play_ms": "", "ended_ms": "", "startup_ms": 50}
    assert parse_viewing(posted(no_frame), page_ms=10_000)["record"] == "implausible"


@pytest.mark.parametrize("name,raw", [
    ("first_play_ms", "-1"), ("first_play_ms", "nan"), ("first_play_ms", "inf"), ("first_play_ms", "1e400"),
    ("first_play_ms", "abc"), ("first_play_ms", "12.5"), ("ended_ms", "15001"), ("stall_ms", "99999999"),
    ("plays", str(MAX_COUNT + 1)), ("seeks", "-3"), ("hidden", "1;2"), ("pauses", "9" * 40),
])
def test_out_of_bound_or_malformed_fields_make_the_record_implausible(name, raw):
    record = parse_viewing({**posted(GOOD_RECORD), field_name(name): raw}, page_ms=10_000)
    assert record["record"] == "implausible"
    assert all(record[k] == v for k, v in GOOD_RECORD.items() if k != name and k != "ended_ms")


def test_an_end_before_the_first_play_is_implausible():
    record = parse_viewing({**posted(GOOD_RECORD), field_name("ended_ms"): "100"}, 10_000)
    assert record["record"] == "implausible"


@pytest.mark.parametrize("change", [{"first_play_ms": ""}, {"plays": "0"}])
def test_an_end_means_it_played(change):
    """The start may be missed (the clip started before the script attached): the end still counts as a play."""
    record = parse_viewing({**posted(GOOD_RECORD), **{field_name(k): v for k, v in change.items()}}, 10_000)
    assert record["ended_ms"] == 2400 and record["plays"] >= 1 and record["record"] == "ok"


def test_plays_are_bounded_by_the_page_time_over_the_clip_duration():
    faked = parse_viewing(posted({**GOOD_RECORD, "plays": 999}), page_ms=5_000, duration_s=1.0, time_slack_ms=0)
    assert faked["record"] == "implausible" and faked["plays"] == 999       # kept as sent, marked not trusted
    assert max_plays(5_000, 1.0) == 6 and max_plays(5_000, None) is None
    fair = parse_viewing(posted({**GOOD_RECORD, "plays": 6}), page_ms=5_000, duration_s=1.0, time_slack_ms=0)
    assert fair["record"] == "ok"
    assert parse_viewing(posted({**GOOD_RECORD, "plays": 7}), 5_000, 1.0, time_slack_ms=0)["record"] == "implausible"

    assert parse_viewing(posted({**GOOD_RECORD, "plays": 2}), 5_000, 1.0, max_replays=1)["record"] == "ok"
    beyond = parse_viewing(posted({**GOOD_RECORD, "plays": 3}), 5_000, 1.0, max_replays=1)
    assert beyond["record"] == "implausible" and beyond["plays"] == 3
    assert parse_viewing(posted({**GOOD_RECORD, "plays": 2}), 5_000, 1.0, max_replays=0)["record"] == "implausible"


def test_the_servers_playback_counts_survive_a_reload():
    """After a reload the page's own record starts from zero; the plays and the end the player reported before
    are the server's."""
    fresh = {SCRIPT_FIELD: "1", field_name("plays"): "0", field_name("pauses"): "0"}
    record = parse_viewing(fresh, 20_000, 2.0, {"plays": 3, "ended_ms": 2_500, "shows": 2})
    assert record["plays"] == 3 and record["ended_ms"] == 0 and record["first_play_ms"] == 0
    assert record["shows"] == 2 and record["record"] == "ok"


def test_counts_of_displays_left_without_an_answer_are_added():
    fresh = {SCRIPT_FIELD: "1", field_name("plays"): "1", field_name("pauses"): "1", field_name("hidden"): "0"}
    record = parse_viewing(fresh, 20_000, 2.0, {"plays": 2, "carried": {"pauses": 2, "hidden": 1, "hidden_ms": 700,
                                                                         "unknown": 5, "seeks": "x"}})
    assert (record["pauses"], record["hidden"], record["hidden_ms"], record["seeks"]) == (3, 1, 700, None)
    assert carried_counts({field_name("pauses"): "2", field_name("hidden_ms"): "99999", field_name("seeks"): "-1"},
                          5_000, {"pauses": 1}) == {"pauses": 3}        # out of bound values are ignored


def test_missing_fields_are_unknown():
    record = parse_viewing({SCRIPT_FIELD: "1", field_name("plays"): "1"}, page_ms=10_000)
    assert {k: record[k] for k in VIEWING_FIELDS} == {**{f: None for f in VIEWING_FIELDS}, "plays": 1}


# ---- the answer path -------------------------------------------------------------------------------------------

study = flow.study          # the open demo study of the participant-flow tests (a fixture)

def started(client: Client, study: Study) -> Participant:
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    return p


def fetch_clip(client, p) -> None:
    """What the player does first: fetch the current page's clip (the server's evidence that it was sent)."""
    clip = cur(p).assignment.clip
    assert client.get(reverse("studyapp:media", args=[clip.media_key, "mp4"])).status_code == 200


def answer(client, p, n, extra):
    step = cur(p)
    r = client.post(reverse("studyapp:item", args=[p.token, n]), {**answer_for(step.assignment), **extra})
    assert r.status_code == 302, r.content[:300]
    return step.assignment


@pytest.mark.django_db
def test_record_is_stored_with_the_answer_without_extra_queries(client, study):
    p = started(client, study)
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    with CaptureQueriesContext(connection) as plain:
        answer(client, p, 1, {"rt": "900"})
    client.get(reverse("studyapp:item", args=[p.token, 2]))
    with CaptureQueriesContext(connection) as recorded:
        a2 = answer(client, p, 2, {"rt": "900", **posted({**GOOD_RECORD, "ended_ms": 500})})
    assert len(recorded) == len(plain)
    a1 = Assignment.objects.get(participant=p, seq=1)
    assert a1.viewing["record"] == "missing" and a1.viewing["plays"] is None     # posted without the page's fields
    a2.refresh_from_db()
    stored = a2.viewing
    assert stored["plays"] == 2 and stored["hidden"] == 1 and stored["seeks"] == 3
    assert stored["ended_ms"] == 500 and stored["first_play_ms"] == 120


@pytest.mark.django_db
def test_times_beyond_the_page_time_are_not_stored(client, study):
    p = started(client, study)
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    a = answer(client, p, 1, posted({**GOOD_RECORD, "ended_ms": 3_000_000, "stall_ms": 2_000_000}))
    a.refresh_from_db()
    assert a.viewing["record"] == "implausible" and a.viewing["plays"] == 2


@pytest.mark.django_db
def test_start_up_buffering_is_stored_as_start_up_time_not_as_stalls(client, study):
    """The player's record of a clip that buffered 800 ms before its first frame and never after: viewing.csv has
    startup_ms 800 and no stall, and a stall after the first frame is counted as one."""
    p = started(client, study)
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    fetch_clip(client, p)
    answer(client, p, 1, posted({**GOOD_RECORD, "first_play_ms": 900, "ended_ms": 3900, "startup_ms": 800,
                                 "stalls": 0, "stall_ms": 0}))
    client.get(reverse("studyapp:item", args=[p.token, 2]))
    fetch_clip(client, p)
    answer(client, p, 2, posted({**GOOD_RECORD, "first_play_ms": 300, "ended_ms": 3500, "startup_ms": 250,
                                 "stalls": 1, "stall_ms": 400}))
    rows = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "viewing")))))
    got = [(r["startup_ms"], r["stalls"], r["stall_ms"], r["record"]) for r in rows]
    assert got == [("800", "0", "0", "ok"), ("250", "1", "400", "ok")], got


@pytest.mark.django_db
def test_viewing_csv_has_one_row_per_answered_clip_page(client, study):
    p = started(client, study)
    for n in (1, 2):
        client.get(reverse("studyapp:item", args=[p.token, n]))
    answer(client, p, 1, {})
    client.get(reverse("studyapp:item", args=[p.token, 2]))
    client.get(reverse("studyapp:item", args=[p.token, 2]))      # a reload
    fetch_clip(client, p)
    a2 = answer(client, p, 2, posted(GOOD_RECORD | {"ended_ms": 400}))
    rows = list(csv.reader(io.StringIO("".join(stream_csv(study, "viewing")))))
    assert tuple(rows[0]) == VIEWING_COLUMNS
    assert len(rows) == 3
    first, second = rows[1], rows[2]
    n = len(VIEWING_FIELDS)
    assert first[:1] == [p.public_id] and first[3:3 + n] == [""] * n and first[3 + n] == "missing"
    assert second[1] == a2.clip.clip_id and second[2] == a2.section.section_type
    assert second[3:3 + n] == ["120", "400", "2", "1", "3", "1", "250", "1", "", ""]
    assert second[3 + n] == "ok" and int(second[4 + n]) >= 0 and second[5 + n] == "2"     # shown twice: a reload


@pytest.mark.django_db
def test_viewing_csv_download_for_staff(client, study, django_user_model):
    staff = django_user_model.objects.create_superuser("boss", "b@example.org", "pw-long-enough-123")
    c = Client()
    c.force_login(staff)
    r = c.get(reverse("studyapp:export_csv", args=[study.pk, "viewing"]))
    assert r.status_code == 200
    assert b"".join(r.streaming_content).decode().splitlines()[0] == ",".join(VIEWING_COLUMNS)


# ---- the player's markup ---------------------------------------------------------------------------------------

def with_player_options(study, **options) -> None:
    """Give every section of ``study`` these player options (controls, max_replays) on top of its own."""
    for section in study.sections.all():
        section.options = {**section.options, **options}
        section.save()


@pytest.mark.django_db
@pytest.mark.parametrize("options,native,attrs", [
    ({}, False, ['data-controls="replay-only"', 'data-max-replays=""', 'id="play-pause"', 'id="replay"']),
    ({"controls": "full", "max_replays": 2}, True, ['data-controls="full"', 'data-max-replays="2"']),
    ({"controls": "none", "max_replays": 0}, False, ['data-controls="none"', 'data-max-replays="0"']),
])
def test_player_markup_follows_the_options(client, study, options, native, attrs):
    with_player_options(study, **options)
    p = started(client, study)
    html = client.get(reverse("studyapp:item", args=[p.token, 1])).content.decode()
    video = html[html.index("<video"):html.index(">", html.index("<video"))]
    assert (" controls " in video or video.endswith(" controls")) == native, video
    for attr in attrs:
        assert attr in html, attr
    for name in VIEWING_FIELDS:
        assert f'name="{field_name(name)}"' in html
    if options.get("controls") == "none":
        assert 'id="play-pause"' not in html


# ---- playback kept across reloads, media access -----------------------------------------------------------------

def report(client, p, n, event):
    """What the player's script sends on a play from the start or the clip's first end."""
    return client.post(reverse("studyapp:playback", args=[p.token, n]), {"event": event})


@pytest.mark.django_db
def test_a_reload_keeps_the_plays_and_max_replays_holds(client, study):
    with_player_options(study, max_replays=1)
    p = started(client, study)
    url = reverse("studyapp:item", args=[p.token, 1])
    html = client.get(url).content.decode()
    assert 'data-plays-before="0"' in html and " autoplay" in html
    assert f'data-playback-url="{reverse("studyapp:playback", args=[p.token, 1])}"' in html
    assert report(client, p, 1, "play").status_code == 204
    assert report(client, p, 1, "ended").status_code == 204
    html = client.get(url).content.decode()                     # a reload: one replay left, it may autoplay
    assert 'data-plays-before="1"' in html and 'data-ended-before="1"' in html and " autoplay" in html
    assert report(client, p, 1, "play").status_code == 204
    html = client.get(url).content.decode()                     # no plays left: the clip does not start again
    video = html[html.index("<video"):html.index(">", html.index("<video"))]
    assert 'data-plays-before="2"' in video and " autoplay" not in video
    fetch_clip(client, p)
    a = answer(client, p, 1, posted({"plays": 0, "pauses": 0}))      # the last display's own record: no play
    a.refresh_from_db()
    assert a.plays == 2 and a.play_ended_ms is not None and a.shows == 3
    assert a.viewing["plays"] == 2 and a.viewing["ended_ms"] == 0 and a.viewing["shows"] == 3
    assert a.viewing["record"] == "ok"
    # answered: reports for it are refused and change nothing
    assert report(client, p, 1, "play").status_code == 404
    a.refresh_from_db()
    assert a.plays == 2


@pytest.mark.django_db
def test_plays_beyond_max_replays_that_bypass_the_player_make_the_record_implausible(client, study):
    with_player_options(study, max_replays=0)
    p = started(client, study)
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    assert report(client, p, 1, "play").status_code == 204
    assert report(client, p, 1, "play").status_code == 204       # a replay the player would not have started
    a = answer(client, p, 1, posted({"plays": 0, "pauses": 0}))
    a.refresh_from_db()
    assert a.viewing["plays"] == 2 and a.viewing["record"] == "implausible"


@pytest.mark.django_db
def test_a_display_left_without_an_answer_hands_on_its_counts(client, study):
    p = started(client, study)
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    from datetime import timedelta

    from django.utils import timezone

    Assignment.objects.filter(participant=p, seq=1).update(shown_at=timezone.now() - timedelta(seconds=10))
    leave = {"event": "leave", field_name("pauses"): "2", field_name("hidden"): "1", field_name("hidden_ms"): "400"}
    assert client.post(reverse("studyapp:playback", args=[p.token, 1]), leave).status_code == 204
    client.get(reverse("studyapp:item", args=[p.token, 1]))             # the reload
    a = answer(client, p, 1, posted({**GOOD_RECORD, "hidden": 0, "pauses": 1}))
    a.refresh_from_db()
    assert a.carried == {"pauses": 2, "hidden": 1, "hidden_ms": 400}
    assert (a.viewing["pauses"], a.viewing["hidden"], a.viewing["hidden_ms"]) == (3, 1, 400)


@pytest.mark.django_db
def test_playback_reports_are_checked(client, study):
    p = started(client, study)
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    assert report(client, p, 1, "jump").status_code == 400
    assert report(client, p, 5, "play").status_code == 404          # not the participant's current page
    assert client.get(reverse("studyapp:playback", args=[p.token, 1])).status_code == 405
    assert Client(enforce_csrf_checks=True).post(reverse("studyapp:playback", args=[p.token, 1]),
                                                 {"event": "play"}).status_code == 403
    other = Client()
    assert other.post(reverse("studyapp:playback", args=["no-such-token-xyz", 1]),
                      {"event": "play"}).status_code == 404


@pytest.mark.django_db
def test_media_needs_the_participants_session_and_stops_once_answered(client, study):
    p = started(client, study)
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    p.refresh_from_db()
    step = current_step(p, lookahead=True)
    clip_url = reverse("studyapp:media", args=[step.assignment.clip.media_key, "mp4"])
    next_url = reverse("studyapp:media", args=[step.next_assignment.clip.media_key, "mp4"])
    assert client.get(clip_url).status_code == 200
    assert client.get(next_url).status_code == 200                    # the next clip may be preloaded
    assert Client().get(clip_url).status_code == 403                  # the URL alone (a new browser, a script)
    p.assignments.exclude(pk=step.assignment.pk).filter(clip=step.assignment.clip).delete()   # shown once only
    answer(client, p, 1, posted(GOOD_RECORD))
    assert client.get(clip_url).status_code == 403                    # answered: no more viewing


@pytest.mark.django_db
def test_media_admits_the_current_clip_and_the_preloaded_next_one_only(client, study):
    p = started(client, study)
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    order = list(p.assignments.order_by("seq"))
    near = {a.clip_id for a in order[:2]}                              # the current page's clip and the next
    later = next(a for a in order[2:] if a.clip_id not in near)       # a page further on

    def status(assignment) -> int:
        return client.get(reverse("studyapp:media", args=[assignment.clip.media_key, "mp4"])).status_code

    assert (status(order[0]), status(order[1]), status(later)) == (200, 200, 403)
    for n in range(1, later.seq - 1):                                 # on to the page before it
        answer(client, p, n, posted(GOOD_RECORD))
    assert status(later) == 200                                        # now the next one: preloaded


@pytest.mark.django_db
def test_a_participant_link_opened_in_a_new_browser_can_play_its_clip(client, study):
    p = started(client, study)
    step = cur(p)
    elsewhere = Client()                                             # the /p/<token>/ link on another device
    assert elsewhere.get(reverse("studyapp:item", args=[p.token, step.index])).status_code == 200
    assert elsewhere.get(reverse("studyapp:media", args=[step.assignment.clip.media_key, "mp4"])).status_code == 200


@pytest.mark.django_db
def test_staff_who_may_see_the_catalogue_get_media(study, django_user_model):
    from studyapp.models import Clip

    clip = Clip.objects.first()
    url = reverse("studyapp:media", args=[clip.media_key, "mp4"])
    staff = Client()
    staff.force_login(django_user_model.objects.create_superuser("boss2", "b@example.org", "pw-long-enough-123"))
    assert staff.get(url).status_code == 200
    plain = Client()
    plain.force_login(django_user_model.objects.create_user("member", password="pw-member-12345"))
    assert plain.get(url).status_code == 403


# ---- the record against the server's evidence ------------------------------------------------------------------

def shown_ago(p, seconds: float) -> None:
    """Move the current page's first display back in time (as if the participant had been on it that long)."""
    from datetime import timedelta

    from django.utils import timezone

    Assignment.objects.filter(pk=cur(p).assignment.pk).update(shown_at=timezone.now() - timedelta(seconds=seconds))


def six_second_clips(study) -> None:
    from studyapp.models import Clip

    Clip.objects.update(duration_s=6.0)
    study.sections.update(require_full_play=False)


@pytest.mark.django_db
def test_a_forged_record_of_a_clip_never_fetched_is_implausible(client, study):
    p = started(client, study)
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    forged = answer(client, p, 1, posted(GOOD_RECORD))          # invented fields: the clip was never sent
    forged.refresh_from_db()
    assert forged.fetched_at is None and forged.viewing["record"] == "implausible"
    client.get(reverse("studyapp:item", args=[p.token, 2]))
    fetch_clip(client, p)
    honest = answer(client, p, 2, posted(GOOD_RECORD))
    honest.refresh_from_db()
    assert honest.fetched_at is not None and honest.viewing["record"] == "ok"


@pytest.mark.django_db
def test_an_end_reported_sooner_than_the_clip_lasts_is_implausible(client, study):
    six_second_clips(study)
    p = started(client, study)
    client.get(reverse("studyapp:item", args=[p.token, 1]))
    fetch_clip(client, p)
    assert report(client, p, 1, "play").status_code == 204
    assert report(client, p, 1, "ended").status_code == 204     # 'ended' a few ms after the page of a 6 s clip
    shown_ago(p, 10)                                             # the answer itself comes late enough
    early = answer(client, p, 1, posted({"first_play_ms": 100, "ended_ms": 6300, "plays": 1}))
    early.refresh_from_db()
    assert early.play_ended_ms < 1000 and early.viewing["record"] == "implausible"
    # the same record after the clip had time to play: ok
    client.get(reverse("studyapp:item", args=[p.token, 2]))
    fetch_clip(client, p)
    shown_ago(p, 7)
    assert report(client, p, 2, "ended").status_code == 204
    fair = answer(client, p, 2, posted({"first_play_ms": 100, "ended_ms": 6300, "plays": 1}))
    fair.refresh_from_db()
    assert fair.viewing["record"] == "ok"


def test_ends_too_soon_after_the_first_play_or_the_page_are_implausible():
    record = {"first_play_ms": 100, "ended_ms": 160, "plays": 1}
    assert parse_viewing(posted(record), 10_000, 6.0, fetched=True)["record"] == "implausible"
    assert parse_viewing(posted(record), 10_000, 6.0, fetched=True, controls="full")["record"] == "ok"   # seekable
    ok = {"first_play_ms": 100, "ended_ms": 6200, "plays": 1}
    assert parse_viewing(posted(ok), 6_300, 6.0, fetched=True)["record"] == "ok"
    assert parse_viewing(posted(ok), 3_000, 6.0, fetched=True)["record"] == "implausible"    # the page was shorter
    assert parse_viewing(posted(ok), 6_300, 6.0, fetched=False)["record"] == "implausible"   # never sent
    assert parse_viewing(posted({"plays": 0}), 6_300, 6.0, fetched=False)["record"] == "ok"  # nothing claimed
