"""Participant flow: consent, demographics, clips in order, validation, resume, double submit, Prolific, completion."""
from __future__ import annotations

import re
from datetime import timedelta

import pytest
from django.test import Client
from django.urls import reverse
from django.utils import timezone

from protocol.vocabulary import SECTION_TYPES
from studyapp.models import Assignment, Participant, Response, Study
from studyapp.participant.assignment import current_step
from studyapp.questions import questions_for
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    s = create_study_from_preset("demo", "demo", plan="test", status=Study.Status.OPEN,
                                 completion_redirect="https://app.prolific.com/submissions/complete?cc={code}")
    s.sections.update(require_full_play=False)
    return s


def consent(client: Client, study: Study, query: str = "") -> Participant:
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]) + query, {"consent": "on"})
    assert r.status_code == 302, r.content[:500]
    token = r["Location"].rstrip("/").split("/")[-1]
    return Participant.objects.get(token=token)


def answer_for(assignment: Assignment) -> dict:
    """A valid POST for an assignment: the first choice of every question."""
    section, clip = assignment.section, assignment.clip
    return {q.key: q.choices[0][0] for q in questions_for(section.section_type, section.options, clip.theme,
                                                          assignment.options)}


def cur(p: Participant):
    """The participant's step, read fresh from the database."""
    p.refresh_from_db()
    return current_step(p)


def demographics(client, p):
    r = client.post(reverse("studyapp:demographics", args=[p.token]), {"gender": "female", "age_group": "25-34"})
    assert r.status_code == 302


def test_home_page_lists_open_studies_that_ask_to_be_listed_only(client, study):
    assert "No study is open" in client.get("/").content.decode()      # open, but not listed: its slug stays unseen
    assert study.slug not in client.get("/").content.decode()
    Study.objects.filter(pk=study.pk).update(listed_publicly=True)
    create_study_from_preset("rbf_thms2016", "draft-study", plan="test", title="A draft study",
                             listed_publicly=True)
    create_study_from_preset("rbf_thms2016", "closed-study", plan="test", title="A closed study",
                             status=Study.Status.CLOSED, listed_publicly=True)
    r = client.get("/")
    assert r.status_code == 200
    html = r.content.decode()
    assert "<h2>Open studies</h2>" in html
    link = reverse("studyapp:study_entry", args=[study.slug])
    assert f'href="{link}">{study.title}</a>' in html
    assert "draft-study" not in html and "A draft study" not in html
    assert "closed-study" not in html and "No study is open" not in html


def test_whole_study_and_one_response_per_question(client, study):
    p = consent(client, study)
    demographics(client, p)
    r = client.get(reverse("studyapp:resume", args=[p.token]))
    assert r.status_code == 302 and "/clip/1/" in r["Location"]
    p.refresh_from_db()
    assert p.status == "started" and p.started_at is not None
    total = p.assignments.count()
    assert total > 0
    expected = 0
    for n in range(1, total + 1):
        step = cur(p)
        assert step.kind == "item" and step.index == n
        page = client.get(reverse("studyapp:item", args=[p.token, n]))
        assert page.status_code == 200
        assert f"Clip {n} of {total}".encode() in page.content
        data = answer_for(step.assignment)
        expected += len(data)
        r = client.post(reverse("studyapp:item", args=[p.token, n]), data)
        assert r.status_code == 302
    r = client.get(reverse("studyapp:resume", args=[p.token]))
    assert r["Location"].endswith("/feedback/")
    feedback = {q["key"]: "yes" if q["kind"] == "yesno" else "fine" for q in study.feedback_questions}
    r = client.post(reverse("studyapp:feedback", args=[p.token]), feedback)
    r = client.get(reverse("studyapp:resume", args=[p.token]))
    assert r["Location"].endswith("/done/")
    page = client.get(r["Location"])
    assert study.completion_code.encode() in page.content
    assert f"cc={study.completion_code}".encode() in page.content
    p.refresh_from_db()
    assert p.status == "completed" and p.completed_at and p.feedback["distracted_camera"] == "yes"
    assert Response.objects.filter(participant=p).count() == expected
    assert set(Response.objects.values_list("section__section_type", flat=True)) == set(SECTION_TYPES)


