"""Study extras in the study app: attention checks, practice trials, counterbalanced section order, honest duration."""
from __future__ import annotations

import csv
import io
import math
import re
from collections import Counter

import pytest
from django.test import Client
from django.urls import reverse

from protocol.vocabulary import ATTENTION_CHECK, ATTENTION_COLUMNS, PARTICIPANT_COLUMNS, SECTION_QUESTIONS
from studyapp.data.catalogue import pool_queryset
from studyapp.data.export import stream_csv
from studyapp.models import Assignment, Clip, Participant, Response, Study
from studyapp.participant.assignment import current_step, start_participant
from studyapp.participant.counterbalance import williams_rows
from studyapp.participant.duration import (
    ANSWER_SECONDS_PER_QUESTION,
    DEMOGRAPHICS_SECONDS,
    FEEDBACK_SECONDS_PER_QUESTION,
    PAGE_SECONDS,
    expected_minutes,
)
from studyapp.participant.views import item_questions
from studyapp.questions import questions_for
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    s = create_study_from_preset("gait_ismar2020", "g", plan="test", status=Study.Status.OPEN)
    s.sections.update(require_full_play=False)
    return s


def csv_rows(study: Study, kind: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO("".join(stream_csv(study, kind)))))


def started(study: Study, client: Client | None = None) -> tuple[Client, Participant]:
    client = client or Client()
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]), {"consent": "on"})
    p = Participant.objects.get(token=r["Location"].rstrip("/").split("/")[-1])
    client.post(reverse("studyapp:demographics", args=[p.token]), {"gender": "female", "age_group": "25-34"})
    client.get(reverse("studyapp:resume", args=[p.token]))
    p.refresh_from_db()
    return client, p


def answer(client: Client, p: Participant, chooser=None) -> list:
    """Answer every clip page of p (first choice, or chooser(assignment, question)); returns the assignments."""
    done = []
    while (step := current_step(p)).kind == "item":
        a = step.assignment
        qs = item_questions(a.section, a.clip, a.options, a.kind, a.instructed)
        data = {q.key: (chooser(a, q) if chooser else None) or q.choices[0][0] for q in qs}
        r = client.post(reverse("studyapp:item", args=[p.token, step.index]), data)
        assert r.status_code == 302, r.content[:300]
        done.append(a)
        p.refresh_from_db()
    return done


def first_section(study: Study):
    return study.sections.get(order=1)


def tag_outline(page: str) -> list[str]:
    """The page's tags with their class and type attributes, in order (what a script could tell pages apart by
    without reading their text)."""
    body = page[page.index("<main"):page.index("</main>")]
    return re.findall(r'<(\w+)(?:[^>]*?\s(?:class|type)="([^"]*)")?', body)


def test_attention_check_at_fixed_position_shown_exported_and_counted(study):
    section = first_section(study)
    section.options = {"attention_checks": {"count": 1, "answer": "sad", "positions": [3]}}
    section.clips_per_participant = 6           # the pool holds 8: two spare clips for checks
    section.full_clean()
    section.save()
    client, p = started(study)
    items = list(p.assignments.filter(section=section).order_by("position"))
    assert len(items) == section.clips_per_participant + 1
    check = items[2]
    assert [a.kind for a in items].count(ATTENTION_CHECK) == 1 and check.kind == ATTENTION_CHECK
    assert check.instructed == "perceived=sad"
    assert check.clip_id in set(pool_queryset(section.pool).values_list("pk", flat=True))
    assert not p.assignments.filter(kind="", clip_id=check.clip_id).exists()      # rated nowhere in the study
    # the page looks like every clip page of the section: the same question, the instruction in the note line
    normal = ""
    while current_step(p).assignment.pk != check.pk:
        a = current_step(p).assignment
        normal = client.get(reverse("studyapp:item", args=[p.token, a.seq])).content.decode()
        client.post(reverse("studyapp:item", args=[p.token, a.seq]), {"perceived": "happy"})
        p.refresh_from_db()
    page = client.get(reverse("studyapp:item", args=[p.token, check.seq])).content.decode()
    assert "Attention check" not in page and "attention" not in page.lower()
    note = re.search(r'<p class="page-note" id="page-note">(.*?)</p>', page).group(1)
    assert "“Which emotion(s) do you perceive from this walk?” with Sad only" in note.replace("&#x27;", "'")
    assert page.index("page-note") < page.index("<fieldset") and page.count("<fieldset") == 1
    assert tag_outline(page) == tag_outline(normal)
    client.post(reverse("studyapp:item", args=[p.token, check.seq]), {"perceived": "sad"})
    p.refresh_from_db()
    answer(client, p)
    rows = [r for r in csv_rows(study, "responses") if r["section_type"] == ATTENTION_CHECK]
    assert len(rows) == 1 and rows[0]["question"] == "perceived=sad" and rows[0]["answer"] == "sad"
    assert rows[0]["clip_id"] == Clip.objects.get(pk=check.clip_id).clip_id
    people = csv_rows(study, "participants")
    assert list(people[0])[:len(PARTICIPANT_COLUMNS)] == list(PARTICIPANT_COLUMNS)
    assert (people[0][ATTENTION_COLUMNS[0]], people[0][ATTENTION_COLUMNS[1]]) == ("1", "1")
    audit = [r for r in csv_rows(study, "assignments") if r["section_type"] == ATTENTION_CHECK]
    assert len(audit) == 1


