"""Instruction and break pages between sections: shown in the section order on their own URL, a break's wait
enforced by the server, reload and double Continue safe, kept in place under counterbalancing, exported as
pages.csv, added in the admin like any section, and never met by the code of question-bearing section types."""
from __future__ import annotations

import csv
import io
import zipfile
from datetime import timedelta

import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.urls import reverse
from django.utils import timezone

import protocol.vocabulary as P
from protocol.pools import validate_section
from protocol.section_types import is_page_type, page_types, registered, section_type_names
from protocol.section_types.pages import MAX_WAIT_SECONDS
from studyapp.admin.forms import SectionForm
from studyapp.data.export import stream_csv
from studyapp.models import Participant, Response, Section, Study
from studyapp.participant.assignment import current_step, plan_study
from studyapp.participant.counterbalance import attach_pages
from studyapp.participant.duration import READING_SECONDS, expected_seconds
from studyapp.questions import section_type_choices
from studyapp.testing import admin_form_data, make_catalogue
from tests.studyapp.participant.test_study_flow import answer_for

pytestmark = pytest.mark.django_db

GAIT = {"modality": "gait", "origin": "generated", "transition": False}


def add_sections(study: Study, *specs) -> list[Section]:
    """Sections in the given order: (section_type, pool or page fields)."""
    out = []
    for order, (stype, extra) in enumerate(specs, start=1):
        if is_page_type(stype):
            out.append(Section.objects.create(study=study, order=order, section_type=stype, pool={}, **extra))
        else:
            out.append(Section.objects.create(study=study, order=order, section_type=stype, pool=extra,
                                              clips_per_participant=2, require_full_play=False))
    return out


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    s = Study.objects.create(slug="paged", title="Paged study", status=Study.Status.OPEN, ask_demographics=False)
    add_sections(s, ("emotion_choice", GAIT),
                 ("instruction_page", {"title": "Part two", "instructions": "Now rate the body.\nTake your time."}),
                 ("affect_likert", GAIT),
                 ("break_page", {"options": {"wait_seconds": 30}}),
                 ("gesture_emotion", {"modality": "gesture"}),
                 ("instruction_page", {"title": "Almost done"}))
    return s


def start(client: Client, study: Study) -> Participant:
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]), {"consent": "on"})
    assert r.status_code == 302
    p = Participant.objects.get(token=r["Location"].rstrip("/").split("/")[-1])
    assert client.get(reverse("studyapp:resume", args=[p.token])).status_code == 302
    p.refresh_from_db()
    return p


def answer(client: Client, p: Participant, n: int):
    p.refresh_from_db()
    step = current_step(p)
    assert (step.kind, step.index) == ("item", n)
    return client.post(reverse("studyapp:item", args=[p.token, n]), answer_for(step.assignment))


def page_url(p: Participant, n: int) -> str:
    return reverse("studyapp:page", args=[p.token, n])


def past_wait(p: Participant, n: int, seconds: float = 31) -> None:
    """Move page n's first display ``seconds`` into the past (as if the participant had waited)."""
    p.refresh_from_db()
    pages = p.pages
    pages[n - 1]["shown_at"] = (timezone.now() - timedelta(seconds=seconds)).isoformat()
    Participant.objects.filter(pk=p.pk).update(pages=pages)


def test_the_registry_keeps_pages_out_of_the_question_bearing_lists():
    names = [t.name for t in page_types()]
    assert names == ["instruction_page", "break_page"]
    assert not set(names) & set(P.SECTION_TYPES) and not set(names) & set(P.SECTION_QUESTIONS)
    assert not set(names) & set(section_type_names()) and not set(names) & {t.name for t in registered()}
    assert set(names) <= set(section_type_names(pages=True)) <= {name for name, _ in section_type_choices()}
    assert validate_section("break_page", {}, {"wait_seconds": 10}) == []
    problems = {e.field: e.message for e in validate_section("break_page", {"modality": "gait"},
                                                             {"wait_seconds": -1})}
    assert "leave its pool empty" in problems["pool"] and f"from 0 to {MAX_WAIT_SECONDS}" in problems["options"]
    assert "unknown option 'practice'" in validate_section("instruction_page", {}, {"practice": True})[0].message


