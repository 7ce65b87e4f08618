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

from study_pools import options_errors, player_errors
from study_protocol import VIEWING_COLUMNS, VIEWING_FIELDS
from studyapp.export import stream_csv
from studyapp.models import Assignment, Participant, Study
from studyapp.viewing import MAX_COUNT, field_name, parse_viewing
from tests import test_study_flow as flow
from tests.test_study_flow import answer_for, consent, cur, demographics

GOOD_RECORD = {"first_play_ms": 120, "ended_ms": 2400, "plays": 2, "pauses": 1, "seeks": 3, "stalls": 1,
               "stall_ms": 250, "hidden": 1}


def posted(record: dict) -> dict:
    return {field_name(k): str(v) for k, v in record.items()}


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
    from studyapp import pool_editor as pe

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
    assert parse_viewing(posted(GOOD_RECORD), page_ms=10_000) == GOOD_RECORD
    assert parse_viewing({**posted(GOOD_RECORD), field_name("plays"): "2.0"}, 10_000)["plays"] == 2


def test_a_post_without_record_stores_none():
    assert parse_viewing({"perceived": "sad", "rt": "900"}, page_ms=10_000) is None
    blank_form = {field_name(f): "" for f in VIEWING_FIELDS}               # the page without JavaScript
    assert parse_viewing(blank_form, page_ms=10_000) is None
    assert parse_viewing({**blank_form, field_name("plays"): "-4"}, page_ms=10_000) is None


@pytest.mark.parametrize("name,raw", [
    ("first_play_ms", "-1"), ("first_play_ms", "nan"), ("first_play_ms", "inf"), ("first_play_ms", "1e400"),
    ("first_play_ms", "abc"), ("first_play_ms", "12.5"), ("ended_ms", "10001"), ("stall_ms", "99999999"),
    ("plays", str(MAX_COUNT + 1)), ("seeks", "-3"), ("hidden", "1;2"), ("pauses", "9" * 40),
])
def test_out_of_bound_or_malformed_fields_become_unknown(name, raw):
    record = parse_viewing({**posted(GOOD_RECORD), field_name(name): raw}, page_ms=10_000)
    assert record[name] is None
    assert all(record[k] == v for k, v in GOOD_RECORD.items() if k != name and k != "ended_ms")


@pytest.mark.parametrize("change", [{"ended_ms": "100"}, {"first_play_ms": ""}, {"plays": "0"}])
def test_an_end_before_any_play_is_dropped(change):
    record = parse_viewing({**posted(GOOD_RECORD), **{field_name(k): v for k, v in change.items()}}, 10_000)
    assert record["ended_ms"] is None


def test_missing_fields_are_unknown():
    record = parse_viewing({field_name("plays"): "1"}, page_ms=10_000)
    assert record == {**{f: None for f in VIEWING_FIELDS}, "plays": 1}


# ---- the answer path -------------------------------------------------------------------------------------------

study = flow.study          # the open demo study of the participant-flow tests (a fixture)

def started(client: Client, study: Study) -> Participant:
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    return p


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
    assert a1.viewing is None
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
    assert a.viewing["ended_ms"] is None and a.viewing["stall_ms"] is None and a.viewing["plays"] == 2


@pytest.mark.django_db
def test_viewing_csv_has_one_row_per_answered_clip_page(client, study):
    p = started(client, study)
    for n in (1, 2):
        client.get(reverse("studyapp:item", args=[p.token, n]))
    answer(client, p, 1, {})
    client.get(reverse("studyapp:item", args=[p.token, 2]))
    a2 = answer(client, p, 2, posted(GOOD_RECORD | {"ended_ms": 400}))
    rows = list(csv.reader(io.StringIO("".join(stream_csv(study, "viewing")))))
    assert tuple(rows[0]) == VIEWING_COLUMNS
    assert len(rows) == 3
    first, second = rows[1], rows[2]
    assert first[:1] == [p.public_id] and first[3:] == [""] * len(VIEWING_FIELDS)
    assert second[1] == a2.clip.clip_id and second[2] == a2.section.section_type
    assert second[3:] == ["120", "400", "2", "1", "3", "1", "250", "1"]


@pytest.mark.django_db
def test_viewing_csv_download_for_staff(client, study, django_user_model):
    staff = django_user_model.objects.create_superuser("boss", "b@example.org", "pw-long-enough-123")
    c = Client()
    c.force_login(staff)
    r = c.get(reverse("studyapp:export_csv", args=[study.pk, "viewing"]))
    assert r.status_code == 200
    assert b"".join(r.streaming_content).decode().splitlines()[0] == ",".join(VIEWING_COLUMNS)


# ---- the player's markup ---------------------------------------------------------------------------------------

@pytest.mark.django_db
@pytest.mark.parametrize("options,native,attrs", [
    ({}, False, ['data-controls="replay-only"', 'data-max-replays=""', 'id="play-pause"', 'id="replay"']),
    ({"controls": "full", "max_replays": 2}, True, ['data-controls="full"', 'data-max-replays="2"']),
    ({"controls": "none", "max_replays": 0}, False, ['data-controls="none"', 'data-max-replays="0"']),
])
def test_player_markup_follows_the_options(client, study, options, native, attrs):
    for section in study.sections.all():
        section.options = {**section.options, **options}
        section.save()
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