def test_failed_attention_check_counts_and_random_positions_never_first(study):
    section = first_section(study)
    section.options = {"attention_checks": {"count": 2, "answer": "angry", "positions": "random"}}
    section.clips_per_participant = 6
    section.save()
    places = Counter()
    for _ in range(6):
        client, p = started(study)
        kinds = list(p.assignments.filter(section=section).order_by("position").values_list("kind", flat=True))
        assert kinds.count(ATTENTION_CHECK) == 2 and kinds[0] == ""
        places.update(i for i, k in enumerate(kinds) if k == ATTENTION_CHECK)
        answer(client, p, lambda a, q: ("angry" if a.seq % 2 else "happy") if a.kind else None)
    assert len(places) > 2                       # drawn per participant, not one fixed place
    people = csv_rows(study, "participants")
    assert all(r[ATTENTION_COLUMNS[1]] == "2" for r in people)
    assert {r[ATTENTION_COLUMNS[0]] for r in people} <= {"0", "1", "2"}
    checks = Response.objects.filter(kind=ATTENTION_CHECK)
    assert checks.count() == 12
    passed = sum(r.answer == "angry" for r in checks)
    assert sum(int(r[ATTENTION_COLUMNS[0]]) for r in people) == passed


def test_gesture_attention_check_offers_the_instructed_answer(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("demo", "d", plan="test", status="open")
    section = study.sections.get(section_type="gesture_emotion")
    section.options = {"attention_checks": {"answer": "proud", "positions": [1]}}
    section.save()
    p = Participant.objects.create(study=study, demographics_done=True)
    start_participant(p)
    check = p.assignments.get(section=section, kind=ATTENTION_CHECK)
    assert check.position == 0 and "proud" in check.options and len(check.options) == 4
    assert [q.key for q in item_questions(section, check.clip, check.options, check.kind, check.instructed)] == \
        ["perceived"]


def test_practice_item_first_outside_the_pool_and_never_exported(study):
    section = first_section(study)
    section.options = {"practice": True}
    section.save()
    client, p = started(study)
    practice = p.assignments.get(section=section, position=0)
    assert practice.kind == Assignment.Kind.PRACTICE and practice.seq == 1
    assert practice.clip_id not in set(pool_queryset(section.pool).values_list("pk", flat=True))
    assert Clip.objects.get(pk=practice.clip_id).modality == "gait"
    page = client.get(reverse("studyapp:item", args=[p.token, 1])).content.decode()
    assert "Practice" in page and "not recorded" in page
    answered = answer(client, p)
    assert answered[0].pk == practice.pk
    clip_id = Clip.objects.get(pk=practice.clip_id).clip_id
    responses = csv_rows(study, "responses")
    assert responses and not [r for r in responses if r["clip_id"] == clip_id and r["section_type"] ==
                              section.section_type]
    assert not Response.objects.filter(participant=p, section=section, clip_id=practice.clip_id).exists()
    assert len([r for r in csv_rows(study, "assignments") if r["section_type"] == section.section_type]) == \
        section.clips_per_participant
    expected = sum(len(item_questions(a.section, a.clip, a.options, a.kind, a.instructed))
                   for a in answered if a.kind != Assignment.Kind.PRACTICE)
    assert Response.objects.filter(participant=p).count() == expected


def test_practice_clip_option_uses_that_clip(study):
    section = first_section(study)
    section.options = {"practice_clip": "gait_src_02"}
    section.full_clean()
    section.save()
    p = Participant.objects.create(study=study, demographics_done=True)
    start_participant(p)
    assert p.assignments.get(kind=Assignment.Kind.PRACTICE).clip.clip_id == "gait_src_02"
    section.options = {"practice_clip": "no_such_clip"}
    with pytest.raises(Exception, match="practice_clip"):
        section.full_clean()


def test_latin_square_rows_balanced_recorded_and_exported(study):
    """gait_ismar2020: sections 1..4, section 3 reuses section 1 (moves with it), section 4 pinned last."""
    Study.objects.filter(pk=study.pk).update(counterbalance_sections=True)
    study.refresh_from_db()
    study.sections.filter(order=4).update(counterbalance=False)
    s = {x.order: x.pk for x in study.sections.all()}
    orders = []
    for _ in range(4):
        p = Participant.objects.create(study=study, demographics_done=True)
        start_participant(p)
        orders.append(p.section_order)
        seq_sections = list(p.assignments.order_by("seq").values_list("section_id", flat=True))
        assert list(dict.fromkeys(seq_sections)) == p.section_order      # shown in the recorded order
    # two rotating units, {1, 3} (3 reuses 1's clips, so it moves with 1) and {2}: Williams rows [0, 1], [1, 0]
    assert orders[0] == [s[1], s[3], s[2], s[4]] and orders[1] == [s[2], s[1], s[3], s[4]]
    assert orders[2] == orders[0] and orders[3] == orders[1]
    for order in orders:
        assert order.index(s[3]) > order.index(s[1]) and order[-1] == s[4]
    exported = [r["section_order"] for r in csv_rows(study, "participants")]
    assert exported == ["1;3;2;4", "2;1;3;4", "1;3;2;4", "2;1;3;4"]


def test_williams_square_properties():
    for n in (2, 3, 4, 5, 6):
        rows = williams_rows(n)
        assert len(rows) == (n if n % 2 == 0 else 2 * n)
        per_place = Counter((r[i], i) for r in rows for i in range(n))
        assert set(per_place.values()) == {len(rows) // n} and len(per_place) == n * n
        pairs = Counter((r[i], r[i + 1]) for r in rows for i in range(n - 1))
        assert len(pairs) == n * (n - 1) and len(set(pairs.values())) == 1


def test_study_order_kept_without_counterbalancing(study):
    p = Participant.objects.create(study=study, demographics_done=True)
    start_participant(p)
    assert p.section_order == list(study.sections.order_by("order").values_list("pk", flat=True))


def test_duration_from_pool_durations(study):
    for i, clip in enumerate(Clip.objects.all()):
        clip.duration_s = 4.0 + (i % 3) * 2     # 4, 6, 8 s
        clip.save()
    section = first_section(study)
    section.options = {"attention_checks": {"answer": "sad"}, "practice": True}
    section.save()
    seconds = 0.0
    for sec in study.sections.order_by("order"):
        source = sec.reuse_section or sec
        pool = list(pool_queryset(source.pool))
        mean = sum(c.duration_s for c in pool) / len(pool)
        n = min(source.clips_per_participant, len(pool)) if source.clips_per_participant else len(pool)
        questions = len(SECTION_QUESTIONS[sec.section_type])
        seconds += n * (mean + PAGE_SECONDS + questions * ANSWER_SECONDS_PER_QUESTION)
        if sec.pk == section.pk:
            seconds += (mean + PAGE_SECONDS + questions * ANSWER_SECONDS_PER_QUESTION)     # practice
            seconds += mean + PAGE_SECONDS + questions * ANSWER_SECONDS_PER_QUESTION       # one check
    seconds += DEMOGRAPHICS_SECONDS + FEEDBACK_SECONDS_PER_QUESTION * len(study.feedback_questions)
    assert expected_minutes(study) == math.ceil(seconds / 60)
    page = Client().get(reverse("studyapp:study_entry", args=[study.slug])).content.decode()
    assert f"The study takes about {math.ceil(seconds / 60)} minutes" in page
    # longer clips, longer study
    Clip.objects.update(duration_s=30.0)
    Clip.objects.first().save()         # a new catalogue version (update() does not touch updated_at)
    assert expected_minutes(study) > math.ceil(seconds / 60)


def test_question_list_of_attention_item_matches_questions_for(study):
    section = first_section(study)
    qs = questions_for(section.section_type, section.options)
    assert [q.key for q in qs] == list(SECTION_QUESTIONS[section.section_type])


def test_checks_in_a_reusing_likert_section_and_gesture_practice(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("demo", "d2", plan="test", status="open")
    likert = study.sections.get(section_type="affect_likert")
    assert likert.reuse_section_id
    likert.options = {"attention_checks": {"answer": "2", "question": "pace", "positions": "random"}}
    likert.full_clean()
    likert.save()
    gesture = study.sections.get(section_type="gesture_emotion")
    gesture.options = {"practice": True}
    gesture.save()
    p = Participant.objects.create(study=study, demographics_done=True)
    start_participant(p)
    check = p.assignments.get(section=likert, kind=ATTENTION_CHECK)
    rated = set(p.assignments.filter(kind="").values_list("clip_id", flat=True))
    assert check.clip_id not in rated and check.instructed == "pace=2" and check.position > 0
    assert check.clip_id in set(pool_queryset(likert.reuse_section.pool).values_list("pk", flat=True))
    # the check page asks the section's four questions, like its other pages; only the instructed one is stored
    assert [q.key for q in item_questions(likert, check.clip, check.options, check.kind, check.instructed)] == \
        list(SECTION_QUESTIONS["affect_likert"])
    practice = p.assignments.get(section=gesture, kind=Assignment.Kind.PRACTICE)
    assert practice.position == 0 and practice.clip.modality == "gesture"
    assert practice.clip_id not in set(pool_queryset(gesture.pool).values_list("pk", flat=True))
    assert practice.clip.emotion_label in practice.options and len(practice.options) == 4


@pytest.fixture
def staff_client(django_user_model):
    user = django_user_model.objects.create_user("researcher", password="pw-researcher-1", is_staff=True,
                                                 is_superuser=True)
    c = Client()
    c.force_login(user)
    return c


def test_preview_shows_practice_and_attention_check_and_records_nothing(study, staff_client):
    section = first_section(study)
    section.options = {"practice": True, "attention_checks": {"count": 1, "answer": "sad", "positions": [2]}}
    section.save()
    url = lambda n: reverse("studyapp:preview_item", args=[study.pk, n]) + "?seed=7"   # noqa: E731
    first = staff_client.get(url(1)).content.decode()
    assert "Practice" in first and "(practice, never stored)" in first
    check = staff_client.get(url(3)).content.decode()
    assert "(attention check, instructed perceived=sad)" in check      # the researcher's banner
    assert "with Sad only" in check                                    # the participant's instruction, shown
    assert staff_client.post(url(3), {}).status_code == 400           # validated like a participant's page
    r = staff_client.post(url(3), {"perceived": "sad"})
    assert r.status_code == 302 and r["Location"] == url(4)
    n_trials = section.clips_per_participant + 2
    assert staff_client.get(url(n_trials)).status_code == 200
    assert not Participant.objects.filter(study=study).exists()
    assert not Response.objects.exists() and not Assignment.objects.exists()


def test_admin_participant_page_lists_seq_kind_and_instructed_answer(study, staff_client):
    section = first_section(study)
    section.options = {"attention_checks": {"count": 1, "answer": "sad", "positions": [2]}}
    section.clips_per_participant = 6
    section.save()
    _, p = started(study)
    page = staff_client.get(reverse("admin:studyapp_participant_change", args=[p.pk])).content.decode()
    assert "Seq" in page and "Attention check" in page and "perceived=sad" in page
    assert 'name="assignments-0-seq"' not in page      # read-only


def test_presets_do_not_hard_code_a_duration():
    """The consent page computes the duration (studyapp.participant.duration); preset texts must not state another."""
    import re

    from studyapp.staff.presets import PRESETS

    for key, preset in PRESETS.items():
        texts = [preset.get("introduction", ""), preset.get("consent_text", "")]
        texts += [s.get("instructions", "") for s in preset["sections"]]
        for text in texts:
            assert not re.search(r"\b(minutes?|hours?)\b", text, re.I), (key, text)