def test_double_submit_and_back_button_store_one_answer(client, study):
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    a = cur(p).assignment
    url = reverse("studyapp:item", args=[p.token, 1])
    data = answer_for(a)
    for _ in range(3):
        assert client.post(url, data).status_code == 302
    assert Response.objects.filter(participant=p, clip=a.clip).count() == len(data)
    # back button: the old page redirects to where the participant is
    r = client.get(url)
    assert r.status_code == 302 and r["Location"].endswith(f"/p/{p.token}/")
    assert client.get(r["Location"])["Location"].endswith("/clip/2/")


def test_answers_of_one_page_resent_to_the_next_page_are_not_stored_there(client, study):
    """A browser that resends the POST which brought clip page 2 when page 2 is reloaded (WebKit, after the page
    put its own URL into the address bar) posts clip 1's answers to clip 2's URL: they are not clip 2's answers."""
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    first = cur(p).assignment
    data = {**answer_for(first), "page": "1", "inline_next": "1"}
    page2 = client.post(reverse("studyapp:item", args=[p.token, 1]), data)
    assert page2.status_code == 200 and 'name="page" value="2"' in page2.content.decode()
    second = cur(p).assignment
    r = client.post(reverse("studyapp:item", args=[p.token, 2]), data)        # the resent POST
    assert r.status_code == 302 and r["Location"].endswith("/clip/2/")
    assert not Response.objects.filter(participant=p, clip=second.clip, section=second.section).exists()
    assert cur(p).assignment.pk == second.pk
    r = client.post(reverse("studyapp:item", args=[p.token, 2]), {**answer_for(second), "page": "2"})
    assert r.status_code == 302 and Response.objects.filter(participant=p, clip=second.clip).exists()


def test_reload_second_tab_and_new_client_resume(client, study):
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    client.post(reverse("studyapp:item", args=[p.token, 1]), answer_for(cur(p).assignment))
    # the same browser opening the study link again resumes (session)
    r = client.get(reverse("studyapp:study_entry", args=[study.slug]))
    assert r.status_code == 302 and p.token in r["Location"]
    # a second browser with the token URL (e.g. after a server restart) lands on clip 2, assignments unchanged
    before = list(p.assignments.values_list("section_id", "position", "clip_id"))
    other = Client()
    r = other.get(reverse("studyapp:resume", args=[p.token]))
    assert r["Location"].endswith("/clip/2/")
    assert list(p.assignments.values_list("section_id", "position", "clip_id")) == before


def test_answers_validated_on_server(client, study):
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    url = reverse("studyapp:item", args=[p.token, 1])
    a = cur(p).assignment
    assert a.section.section_type == "emotion_choice"
    r = client.post(url, {})
    assert r.status_code == 400 and b"Please answer" in r.content
    r = client.post(url, {"perceived": "joyful"})
    assert r.status_code == 400 and b"not an allowed answer" in r.content
    # answering a later clip out of order is refused with a message
    r = client.post(reverse("studyapp:item", args=[p.token, 3]), {"perceived": "happy"})
    assert r.status_code == 409 and b"in order" in r.content
    assert not Response.objects.filter(participant=p).exists()
    r = client.post(url, {"perceived": ["neutral", "happy", "happy"]})
    assert r.status_code == 302
    assert Response.objects.get(participant=p).answer == "happy;neutral"


