"""The norming preset: its questions, the balanced incomplete design (participants and positions), the admin's
design table and refusal to open, the staff monitor, and one SIMULATED norming study driven through the real
participant pages (Django test client), exported, normed and checked against the simulated truth."""
from __future__ import annotations

import io
from collections import Counter

import numpy as np
import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.urls import reverse

from analysis.io import load_study, read_clips
from analysis.norms import clip_norms
from analysis.norms_simulate import expected_shares, true_perception
from protocol.norming import required_participants
from protocol.vocabulary import ATTENTION_CHECK, GESTURE_EMOTIONS
from studyapp.admin.model_admins import StudyAdmin
from studyapp.data.export import stream_csv
from studyapp.data.norming import design_rows, open_errors
from studyapp.models import Assignment, Participant, Response, Study
from studyapp.participant.assignment import current_step
from studyapp.questions import questions_for
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import admin_form_data, make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def norming(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("norming", "norming", plan="test")
    study.sections.update(require_full_play=False)
    return study


def test_norming_pages_ask_emotion_intensity_and_naturalness(norming):
    shown = list(GESTURE_EMOTIONS[:4])
    keys = {s.section_type: [q.key for q in questions_for(s.section_type, s.options, "happy", shown)]
            for s in norming.sections.all()}
    assert keys == {"emotion_choice": ["perceived", "intensity", "naturalness"],
                    "gesture_emotion": ["perceived", "intensity", "naturalness"],
                    "theme_rating": ["rating", "intensity", "naturalness"]}
    gait = questions_for("emotion_choice", norming.sections.get(section_type="emotion_choice").options)
    assert gait[0].kind == "multi" and [v for v, _ in gait[1].choices] == ["1", "2", "3", "4", "5"]
    assert gait[2].choices[0] == ("1", "not natural at all")


def test_design_table_and_refusal_to_open(norming, client):
    rows = {r.section.section_type: r for r in design_rows(norming)}
    # the synthetic test catalogue: 14 single-emotion walks, 24 gestures, 12 positive-weight theme clips
    assert [(rows[t].n_clips, rows[t].m, rows[t].k, rows[t].n_needed) for t in rows] == [
        (14, 8, 20, 35), (24, 8, 20, 60), (12, 8, 20, 30)]
    assert any("set the participant limit" in e for e in open_errors(norming))
    norming.max_participants = 59
    norming.save()
    errors = open_errors(norming)
    assert errors == ["Norming section 2 (gesture_emotion): 59 participants x 8 clips give the 24 clips at least 19 "
                      "ratings each, fewer than 20: plan at least 60 participants or show more clips each"]
    admin_user = User.objects.create_superuser("admin", "a@example.org", "pw")
    client.force_login(admin_user)
    url = reverse("admin:studyapp_study_changelist")
    r = client.post(url, {"action": "open_studies", "_selected_action": [norming.pk]}, follow=True)
    assert "Not opened: norming" in r.content.decode()
    norming.refresh_from_db()
    assert norming.status == Study.Status.DRAFT
    page = client.get(reverse("admin:studyapp_study_change", args=[norming.pk])).content.decode()
    assert "participants needed N" in page and "<td>60</td>" in page
    norming.max_participants = 60
    norming.save()
    assert open_errors(norming) == []
    client.post(url, {"action": "open_studies", "_selected_action": [norming.pk]})
    norming.refresh_from_db()
    assert norming.status == Study.Status.OPEN
    assert StudyAdmin.norming_design.short_description == "norming design"


def test_study_form_refuses_to_open_a_norming_study_short_of_participants(norming, client):
    client.force_login(User.objects.create_superuser("admin", "a@example.org", "pw"))
    url = reverse("admin:studyapp_study_change", args=[norming.pk])
    data = admin_form_data(client.get(url))
    data.update(status="open", max_participants="40")
    page = client.post(url, data)
    assert page.status_code == 200                                    # the form again, with the error
    assert "Norming section 2 (gesture_emotion): 40 participants x 8 clips give the 24 clips at least 13" in (
        page.content.decode())
    norming.refresh_from_db()
    assert norming.status == Study.Status.DRAFT and norming.max_participants == 0
    data.update(max_participants="60")
    assert client.post(url, data).status_code == 302
    norming.refresh_from_db()
    assert norming.status == Study.Status.OPEN and norming.max_participants == 60


def _start(client: Client, study: Study, query: str = "") -> Participant:
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]) + query, {"consent": "on"})
    token = r["Location"].rstrip("/").split("/")[-1]
    p = Participant.objects.get(token=token)
    client.post(reverse("studyapp:demographics", args=[p.token]), {"gender": "female", "age_group": "25-34"})
    client.get(reverse("studyapp:resume", args=[p.token]))
    return p