def test_participant_sees_the_pages_in_the_section_order(client, study):
    p = start(client, study)
    assert [r["before"] for r in p.pages] == [3, 5, 7] and p.n_items == 6
    answer(client, p, 1)
    r = answer(client, p, 2)
    assert r["Location"] == page_url(p, 1)
    page = client.get(page_url(p, 1))
    html = page.content.decode()
    assert page.status_code == 200 and "<h1 class=\"page-title\">Part two</h1>" in html
    assert "<p>Now rate the body.<br>Take your time.</p>" in html and "page.js" in html and "<script>" not in html
    r = client.post(page_url(p, 1))
    assert r["Location"] == reverse("studyapp:item", args=[p.token, 3])
    answer(client, p, 3)
    assert answer(client, p, 4)["Location"] == page_url(p, 2)
    assert "Short break" in client.get(page_url(p, 2)).content.decode()
    past_wait(p, 2)
    assert client.post(page_url(p, 2))["Location"] == reverse("studyapp:item", args=[p.token, 5])
    answer(client, p, 5)
    assert answer(client, p, 6)["Location"] == page_url(p, 3)
    p.refresh_from_db()
    assert p.status == Participant.Status.STARTED and p.completed_at is None    # the last page is still to come
    assert client.get(reverse("studyapp:done", args=[p.token]))["Location"].endswith(f"/p/{p.token}/")
    client.get(page_url(p, 3))
    assert client.post(page_url(p, 3))["Location"] == reverse("studyapp:done", args=[p.token])
    p.refresh_from_db()
    assert p.status == Participant.Status.COMPLETED
    assert all(r["shown_at"] and r["continued_at"] for r in p.pages)
    assert Response.objects.filter(participant=p).values("section__section_type").distinct().count() == 3


def test_a_clip_page_before_its_page_is_continued_sends_the_participant_to_the_page(client, study):
    p = start(client, study)
    answer(client, p, 1)
    answer(client, p, 2)
    r = client.get(reverse("studyapp:item", args=[p.token, 3]))
    assert client.get(r["Location"])["Location"] == page_url(p, 1)
    assert client.get(page_url(p, 2))["Location"] == page_url(p, 1)     # a later page is not due yet
    assert client.get(reverse("studyapp:resume", args=[p.token]))["Location"] == page_url(p, 1)


def reach_break(client, study) -> Participant:
    p = start(client, study)
    for n in (1, 2):
        answer(client, p, n)
    client.post(page_url(p, 1))
    for n in (3, 4):
        answer(client, p, n)
    return p


def test_a_break_refuses_continue_before_its_wait_and_records_nothing(client, study):
    p = reach_break(client, study)
    assert client.post(page_url(p, 2)).status_code == 400           # never shown: the whole wait is ahead
    p.refresh_from_db()
    assert p.pages[1]["shown_at"] is None and p.pages[1]["continued_at"] is None
    page = client.get(page_url(p, 2))
    assert 'data-wait-left="30"' in page.content.decode()
    r = client.post(page_url(p, 2))
    assert r.status_code == 400 and "you can continue in 30 seconds" in r.content.decode()
    p.refresh_from_db()
    assert p.pages[1]["continued_at"] is None and current_step(p).kind == "page"
    past_wait(p, 2, seconds=29.5)
    assert client.post(page_url(p, 2)).status_code == 400
    past_wait(p, 2, seconds=30.5)
    assert client.post(page_url(p, 2)).status_code == 302
    p.refresh_from_db()
    assert p.pages[1]["continued_at"] and current_step(p).index == 5


def test_a_reload_shows_the_same_page_and_keeps_counting(client, study):
    p = reach_break(client, study)
    client.get(page_url(p, 2))
    p.refresh_from_db()
    first = p.pages[1]["shown_at"]
    past_wait(p, 2, seconds=12)
    p.refresh_from_db()
    shown = p.pages[1]["shown_at"]
    again = client.get(reverse("studyapp:resume", args=[p.token]))
    assert again["Location"] == page_url(p, 2)
    html = client.get(page_url(p, 2)).content.decode()
    assert 'data-wait-left="18"' in html
    p.refresh_from_db()
    assert p.pages[1]["shown_at"] == shown != first                   # the first display stays the first


def test_a_double_continue_skips_no_section(client, study):
    p = start(client, study)
    answer(client, p, 1)
    answer(client, p, 2)
    client.get(page_url(p, 1))
    first = client.post(page_url(p, 1))
    second = client.post(page_url(p, 1))
    item3 = reverse("studyapp:item", args=[p.token, 3])
    assert first["Location"] == second["Location"] == item3
    p.refresh_from_db()
    step = current_step(p)
    assert (step.kind, step.index) == ("item", 3) and p.pages[1]["shown_at"] is None
    assert not Response.objects.filter(participant=p, section__section_type="affect_likert").exists()


