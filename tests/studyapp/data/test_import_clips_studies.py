"""Imported clips in studies: a norming study of imported walks taken by SIMULATED participants through the real
participant pages (Django test client), normed per clip, and a study's exports listing imported clips with their
origin, licence and citation beside generated ones.

The videos are tiny synthetic test patterns made with the bundled ffmpeg
(tests/studyapp/data/test_import_clips.make_video).
"""
from __future__ import annotations

import csv
import io
from datetime import timedelta

import pytest
from django.test import Client
from django.urls import reverse
from django.utils import timezone

from analysis.io import load_study
from protocol.vocabulary import ATTENTION_CHECK
from studyapp.data import norms_rule
from studyapp.models import Assignment, Clip, Participant, Response, Section, Study
from studyapp.participant.assignment import current_step
from studyapp.questions import questions_for
from studyapp.testing import section_form_errors
from tests.studyapp.data.test_import_clips import make_video, media, read_report, run, write_manifest  # noqa: F401 - fixture

pytestmark = pytest.mark.django_db

#: Two walks a lab recorded: one meant as happy, one as sad (the manifest's intended labels).
WALKS = [
    {"path": "walks/happy_walk.mp4", "modality": "gait", "origin": "imported", "happy": "1", "sad": "0",
     "angry": "0", "neutral": "0", "title": "happy walk", "licence": "CC BY 4.0", "citation": "Lab A, walks 2026"},
    {"path": "walks/sad_walk.mp4", "modality": "gait", "origin": "imported", "happy": "0", "sad": "1",
     "angry": "0", "neutral": "0", "title": "sad walk", "licence": "CC0", "citation": "Lab A, walks 2026"},
]
#: The collection of an import: ``import:<manifest's folder>/<manifest's stem>``.
PLAN = "import:lab/manifest"
#: Seconds a SIMULATED participant watches a clip before answering (the walks last 1 s).
WATCH_S = 2.0


def import_walks(tmp_path) -> dict[str, Clip]:
    """Import the two WALKS (from ``tmp_path/lab``); their clips by intended emotion."""
    folder = tmp_path / "lab"
    make_video(folder / WALKS[0]["path"], pattern="testsrc2")
    make_video(folder / WALKS[1]["path"], pattern="smptebars")
    run(write_manifest(folder, WALKS))
    report = read_report(folder / "import_report.csv")
    assert [r["status"] for r in report] == ["ok", "ok"], report
    clips = {c.clip_id: c for c in Clip.objects.filter(origin="imported")}
    assert set(clips) == {r["clip_id"] for r in report} and {c.plan for c in clips.values()} == {PLAN}
    return {"happy": clips[report[0]["clip_id"]], "sad": clips[report[1]["clip_id"]]}


def start(client: Client, study: Study, external_id: str) -> Participant:
    """A SIMULATED participant consents, answers the demographics and reaches the first item."""
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]) + f"?PROLIFIC_PID={external_id}",
                    {"consent": "on"})
    assert r.status_code == 302, r.content[:400]
    p = Participant.objects.get(token=r["Location"].rstrip("/").split("/")[-1])
    client.post(reverse("studyapp:demographics", args=[p.token]), {"gender": "female", "age_group": "25-34"})
    client.get(reverse("studyapp:resume", args=[p.token]))
    return p


def take_study(study: Study, external_id: str, answer) -> Participant:
    """One SIMULATED participant takes ``study`` page by page, WATCH_S seconds a clip: ``answer(assignment,
    questions)`` gives the POST of a rated trial; practice items get the first choice of each question, attention
    checks the instructed answer."""
    client = Client()
    p = start(client, study, external_id)
    while (step := current_step(Participant.objects.get(pk=p.pk))).kind == "item":
        a = step.assignment
        qs = questions_for(a.section.section_type, a.section.options, a.clip.theme, a.options)
        if a.kind == ATTENTION_CHECK:                              # the section's questions, one instructed
            key, _, value = a.instructed.partition("=")
            data = {**{q.key: q.choices[0][0] for q in qs}, key: value}
        elif a.kind:                                                       # practice
            data = {q.key: q.choices[0][0] for q in qs}
        else:
            data = answer(a, qs)
        # SIMULATED viewing: the clip was shown WATCH_S ago (the test client answers at once, which the analysis
        # would exclude as too fast)
        Assignment.objects.filter(pk=a.pk).update(shown_at=timezone.now() - timedelta(seconds=WATCH_S))
        r = client.post(reverse("studyapp:item", args=[p.token, step.index]), data)
        assert r.status_code == 302, r.content[:400]
    client.post(reverse("studyapp:feedback", args=[p.token]), {"comments": "simulated"})
    p.refresh_from_db()
    assert p.status == Participant.Status.COMPLETED
    return p