def test_balanced_over_participants_and_positions(norming):
    Study.objects.filter(pk=norming.pk).update(status=Study.Status.OPEN)
    gait = norming.sections.get(section_type="emotion_choice")
    norming.sections.exclude(pk=gait.pk).delete()
    gait.clips_per_participant, gait.options = 7, {"norming": {"ratings_per_clip": 4}}
    gait.save()                                              # 14 clips, M = 7: every 2 participants see all once
    for _ in range(14):
        _start(Client(), norming)
    trials = Assignment.objects.filter(section=gait, kind="")
    per_clip = Counter(trials.values_list("clip__clip_id", flat=True))
    assert len(per_clip) == 14 and set(per_clip.values()) == {7}
    for p in norming.participants.all():
        mine = list(p.assignments.filter(kind="").values_list("clip_id", flat=True))
        assert len(mine) == len(set(mine)) == 7
    positions = Counter(trials.values_list("clip__clip_id", "position"))
    first = min(p for _, p in positions)
    # M divides C: after C participants every clip has been in each of the 7 positions exactly once
    assert positions == Counter({(c, first + k): 1 for c in per_clip for k in range(7)})


@pytest.mark.django_db(transaction=True)
def test_concurrent_starts_follow_the_design(settings, tmp_path):
    """Participants starting at once (threads; PostgreSQL only, as tests/studyapp/participant/test_study_assignment.py)
    still get the design: every clip the same number of times, no clip twice for one participant."""
    import threading

    from django.db import connection

    from studyapp.participant.assignment import start_participant
    if connection.vendor != "postgresql":
        pytest.skip("concurrency test needs PostgreSQL (set DATABASE_URL)")
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("norming", "conc-norming", plan="test", status="open", max_participants=12)
    walks = study.sections.get(section_type="emotion_choice")
    study.sections.exclude(pk=walks.pk).delete()
    walks.clips_per_participant, walks.options = 7, {"norming": {"ratings_per_clip": 6}}
    walks.save()
    people = [Participant.objects.create(study=study, demographics_done=True) for _ in range(12)]
    barrier = threading.Barrier(len(people))
    errors = []

    def run(p):
        barrier.wait()
        try:
            start_participant(p)
        except Exception as exc:           # collected: the assertion below names it
            errors.append(repr(exc))
        finally:
            connection.close()

    threads = [threading.Thread(target=run, args=(p,)) for p in people]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert errors == []
    trials = Assignment.objects.filter(section=walks, kind="")
    assert set(Counter(trials.values_list("clip_id", flat=True)).values()) == {6}       # 12 x 7 / 14
    for p in people:
        mine = list(trials.filter(participant=p).values_list("clip_id", flat=True))
        assert len(mine) == len(set(mine)) == 7


def _simulated_answer(rng, a: Assignment, p_true: np.ndarray, multi: float) -> dict:
    """A SIMULATED participant's POST for a trial: the emotion drawn from the clip's simulated perception."""
    section, clip = a.section, a.clip
    qs = questions_for(section.section_type, section.options, clip.theme, a.options)
    data = {q.key: str(rng.integers(1, 6)) for q in qs[1:]}
    labels = [v for v, _ in qs[0].choices]
    if section.section_type == "gesture_emotion":
        idx = [GESTURE_EMOTIONS.index(v) for v in labels]
        w = p_true[idx] / p_true[idx].sum()
        data[qs[0].key] = labels[rng.choice(len(labels), p=w)]
    else:
        first = rng.choice(len(labels), p=p_true)
        chosen = [labels[first]]
        if rng.random() < multi:
            rest = p_true.copy()
            rest[first] = 0
            chosen.append(labels[rng.choice(len(labels), p=rest / rest.sum())])
        data[qs[0].key] = chosen
    return data