def test_pages_survive_a_server_restart(client, study):
    """Everything is in the database: a new client (a restarted server, another tab) resumes on the same page."""
    p = start(client, study)
    answer(client, p, 1)
    answer(client, p, 2)
    client.get(page_url(p, 1))
    other = Client()
    assert other.get(reverse("studyapp:resume", args=[p.token]))["Location"] == page_url(p, 1)
    assert other.post(page_url(p, 1))["Location"] == reverse("studyapp:item", args=[p.token, 3])


def test_attach_pages_keeps_each_page_before_the_section_that_follows_it():
    study_order = [1, 10, 2, 3, 11, 12, 4, 13]
    assert attach_pages([3, 4, 1, 2], study_order, {10, 11, 12, 13}) == [3, 11, 12, 4, 1, 10, 2, 13]
    assert attach_pages([1, 2], [1, 2], set()) == [1, 2]


def test_under_counterbalancing_a_page_travels_with_the_section_after_it(client, study):
    Study.objects.filter(pk=study.pk).update(counterbalance_sections=True)
    study.refresh_from_db()
    sections = {s.pk: s for s in study.sections.all()}
    follows = {}                        # page pk -> the question section after it in the study
    ordered = list(study.sections.order_by("order"))
    for i, s in enumerate(ordered):
        if is_page_type(s.section_type):
            follows[s.pk] = next((t.pk for t in ordered[i + 1:] if not is_page_type(t.section_type)), None)
    orders = set()
    for _ in range(3):
        p = start(Client(), study)
        order = p.section_order
        orders.add(tuple(pk for pk in order if not is_page_type(sections[pk].section_type)))
        for page, after in follows.items():
            if after is None:
                assert order[-1] == page
            else:
                assert order[order.index(page) + 1] == after
        first_seq = {}
        for a in p.assignments.order_by("seq"):
            first_seq.setdefault(a.section_id, a.seq)
        for record in p.pages:
            after = follows[record["section"]]
            assert record["before"] == (first_seq[after] if after else p.n_items + 1)
    assert len(orders) == 3                  # three different rotations of the question sections


def test_pages_csv_and_the_data_dictionary(client, study, django_user_model):
    p = reach_break(client, study)
    client.get(page_url(p, 2))
    rows = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "pages")))))
    assert [r["page"] for r in rows] == ["1", "2", "3"]
    assert [r["section_type"] for r in rows] == ["instruction_page", "break_page", "instruction_page"]
    assert [r["section_order"] for r in rows] == ["2", "4", "6"]
    assert rows[0]["participant_id"] == p.public_id and float(rows[0]["seconds"]) >= 0
    assert rows[1]["shown_at"] and not rows[1]["continued_at"] and not rows[1]["seconds"]
    assert not rows[2]["shown_at"]
    staff = User.objects.create_user("lead", password="pw-lead-12345", is_staff=True, is_superuser=True)
    c = Client()
    c.force_login(staff)
    r = c.get(reverse("studyapp:data_zip", args=[study.pk]))
    archive = zipfile.ZipFile(io.BytesIO(b"".join(r.streaming_content) if r.streaming else r.content))
    pages_file = next(n for n in archive.namelist() if n.endswith("pages.csv"))
    assert archive.read(pages_file).decode().startswith(",".join(P.PAGE_COLUMNS))
    dictionary = archive.read(next(n for n in archive.namelist() if n.endswith("data_dictionary.csv"))).decode()
    described = {row["column"] for row in csv.DictReader(io.StringIO(dictionary)) if row["file"] == "pages.csv"}
    assert described == {"", *P.PAGE_COLUMNS}
    answers = csv.DictReader(io.StringIO("".join(stream_csv(study, "responses"))))
    assert {r["section_type"] for r in answers} == {"emotion_choice", "affect_likert"}


def test_question_code_never_meets_a_page(study):
    """Planning, pools, the expected duration and the answer exports leave pages out."""
    plan = plan_study(study, seed=1, balanced=False)
    assert [s.section_type for s, _ in plan] == ["emotion_choice", "affect_likert", "gesture_emotion"]
    without = Study.objects.create(slug="plain", title="Plain", ask_demographics=False)
    add_sections(without, ("emotion_choice", GAIT), ("affect_likert", GAIT), ("gesture_emotion",
                                                                               {"modality": "gesture"}))
    assert expected_seconds(study) == pytest.approx(expected_seconds(without) + 2 * READING_SECONDS + 30 + 3)


