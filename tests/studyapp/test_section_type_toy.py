"""A new section type is three registrations: a toy 1..3 "arousal" scale on gait walks is declared, worded and
analysed in three throw-away modules (written here, nothing else changes) and then goes through the admin, a
participant's pages, the exports, the simulator and the report. Should any other file have to change for a new type,
this test fails."""
from __future__ import annotations

import importlib
import json
import random
import sys
import textwrap

import numpy as np
import pytest
from django.test import Client
from django.urls import reverse

from analysis.design import SectionDesign, StudyDesign, design_from_presets
from analysis.io import load_study
from analysis.report import write_report
from analysis.simulate import simulate_design
from protocol import section_types
from protocol.section_types.__main__ import render_page
from protocol.vocabulary import GAIT_EMOTIONS, SECTION_TYPES
from studyapp.data.export import write_study_csvs
from studyapp.models import Participant, Response, Study
from studyapp.participant.assignment import current_step
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import admin_form_data, make_catalogue

DECLARATION = '''
"""Toy section type: how aroused a walk looks, 1 (calm) .. 3 (excited)."""
from protocol.section_types import Ask, ClipNeed, SectionType, register
from protocol.vocabulary import GAIT_EMOTIONS, register_answer_kind

AROUSAL = register_answer_kind("arousal_1_3", scale=(1, 3))
SPEC = register(SectionType(
    name="arousal", label="Arousal (1..3)", summary="A toy three-point arousal scale on walks.", modality="gait",
    questions=(Ask("arousal", AROUSAL),),
    clip_need=ClipNeed((tuple(GAIT_EMOTIONS),), "needs an intended gait emotion vector in clips.csv"),
    simulator="round(intended @ AROUSAL_MEAN + N(0, 0.5)), clipped to 1..3", agreement="icc",
    analyses=("arousal_means", "agreement"), module=__name__))
'''

WORDING = '''
"""Toy section type's participant wording."""
from django.utils.translation import gettext_noop as _

from studyapp.questions import SectionWording, register_wording

register_wording("arousal", SectionWording(
    {"arousal": (_("How aroused does this walk look?"), _("From 1 (calm) to 3 (excited)."))},
    anchors={"arousal": {"1": _("calm"), "3": _("excited")}}))
'''

ANALYSIS = '''
"""Toy section type's analysis: its simulated answers and its report table."""
import numpy as np
import pandas as pd

from analysis.answer_models import intended_vectors, register_answer_model
from analysis.recognition import dominant_intended_label
from analysis.report_tables import ReportTable, register_table
from protocol.vocabulary import GAIT_EMOTIONS

AROUSAL_MEAN = dict(zip(GAIT_EMOTIONS, (2.6, 1.2, 2.9, 1.8), strict=True))


def answers(rng, sec, shown, clips, m, effects):
    mean = intended_vectors(clips, GAIT_EMOTIONS)[shown.clip] @ np.array([AROUSAL_MEAN[e] for e in GAIT_EMOTIONS])
    return [np.clip(np.rint(mean + rng.normal(0, 0.5, len(mean))), 1, 3).astype(int)]


def arousal_means(d):
    r = d.responses[d.responses["section_type"].astype(str) == "arousal"]
    if r.empty:
        return pd.DataFrame(columns=["intended", "mean", "n"])
    intended = dominant_intended_label(d.clips.reindex(r["clip_id"].astype(str)))
    frame = pd.DataFrame({"intended": intended, "value": r["value"].to_numpy(float)}).dropna()
    out = frame.groupby("intended")["value"].agg(["mean", "size"]).reset_index()
    return out.rename(columns={"size": "n"})


register_answer_model("arousal", answers)
register_table(ReportTable(
    "arousal_means", "Arousal by dominant intended gait emotion", "Mean 1..3 rating per dominant intended emotion.",
    compute=arousal_means,
    summary=lambda t, alpha: [f"Arousal: highest for {t.loc[t['mean'].idxmax(), 'intended']} walks."]))
'''


@pytest.fixture
def toy(tmp_path, monkeypatch):
    """The three modules of the toy type, imported from a temporary package; everything registered is removed
    afterwards."""
    package = tmp_path / "toy_arousal"
    package.mkdir()
    (package / "__init__.py").write_text("")
    for name, text in (("declaration", DECLARATION), ("wording", WORDING), ("analysis", ANALYSIS)):
        (package / f"{name}.py").write_text(textwrap.dedent(text))
    monkeypatch.syspath_prepend(str(tmp_path))
    modules = [importlib.import_module(f"toy_arousal.{name}") for name in ("declaration", "wording", "analysis")]
    yield modules
    from analysis.answer_models import unregister_answer_model
    from analysis.report_tables import unregister_table
    from protocol.vocabulary import unregister_answer_kind
    from studyapp.questions import unregister_wording

    unregister_table("arousal_means")
    unregister_answer_model("arousal")
    unregister_wording("arousal")
    section_types.unregister("arousal")
    unregister_answer_kind("arousal_1_3")
    for name in [m for m in sys.modules if m.startswith("toy_arousal")]:
        del sys.modules[name]


def test_the_toy_type_is_in_the_protocol_and_its_docs(toy):
    assert "arousal" in SECTION_TYPES
    assert "## `arousal`: Arousal (1..3)" in render_page() and "arousal_means" in render_page()


