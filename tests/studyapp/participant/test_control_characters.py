"""Control characters (NUL first: PostgreSQL refuses it in any text value) in every participant-facing parameter,
path segment, form field and cookie are a 400 before the database is asked, on SQLite and on PostgreSQL (run this
file with DATABASE_URL set for the latter). Free text keeps its newlines and tabs."""
from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.urls import reverse

from studyapp.inputs import has_control_character
from studyapp.models import Participant, Response, Study
from studyapp.participant.assignment import current_step
from studyapp.participant.forms import ConsentForm, FeedbackForm
from studyapp.participant.viewing import SCRIPT_FIELD, VIEWING_FORM_FIELDS
from tests.studyapp.participant.test_study_flow import answer_for, consent, demographics

pytestmark = pytest.mark.django_db

CONTROLS = ["\x00", "\x01", "\x08", "\x0b", "\x1b", "\x1f", "\x7f", "\x85", "\x9f"]


def bad(text: str, control: str) -> str:
    return f"a{control}{text}"


@pytest.fixture
def study(settings, tmp_path):
    from studyapp.staff.presets import create_study_from_preset
    from studyapp.testing import make_catalogue

    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    s = create_study_from_preset("demo", "demo", plan="test", status=Study.Status.OPEN)
    s.sections.update(require_full_play=False)
    return s


def at_clip(client: Client, study: Study) -> Participant:
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    p.refresh_from_db()
    return p


def test_the_check_itself():
    for c in CONTROLS:
        assert has_control_character(bad("b", c))
        assert has_control_character(bad("b", c), allow_whitespace=True)
    for c in "\t\n\r":
        assert has_control_character(c) and not has_control_character(c, allow_whitespace=True)
    for fine in ["PID-123_abc", "Grüße, 東京 ✓", ""]:
        assert not has_control_character(fine)


@pytest.mark.parametrize("control", CONTROLS)
@pytest.mark.parametrize("param", ["PROLIFIC_PID", "STUDY_ID", "SESSION_ID", "other"])
def test_study_link_parameters(client, study, param, control):
    url = reverse("studyapp:study_entry", args=[study.slug])
    assert client.get(url, {param: bad("b", control)}).status_code == 400
    assert client.post(url, {"consent": "on", param: bad("b", control)}).status_code == 400
    assert client.post(url + "?PROLIFIC_PID=" + bad("b", control).replace("\x00", "%00"),
                       {"consent": "on"}).status_code == 400
    assert not Participant.objects.exists()


@pytest.mark.parametrize("control", CONTROLS)
def test_consent_key_and_consent_field(client, study, control):
    url = reverse("studyapp:study_entry", args=[study.slug])
    assert client.post(url, {"consent": bad("on", control)}).status_code == 400
    assert client.post(url, {"consent": "on", "consent_key": bad("k", control)}).status_code == 400
    assert not Participant.objects.exists()


@pytest.mark.parametrize("control", CONTROLS)
def test_tokens_and_media_keys_in_the_path(client, study, control):
    p = at_clip(client, study)
    token = bad(p.token, control)
    for name, kwargs in [("resume", {}), ("demographics", {}), ("item", {"n": 1}), ("playback", {"n": 1}),
                         ("feedback", {}), ("done", {})]:
        url = reverse(f"studyapp:{name}", kwargs={"token": token, **kwargs})
        assert client.get(url).status_code == 400, name
        assert client.post(url, {"x": "1"}).status_code == 400, name
    clip = current_step(p).assignment.clip
    assert client.get(reverse("studyapp:media", args=[bad(clip.media_key, control), "mp4"])).status_code == 400
    assert client.get(reverse("studyapp:media", args=[clip.media_key, bad("mp4", control)])).status_code == 400


@pytest.mark.parametrize("control", CONTROLS)
def test_demographics_fields(client, study, control):
    p = consent(client, study)
    url = reverse("studyapp:demographics", args=[p.token])
    for field in ("gender", "age_group"):
        data = {"gender": "female", "age_group": "25-34", field: bad("female", control)}
        assert client.post(url, data).status_code == 400, field
    p.refresh_from_db()
    assert not p.demographics_done


@pytest.mark.parametrize("control", CONTROLS)
def test_clip_answer_rt_and_viewing_fields(client, study, control):
    p = at_clip(client, study)
    step = current_step(p)
    url = reverse("studyapp:item", args=[p.token, step.index])
    good = answer_for(step.assignment)
    for field in [*good, "rt", "inline_next", SCRIPT_FIELD, *VIEWING_FORM_FIELDS]:
        data = {**good, "rt": "1200", field: bad("1", control)}
        assert client.post(url, data).status_code == 400, field
    assert not Response.objects.exists()
    playback = reverse("studyapp:playback", args=[p.token, step.index])
    for data in ({"event": bad("play", control)}, {"event": "leave", "view_pauses": bad("1", control)}):
        assert client.post(playback, data).status_code == 400
    assert client.post(url, good).status_code == 302        # the same answer without the control character


@pytest.mark.parametrize("control", CONTROLS)
def test_feedback_text_and_choices(client, study, control):
    study.feedback_questions = [{"key": "camera", "text": "Distracted?", "kind": "yesno"},
                                {"key": "notes", "text": "Anything else?", "kind": "text"}]
    study.save()
    p = at_clip(client, study)
    Participant.objects.filter(pk=p.pk).update(feedback_done=False)
    p.assignments.update(answered_at="2026-01-01T00:00:00Z")
    url = reverse("studyapp:feedback", args=[p.token])
    assert client.get(url).status_code == 200
    for data in ({"camera": "no", "notes": bad("text", control)}, {"camera": bad("no", control), "notes": ""}):
        assert client.post(url, data).status_code == 400
    p.refresh_from_db()
    assert not p.feedback_done
    r = client.post(url, {"camera": "no", "notes": "line one\r\n\tline two"})      # whitespace in free text is fine
    assert r.status_code == 302
    p.refresh_from_db()
    assert p.feedback["notes"] == "line one\r\n\tline two"


@pytest.mark.parametrize("control", ["\x00", "\x1b"])
def test_cookies_and_the_admin_login(client, study, control):
    client.cookies["sessionid"] = bad("abcdefghijkl", control)
    assert client.get(reverse("studyapp:study_entry", args=[study.slug])).status_code == 400
    other = Client()
    User.objects.create_superuser("boss", password="pw-boss-1")
    r = other.post(reverse("admin:login"), {"username": bad("boss", control), "password": "x"})
    assert r.status_code == 400


def test_forms_refuse_them_too():
    assert not ConsentForm({"consent": "on", "PROLIFIC_PID": "a\nb"}).is_valid()
    form = FeedbackForm([{"key": "notes", "text": "t", "kind": "text"}], {"notes": "a\x00b"})
    assert not form.is_valid()
    assert FeedbackForm([{"key": "notes", "text": "t", "kind": "text"}], {"notes": "a\nb"}).is_valid()