def test_a_researcher_adds_a_break_page_in_the_admin(study):
    user = User.objects.create_user("researcher", password="pw-researcher-1", is_staff=True, is_superuser=True)
    staff = Client()
    staff.force_login(user)
    url = reverse("admin:studyapp_study_change", args=[study.pk])
    page = staff.get(url)
    html = page.content.decode()
    assert 'value="break_page"' in html and 'value="instruction_page"' in html and "only-break_page" in html
    data = admin_form_data(page)
    n = int(data["sections-TOTAL_FORMS"])
    new = {k.replace("sections-0-", f"sections-{n}-"): v for k, v in data.items() if k.startswith("sections-0-")}
    new = {k: v for k, v in new.items() if not k.endswith(("-id", "-DELETE"))}
    new.update({f"sections-{n}-order": "7", f"sections-{n}-section_type": "break_page",
                f"sections-{n}-title": "Rest", f"sections-{n}-pool": "{}", f"sections-{n}-options": "{}",
                f"sections-{n}-opt_wait_seconds": "45", f"sections-{n}-study": str(study.pk)})
    for key in [k for k in new if k.startswith(f"sections-{n}-pool_")]:
        new.pop(key)
    data.update(new)
    data["sections-TOTAL_FORMS"] = str(n + 1)
    r = staff.post(url, data)
    assert r.status_code == 302, r.context["inline_admin_formsets"][0].formset.errors if r.context else r
    added = study.sections.get(order=7)
    assert (added.section_type, added.options, added.pool, added.title) == ("break_page", {"wait_seconds": 45},
                                                                             {}, "Rest")
    data[f"sections-{n}-id"] = str(added.pk)
    data[f"sections-{n}-opt_wait_seconds"] = str(MAX_WAIT_SECONDS + 1)
    data["sections-INITIAL_FORMS"] = str(n + 1)
    r = staff.post(url, data)
    assert r.status_code == 200
    added.refresh_from_db()
    assert added.options == {"wait_seconds": 45}                      # refused, and nothing lost


def test_section_form_names_a_pool_on_a_page(study):
    form = SectionForm(data={"study": study.pk, "order": 9, "section_type": "instruction_page",
                             "clips_per_participant": 0, "pool": '{"modality": "gait"}', "options": "{}"},
                       instance=Section(study=study))
    assert not form.is_valid()
    assert "leave its pool empty" in " ".join(form.errors.get("pool", []))


def test_a_german_study_shows_its_pages_in_german(client, study):
    Study.objects.filter(pk=study.pk).update(language="de")
    p = reach_break(client, study)
    html = client.get(page_url(p, 2)).content.decode()
    assert "Kurze Pause" in html and "Sie können in 30 Sekunden weitermachen." in html and ">Weiter<" in html
    r = client.post(page_url(p, 2))
    assert r.status_code == 400 and "Bitte ruhen Sie sich noch etwas aus" in r.content.decode()


def test_a_page_neither_reuses_nor_is_reused(study):
    from django.core.exceptions import ValidationError

    page = study.sections.get(order=2)
    later = study.sections.get(order=3)
    later.reuse_section = page
    with pytest.raises(ValidationError, match="neither reuse"):
        later.full_clean()
    page.reuse_section = study.sections.get(order=1)
    with pytest.raises(ValidationError, match="neither reuse"):
        page.full_clean()


def test_a_page_first_and_a_page_before_the_feedback(client, settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    s = Study.objects.create(slug="framed", title="Framed", status=Study.Status.OPEN, ask_demographics=True,
                             feedback_questions=[{"key": "comments", "text": "Anything else?", "kind": "text"}])
    add_sections(s, ("instruction_page", {"title": "Welcome"}), ("emotion_choice", GAIT),
                 ("instruction_page", {"title": "Nearly there"}))
    r = client.post(reverse("studyapp:study_entry", args=[s.slug]), {"consent": "on"})
    p = Participant.objects.get(token=r["Location"].rstrip("/").split("/")[-1])
    assert client.get(reverse("studyapp:resume", args=[p.token]))["Location"].endswith("/about-you/")
    client.post(reverse("studyapp:demographics", args=[p.token]), {"gender": "female", "age_group": "25-34"})
    assert client.get(reverse("studyapp:resume", args=[p.token]))["Location"] == page_url(p, 1)
    assert "Welcome" in client.get(page_url(p, 1)).content.decode()
    assert client.post(page_url(p, 1))["Location"] == reverse("studyapp:item", args=[p.token, 1])
    answer(client, p, 1)
    assert answer(client, p, 2)["Location"] == page_url(p, 2)
    assert client.get(reverse("studyapp:feedback", args=[p.token]))["Location"].endswith(f"/p/{p.token}/")
    assert client.post(page_url(p, 2))["Location"] == reverse("studyapp:feedback", args=[p.token])