def _admin_adds_the_toy_section(client: Client, study: Study) -> None:
    """Replace the study's sections by one toy section through the admin's change page."""
    url = reverse("admin:studyapp_study_change", args=[study.pk])
    page = client.get(url)
    assert b"Arousal (1..3)" in page.content                      # offered in the section type menu
    data = admin_form_data(page)
    first_new = int(data["sections-INITIAL_FORMS"])
    for i in range(first_new):
        data[f"sections-{i}-DELETE"] = "on"
    data["sections-TOTAL_FORMS"] = str(max(int(data["sections-TOTAL_FORMS"]), first_new + 1))
    new = f"sections-{first_new}-"
    data.update({new + "order": "1", new + "section_type": "arousal", new + "title": "Arousal",
                 new + "clips_per_participant": "4",
                 new + "pool": json.dumps({"modality": "gait", "plan": "test", "transition": False,
                                           f"{GAIT_EMOTIONS[0]}__isnull": False}),
                 new + "options": "{}"})
    r = client.post(url, data)
    assert r.status_code == 302, r.context["inline_admin_formsets"][0].formset.errors if r.context else r
    assert list(study.sections.values_list("section_type", flat=True)) == ["arousal"]


def _take_part(study: Study, seed: int) -> None:
    client, rng = Client(), random.Random(seed)
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]) + f"?PROLIFIC_PID=P{seed}",
                    {"consent": "on", "PROLIFIC_PID": f"P{seed}"})
    p = Participant.objects.get(token=r["Location"].rstrip("/").split("/")[-1])
    client.post(reverse("studyapp:demographics", args=[p.token]), {"gender": "female", "age_group": "25-34"})
    client.get(reverse("studyapp:resume", args=[p.token]))
    p.refresh_from_db()
    pages = 0
    while (step := current_step(p)).kind == "item":
        url = reverse("studyapp:item", args=[p.token, step.index])
        html = client.get(url).content.decode()
        assert "How aroused does this walk look?" in html and "excited" in html
        bad = client.post(url, {"arousal": ["4"]})
        assert bad.status_code == 400 and Response.objects.filter(participant=p).count() == pages   # refused
        assert client.post(url, {"arousal": [str(rng.randint(1, 3))]}).status_code == 302
        pages += 1
        p.refresh_from_db()
    assert pages == 4


@pytest.mark.django_db
def test_the_toy_type_goes_through_admin_pages_exports_and_report(toy, settings, tmp_path):
    from django.contrib.auth.models import User

    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("demo", "toy", plan="test")
    admin = Client()
    admin.force_login(User.objects.create_superuser("root", "root@example.org", "pw"))
    _admin_adds_the_toy_section(admin, study)
    study.status = Study.Status.OPEN
    study.save()
    for seed in range(3):
        _take_part(study, seed)

    paths = write_study_csvs(study, tmp_path / "export")
    data = load_study(paths["responses"], paths["clips"], paths["participants"])
    toy_rows = data.responses[data.responses["section_type"].astype(str) == "arousal"]
    assert len(toy_rows) == 12 and set(toy_rows["value"]) <= {1.0, 2.0, 3.0}
    report = write_report(paths["responses"], paths["clips"], paths["participants"], tmp_path / "report",
                          figures=False)
    vectors = data.clips.reindex(toy_rows["clip_id"].astype(str))[list(GAIT_EMOTIONS)].to_numpy(float)
    top = np.sort(vectors, axis=1)
    dominant = (top[:, -1] >= 0.5) & (top[:, -1] > top[:, -2])          # a unique largest component >= 0.5
    assert 0 < sum(row["n"] for row in report["arousal_means"]) == dominant.sum()
    assert (tmp_path / "report" / "arousal_means.csv").exists()
    assert "Arousal by dominant intended gait emotion" in (tmp_path / "report" / "report.html").read_text()


def test_the_simulator_answers_the_toy_type_and_the_report_reads_it(toy, tmp_path):
    base = design_from_presets(("demo",))
    clips = base.clips
    walks = np.flatnonzero((clips["modality"] == "gait").to_numpy() & clips[GAIT_EMOTIONS[0]].notna().to_numpy()
                           & clips["theme"].isin(["", None]).to_numpy() & clips["final_happy"].isna().to_numpy())
    design = StudyDesign("toy", ("toy",), {}, (SectionDesign(1, "toy", "arousal", walks, 0),), clips)
    sim = simulate_design(60, design, seed=4)
    assert set(sim.responses["section_type"]) == {"arousal"} and set(sim.responses["question"]) == {"arousal"}
    assert set(sim.responses["answer"]) <= {"1", "2", "3"}
    for name in ("responses", "clips", "participants"):
        getattr(sim, name).to_csv(tmp_path / f"{name}.csv", index=False)
    report = write_report(tmp_path / "responses.csv", tmp_path / "clips.csv", tmp_path / "participants.csv",
                          tmp_path / "report", figures=False)
    means = {row["intended"]: row["mean"] for row in report["arousal_means"]}
    assert means["angry"] > means["neutral"] > means["sad"] and means["happy"] > means["sad"]
    assert any(line.startswith("Arousal: highest for angry") for line in report["meta"]["summary"])
    assert any(row["section_type"] == "arousal" and row["statistic"] == "ICC2" for row in report["agreement"])