def test_scale_ranges(client, study):
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    while True:
        step = cur(p)
        if step.kind != "item":
            break
        a = step.assignment
        url = reverse("studyapp:item", args=[p.token, step.index])
        data = answer_for(a)
        if a.section.section_type in ("affect_likert", "theme_inversion", "theme_rating", "naturalness"):
            key = next(iter(data))
            bad = {"affect_likert": "5", "theme_inversion": "8", "theme_rating": "0", "naturalness": "6"}
            r = client.post(url, dict(data, **{key: bad[a.section.section_type]}))
            assert r.status_code == 400, a.section.section_type
        if a.section.section_type == "theme_inversion":
            data = {"rating": "-7"}
        assert client.post(url, data).status_code == 302
    assert Response.objects.get(participant=p, section__section_type="theme_inversion").answer == "-7"


def test_gesture_options_shown_are_recorded_and_enforced(client, study):
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    a = p.assignments.filter(section__section_type="gesture_emotion").first()
    assert len(a.options) == 4 and a.clip.emotion_label in a.options and len(set(a.options)) == 4
    while cur(p).assignment.pk != a.pk:
        step = cur(p)
        client.post(reverse("studyapp:item", args=[p.token, step.index]), answer_for(step.assignment))
    step = cur(p)
    url = reverse("studyapp:item", args=[p.token, step.index])
    page = client.get(url).content.decode()
    for option in a.options:
        assert f'value="{option}"' in page
    not_shown = next(e for e in ("afraid", "amused", "proud", "sad", "relieved") if e not in a.options)
    assert client.post(url, {"perceived": not_shown}).status_code == 400


def test_clip_page_hides_clip_identity(client, study):
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    page = client.get(reverse("studyapp:item", args=[p.token, 1])).content.decode()
    a = cur(p).assignment
    assert a.clip.clip_id not in page and a.clip.video not in page
    assert f"/m/{a.clip.media_key}.mp4" in page


def test_require_full_play_checked_on_server(client, study):
    study.sections.update(require_full_play=True)
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    a = cur(p).assignment
    a.clip.duration_s = 10.0
    a.clip.save()
    url = reverse("studyapp:item", args=[p.token, 1])
    client.get(url)
    r = client.post(url, answer_for(a))
    assert r.status_code == 400 and b"watch the whole clip" in r.content
    Assignment.objects.filter(pk=a.pk).update(shown_at=timezone.now() - timedelta(seconds=11))
    assert client.post(url, answer_for(a)).status_code == 302


def test_response_time_recorded(client, study):
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    a = cur(p).assignment
    client.post(reverse("studyapp:item", args=[p.token, 1]), dict(answer_for(a), rt="4321"))
    assert Response.objects.get(participant=p).response_ms == 4321


def test_prolific_returning_participant_resumes(study):
    q = "?PROLIFIC_PID=abc123&STUDY_ID=s1&SESSION_ID=x9"
    first = Client()
    page = first.get(reverse("studyapp:study_entry", args=[study.slug]) + q)
    assert b'value="abc123"' in page.content
    p = consent(first, study, q)
    assert (p.external_id, p.external_study_id, p.external_session_id) == ("abc123", "s1", "x9")
    demographics(first, p)
    first.get(reverse("studyapp:resume", args=[p.token]))
    first.post(reverse("studyapp:item", args=[p.token, 1]), answer_for(cur(p).assignment))
    other = Client()       # another device, same Prolific PID
    r = other.get(reverse("studyapp:study_entry", args=[study.slug]) + q)
    assert r.status_code == 302 and p.token in r["Location"]
    assert other.get(r["Location"])["Location"].endswith("/clip/2/")
    # consenting again with the same PID does not create a second participant
    other.post(reverse("studyapp:study_entry", args=[study.slug]), {"consent": "on", "PROLIFIC_PID": "abc123"})
    assert Participant.objects.filter(study=study, external_id="abc123").count() == 1


def test_consent_required(client, study):
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]), {})
    assert r.status_code == 200 and b"tick the box" in r.content
    assert not Participant.objects.exists()