def test_simulated_norming_study_through_the_pages_recovers_the_truth(norming):
    """SIMULATED participants take the norming study page by page; the exports' norms match what they answered
    and come close to the simulated truth."""
    rng = np.random.default_rng(7)
    norming.sections.filter(section_type="theme_rating").delete()
    gait = norming.sections.get(section_type="emotion_choice")
    gesture = norming.sections.get(section_type="gesture_emotion")
    k = 12
    for s, m in ((gait, 7), (gesture, 8)):
        s.clips_per_participant = m
        s.options = {**s.options, "norming": {"ratings_per_clip": k}}
        s.save()
    n = max(required_participants(14, k, 7), required_participants(24, k, 8))     # 36
    Study.objects.filter(pk=norming.pk).update(status=Study.Status.OPEN, max_participants=n)
    norming.refresh_from_db()
    assert open_errors(norming) == []
    table = read_clips(io.StringIO("".join(stream_csv(norming, "clips")))).reset_index(drop=True)
    perception = dict(zip(table["clip_id"], true_perception(rng, table, concentration=6.0)))
    multi = 0.3
    for i in range(n):
        client = Client()
        p = _start(client, norming, f"?PROLIFIC_PID=sim{i:04d}&STUDY_ID=s&SESSION_ID=x{i}")
        while (step := current_step(Participant.objects.get(pk=p.pk))).kind == "item":
            a = step.assignment
            if a.kind == ATTENTION_CHECK:                  # a check page asks the section's questions too
                key, _, value = a.instructed.partition("=")
                data = {**{q.key: q.choices[0][0] for q in questions_for(
                    a.section.section_type, a.section.options, a.clip.theme, a.options)}, key: value}
            elif a.kind:                                   # practice
                data = {q.key: q.choices[0][0] for q in questions_for(a.section.section_type, a.section.options,
                                                                      a.clip.theme, a.options)}
            else:
                data = _simulated_answer(rng, a, perception[a.clip.clip_id], multi)
            r = client.post(reverse("studyapp:item", args=[p.token, step.index]), data)
            assert r.status_code == 302, r.content[:400]
        client.post(reverse("studyapp:feedback", args=[p.token]), {"comments": "simulated"})
    assert norming.participants.filter(status="completed").count() == n
    with_checks = [s for s in norming.sections.all() if s.options.get("attention_checks")]
    assert len(with_checks) == 2                       # walks and gestures (the theme section was deleted)
    assert Response.objects.filter(kind=ATTENTION_CHECK).count() == n * len(with_checks)
    exports = {kind: io.StringIO("".join(stream_csv(norming, kind))) for kind in ("responses", "clips", "participants")}
    data = load_study(exports["responses"], exports["clips"], exports["participants"])
    norms = clip_norms(data.responses, data.clips)
    assert len(norms) == 14 + 24 and norms["n_ratings"].min() >= k
    assert set(norms["naturalness_n"]) == set(norms["n_ratings"])
    # the norms are exactly the posted answers: recount one clip by hand
    row = norms.iloc[0]
    own = data.responses[(data.responses["clip_id"] == row["clip_id"]) & (data.responses["question"] == "perceived")]
    happy = sum(("happy" in a.split(";")) / len(a.split(";")) for a in own["answer"].astype(str))
    assert row["share_happy"] == pytest.approx(happy / len(own))
    # and they recover the SIMULATED truth (n = 12..13 ratings a clip: a standard error of about 0.1 per share)
    errors = []
    for _, r in norms.iterrows():
        kind = "gesture" if r["section_type"] == "gesture_emotion" else "gait"
        c = table.set_index("clip_id").loc[r["clip_id"]]
        j = GESTURE_EMOTIONS.index(c["emotion_label"]) if kind == "gesture" else None
        truth = expected_shares(perception[r["clip_id"]], kind, multi, 4, j)
        labels = GESTURE_EMOTIONS if kind == "gesture" else ("happy", "sad", "angry", "neutral")
        errors += [abs(r[f"share_{lab}"] - t) for lab, t in zip(labels, truth)]
    assert float(np.mean(errors)) < 0.06
    assert (norms["intended_ci_low"].dropna() <= norms["intended_ci_high"].dropna()).all()


def test_monitor_page_lists_ratings_and_clips_below_k(norming, client):
    client.force_login(User.objects.create_superuser("admin", "a@example.org", "pw"))
    Study.objects.filter(pk=norming.pk).update(status=Study.Status.OPEN, max_participants=60)
    p = _start(Client(), norming)
    first = p.assignments.filter(kind="", section__section_type="emotion_choice").first()
    Response.objects.create(participant=p, section=first.section, clip=first.clip, question="perceived",
                            answer="happy")
    page = client.get(reverse("studyapp:norming_monitor", args=[norming.pk]))
    html = page.content.decode()
    assert page.status_code == 200
    assert 'clips below K: <strong class="some">14</strong> of 14' in html
    assert "Ratings so far: <strong>1</strong>" in html
    assert first.clip.clip_id in html
    assert Client().get(reverse("studyapp:norming_monitor", args=[norming.pk])).status_code in (302, 403)