def test_imported_walks_in_a_norming_study_get_norms(media, tmp_path):  # noqa: F811
    """A norming study (the preset) of two imported walks: every SIMULATED participant rates both; the per-clip
    norms, as the pool rule ``norms`` reads them from the study (exports, exclusion rules, analysis.norms), count
    each participant's rating of each clip, and a pool's norms rule admits the walks by them."""
    from studyapp.data.catalogue import pool_queryset
    from studyapp.data.norming import open_errors
    from studyapp.staff.presets import create_study_from_preset

    walks = import_walks(tmp_path)
    study = create_study_from_preset("norming", "norming-imported", plan=PLAN)
    study.sections.exclude(section_type="emotion_choice").delete()        # imported walks only: no gesture clips
    section = study.sections.get()
    assert section.pool["plan"] == PLAN and section.pool["modality"] == "gait"
    n_people, ratings = 3, 3
    section.clips_per_participant, section.require_full_play = 2, False
    section.options = {**section.options, "norming": {"ratings_per_clip": ratings}}
    # both walks are rated by everyone and the catalogue has no other walk: the preset's attention check would
    # have no clip that participants do not rate, so the admin refuses it; this study goes without
    assert "attention_checks" in " ".join(section_form_errors(section).get("options", []))
    del section.options["attention_checks"]
    section.full_clean()
    section.save()
    Study.objects.filter(pk=study.pk).update(status=Study.Status.OPEN, max_participants=n_people)
    study.refresh_from_db()
    assert open_errors(study) == []

    def answer(a, qs):
        """SIMULATED: the intended emotion, except that sim0000 sees every walk as neutral; intensity 4,
        naturalness 3."""
        intended = "happy" if a.clip_id == walks["happy"].pk else "sad"
        return {qs[0].key: ["neutral" if a.participant.external_id == "sim0000" else intended],
                qs[1].key: "4", qs[2].key: "3"}

    for i in range(n_people):
        take_study(study, f"sim{i:04d}", answer)
    assert not Response.objects.filter(section=section, kind=ATTENTION_CHECK).exists()
    rated = Response.objects.filter(section=section, kind="", question="perceived")
    assert sorted(rated.values_list("clip__clip_id", flat=True)) == sorted([c.clip_id for c in walks.values()] * 3)

    norms_rule.clear()
    norms = norms_rule.load_norms(study.slug)          # the norms the pool rule reads: exports, exclusions, norms
    assert set(norms) == {c.clip_id for c in walks.values()}
    for emotion, clip in walks.items():
        row = norms[clip.clip_id]
        assert (row["section_type"], row["question"], row["n_ratings"]) == ("emotion_choice", "perceived", 3)
        assert row["intended"] == emotion and row["intended_share"] == pytest.approx(2 / 3)
        assert row[f"share_{emotion}"] == pytest.approx(2 / 3) and row["share_neutral"] == pytest.approx(1 / 3)
        assert (row["intensity_mean"], row["naturalness_mean"], row["naturalness_n"]) == (4, 3, 3)
    # a later study's pool admits the imported walks by these norms
    rule = {"from": study.slug, "min_ratings": 3, "min_intended_share": 0.6}
    admitted = pool_queryset({"origin": "imported", "norms": rule}).values_list("clip_id", flat=True)
    assert set(admitted) == {c.clip_id for c in walks.values()}
    assert not pool_queryset({"origin": "imported", "norms": {**rule, "min_intended_share": 0.7}}).exists()
    norms_rule.clear()


def test_a_study_export_lists_imported_clips_with_origin_licence_and_citation(media, tmp_path):  # noqa: F811
    """Imported walks beside generated ones in one naturalness section: the staff export's clips.csv lists both
    with their origin, the imported ones with the manifest's licence and citation; the answers of a SIMULATED
    participant name the imported clips, and the analysis reads them back with origin ``imported``."""
    from django.contrib.auth.models import User

    from analysis.naturalness import naturalness
    from studyapp.data.catalogue import pool_queryset
    from studyapp.testing import make_catalogue

    make_catalogue(media, n_gait=2, n_transition=0, n_gait_source=0, n_gesture=0)
    generated = set(pool_queryset({"modality": "gait", "origin": "generated", "rbf": False})
                    .values_list("clip_id", flat=True))
    walks = import_walks(tmp_path)
    study = Study.objects.create(slug="own-and-generated", title="Own and generated walks",
                                 status=Study.Status.OPEN, ask_demographics=True)
    Section.objects.create(study=study, order=1, section_type="naturalness", clips_per_participant=0,
                           require_full_play=False,
                           pool={"modality": "gait", "origin": ["generated", "imported"], "rbf": False})
    take_study(study, "sim0000", lambda a, qs: {q.key: "4" for q in qs})

    staff = Client()
    staff.force_login(User.objects.create_superuser("exporter", "e@example.org", "pw"))
    exports = {}
    for kind in ("responses", "clips", "participants"):
        r = staff.get(reverse("studyapp:export_csv", args=[study.pk, kind]))
        assert r.status_code == 200
        exports[kind] = b"".join(r.streaming_content).decode()
    clips = {row["clip_id"]: row for row in csv.DictReader(io.StringIO(exports["clips"]))}
    imported = {c.clip_id: c for c in walks.values()}
    assert len(generated) >= 2 and set(clips) == generated | set(imported)
    for clip_id, clip in imported.items():
        assert (clips[clip_id]["origin"], clips[clip_id]["licence"], clips[clip_id]["citation"]) == (
            "imported", clip.licence, clip.citation)
    assert {clips[c]["licence"] for c in imported} == {"CC BY 4.0", "CC0"}
    assert {clips[c]["citation"] for c in imported} == {"Lab A, walks 2026"}
    assert {clips[c]["origin"] for c in generated} == {"generated"}
    assert float(clips[walks["happy"].clip_id]["happy"]) == 1.0
    answered = {row["clip_id"] for row in csv.DictReader(io.StringIO(exports["responses"]))}
    assert answered == generated | set(imported)

    data = load_study(*(io.StringIO(exports[k]) for k in ("responses", "clips", "participants")))
    assert set(data.clips.loc[list(imported), "origin"]) == {"imported"}
    table = naturalness(data.responses, data.clips).set_index("origin")
    assert table.loc["imported", "n"] == 2 and table.loc["generated", "n"] == len(generated)