def test_closed_and_full_study_say_so(client, study):
    study.status = Study.Status.CLOSED
    study.save()
    r = client.get(reverse("studyapp:study_entry", args=[study.slug]))
    assert b"closed" in r.content and b"consent" not in r.content.lower().split(b"<main")[1][:2000]
    study.status = Study.Status.OPEN
    study.max_participants = 1
    study.save()
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    r = Client().get(reverse("studyapp:study_entry", args=[study.slug]))
    assert b"study is full" in r.content
    # someone who consented before it filled up is told when they try to start
    study.max_participants = 0
    study.save()
    late = consent(Client(), study)
    study.max_participants = 1
    study.save()
    late_client = Client()
    late_client.post(reverse("studyapp:demographics", args=[late.token]), {"gender": "male", "age_group": "18-24"})
    r = late_client.get(reverse("studyapp:resume", args=[late.token]))
    assert r.status_code == 200 and b"study is full" in r.content
    assert not late.assignments.exists()


def test_participant_cannot_see_another(client, study):
    p1 = consent(client, study)
    other = Client()
    p2 = consent(other, study)
    assert p1.token != p2.token and p1.seed is not None
    # a made-up token is a 404, and the entry page never leaks another participant's token
    assert Client().get(reverse("studyapp:resume", args=["x" * 43])).status_code == 404
    page = Client().get(reverse("studyapp:study_entry", args=[study.slug])).content.decode()
    assert p1.token not in page and p2.token not in page


def test_csrf_enforced(study):
    c = Client(enforce_csrf_checks=True)
    r = c.post(reverse("studyapp:study_entry", args=[study.slug]), {"consent": "on"})
    assert r.status_code == 403
    page = c.get(reverse("studyapp:study_entry", args=[study.slug])).content.decode()
    token = re.search(r'name="csrfmiddlewaretoken" value="([^"]+)"', page).group(1)
    r = c.post(reverse("studyapp:study_entry", args=[study.slug]), {"consent": "on", "csrfmiddlewaretoken": token})
    assert r.status_code == 302


def test_pages_not_cached_so_back_button_asks_the_server(client, study):
    p = consent(client, study)
    r = client.get(reverse("studyapp:demographics", args=[p.token]))
    assert "no-store" in r["Cache-Control"]


def test_started_participant_can_finish_after_study_closes(client, study):
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    Study.objects.filter(pk=study.pk).update(status=Study.Status.CLOSED)
    step = cur(p)
    assert client.post(reverse("studyapp:item", args=[p.token, 1]), answer_for(step.assignment)).status_code == 302
    assert cur(p).index == 2


def test_participant_url_not_sent_as_referrer(client, study):
    page = client.get(reverse("studyapp:study_entry", args=[study.slug])).content
    assert b'<meta name="referrer" content="same-origin">' in page


def test_abandoned_participant_frees_a_place(client, study):
    study.max_participants = 1
    study.abandon_after_minutes = 30
    study.save()
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    assert b"study is full" in Client().get(reverse("studyapp:study_entry", args=[study.slug])).content
    Participant.objects.filter(pk=p.pk).update(last_active_at=timezone.now() - timedelta(minutes=31))
    r = Client().get(reverse("studyapp:study_entry", args=[study.slug]))
    assert b"study is full" not in r.content and b"consent" in r.content
    # the inactive participant can still come back and go on
    assert client.get(reverse("studyapp:resume", args=[p.token]))["Location"].endswith("/clip/1/")


def test_automatic_completion_redirect(client, study):
    study.redirect_automatically = True
    study.save()
    p = consent(client, study)
    demographics(client, p)
    client.get(reverse("studyapp:resume", args=[p.token]))
    while (step := cur(p)).kind == "item":
        client.post(reverse("studyapp:item", args=[p.token, step.index]), answer_for(step.assignment))
    client.post(reverse("studyapp:feedback", args=[p.token]),
                {q["key"]: "no" if q["kind"] == "yesno" else "" for q in study.feedback_questions})
    page = client.get(reverse("studyapp:done", args=[p.token])).content.decode()
    assert f'http-equiv="refresh" content="5; url=https://app.prolific.com/submissions/complete?cc=' \
           f'{study.completion_code}"' in page
