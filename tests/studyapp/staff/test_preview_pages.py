"""Instruction and break pages in the previews (studyapp.staff.views, studyapp.staff.views_share): the staff preview
and the shared preview link show each page at its place in the section order with the participant's template,
Continue goes on to the next step, a break page says how long participants wait but lets the researcher continue at
once, and the shared preview still writes nothing to the database."""
from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.db import connection
from django.test import Client
from django.test.utils import CaptureQueriesContext
from django.urls import reverse

from protocol.section_types import is_page_type
from studyapp.models import Assignment, Participant, Response, Section, Study
from studyapp.staff.sharing import preview_token
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db

GAIT = {"modality": "gait", "origin": "generated", "transition": False}
WRITES = ("INSERT", "UPDATE", "DELETE", "REPLACE")
# the study's steps in a preview: the page's title, or "clip"
STEPS = ["Welcome", "clip", "clip", "Short break", "clip", "clip", "Almost done"]


def add_sections(study: Study, *specs) -> None:
    """Sections in the given order: (section_type, pool or page fields)."""
    for order, (stype, extra) in enumerate(specs, start=1):
        if is_page_type(stype):
            Section.objects.create(study=study, order=order, section_type=stype, pool={}, **extra)
        else:
            Section.objects.create(study=study, order=order, section_type=stype, pool=extra,
                                   clips_per_participant=2, require_full_play=False)


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    s = Study.objects.create(slug="paged-preview", title="Paged preview", status=Study.Status.DRAFT,
                             ask_demographics=False)
    add_sections(s, ("instruction_page", {"title": "Welcome", "instructions": "First you rate walks.\nThen rest."}),
                 ("emotion_choice", GAIT),
                 ("break_page", {"options": {"wait_seconds": 45}}),
                 ("affect_likert", GAIT),
                 ("instruction_page", {"title": "Almost done", "instructions": "One last thing."}))
    return s


@pytest.fixture
def staff():
    client = Client()
    client.force_login(User.objects.create_user("lead", password="pw-lead-12345", is_staff=True,
                                                is_superuser=True))
    return client


def staff_url(study: Study, n: int, seed: int = 7) -> str:
    return reverse("studyapp:preview_item", args=[study.pk, n]) + f"?seed={seed}"


def shared_url(token: str, n: int, seed: int = 7) -> str:
    return reverse("studyapp:shared_preview_item", args=[token, n]) + f"?seed={seed}"


def walk(client: Client, url) -> list[str]:
    """Take every step of a preview (url(n) is step n), continuing each page and answering each clip; the titles
    of the pages met and "clip" for each clip page, in order."""
    seen, n = [], 1
    while True:
        r = client.get(url(n))
        assert r.status_code == 200
        names = {t.name for t in r.templates}
        if "studyapp/page.html" in names:
            seen.append(r.context["title"])
            posted = client.post(url(n))
        elif "studyapp/item.html" in names:
            seen.append("clip")
            assert r.context["index"] == seen.count("clip") and r.context["total"] == STEPS.count("clip")
            posted = client.post(url(n), {f["q"].key: f["q"].choices[0][0] for f in r.context["fields"]})
        else:
            return seen
        assert posted.status_code == 302 and posted["Location"] == url(n + 1)
        n += 1


def test_the_staff_preview_shows_the_pages_in_the_section_order(staff, study):
    assert walk(staff, lambda n: staff_url(study, n)) == STEPS
    first = staff.get(staff_url(study, 1))
    html = first.content.decode()
    assert first.context["preview"] and "Preview — nothing you answer here is recorded." in html
    assert "<p>First you rate walks.<br>Then rest.</p>" in html and first.context["percent"] == 0
    last = staff.get(staff_url(study, len(STEPS)))
    assert last.context["percent"] == 100 and "One last thing." in last.content.decode()
    done = staff.get(staff_url(study, len(STEPS) + 1))
    assert done.templates[0].name == "studyapp/done.html"
    assert not Participant.objects.exists() and not Response.objects.exists() and not Assignment.objects.exists()


def test_a_break_page_in_the_preview_describes_the_wait_and_lets_the_researcher_continue(staff, study):
    r = staff.get(staff_url(study, STEPS.index("Short break") + 1))
    html = r.content.decode()
    assert r.context["is_break"] and r.context["percent"] == 50
    assert ("Preview: participants wait 45 seconds on this page before Continue is enabled (with a countdown). "
            "Here you can continue at once.") in html
    assert 'id="page-wait"' not in html               # no countdown: page.js leaves the button enabled
    assert 'id="continue">' in html and "disabled" not in html
    assert staff.post(staff_url(study, STEPS.index("Short break") + 1)).status_code == 302     # no wait enforced
    Section.objects.filter(study=study, section_type="break_page").update(options={"wait_seconds": 1})
    one = staff.get(staff_url(study, STEPS.index("Short break") + 1)).content.decode()
    assert "participants wait 1 second on this page" in one


def test_a_german_study_describes_the_break_in_german(staff, study):
    Study.objects.filter(pk=study.pk).update(language="de")
    html = staff.get(staff_url(study, STEPS.index("Short break") + 1)).content.decode()
    assert "Vorschau: Teilnehmende warten auf dieser Seite 45 Sekunden" in html and "Kurze Pause" in html


def test_the_shared_preview_shows_the_pages_and_writes_nothing(study):
    token = preview_token(study, 7)
    anyone = Client()
    with CaptureQueriesContext(connection) as queries:
        assert b"Start the preview" in anyone.get(reverse("studyapp:shared_preview", args=[token])).content
        assert walk(anyone, lambda n: shared_url(token, n)) == STEPS
        pause = anyone.get(shared_url(token, STEPS.index("Short break") + 1))
        end = anyone.get(shared_url(token, len(STEPS) + 1))
    assert "participants wait 45 seconds" in pause.content.decode()
    assert pause.context.get("clip_label") is None               # the researcher's labels stay on the staff side
    assert b"End of the preview" in end.content
    writes = [q["sql"] for q in queries.captured_queries if q["sql"].lstrip().upper().startswith(WRITES)]
    assert queries.captured_queries and not writes
    assert not Participant.objects.exists() and not Response.objects.exists() and not Assignment.objects.exists()
    assert "sessionid" not in anyone.cookies


def test_a_study_of_pages_only_is_not_previewed(staff, settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    s = Study.objects.create(slug="only-pages", title="Only pages", ask_demographics=False)
    add_sections(s, ("instruction_page", {"title": "Hello"}))
    r = staff.get(staff_url(s, 1))
    assert r.status_code == 302 and r["Location"] == reverse("admin:studyapp_study_change", args=[s.pk])
