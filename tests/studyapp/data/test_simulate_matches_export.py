"""A simulated study has the structure of a real export of the same preset: the study is built in Django from the
preset with a catalogue made from the plan's entries, participants take it through the pages, it is exported, and
per section type the simulated export agrees on clips per participant, questions, answer options and the clip columns
present. Also: run_report applies and states the study's exclusion rules."""
from __future__ import annotations

import io

import pandas as pd
import pytest

from analysis.design import design_from_presets
from analysis.io import read_clips, read_participants, read_responses
from analysis.simulate import simulate_design
from protocol.vocabulary import CLIP_COLUMNS, GESTURE_EMOTIONS, MULTI_SELECT_KINDS, SECTION_QUESTIONS, answer_values
from studyapp.data.catalogue import upsert_clips
from studyapp.data.export import run_report, write_study_csvs
from studyapp.models import Study
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import write_media
from tests.studyapp.data.test_protocol_roundtrip import take_part

pytestmark = pytest.mark.django_db


def catalogue_from_design(design, media_root) -> int:
    """The plan's entries as catalogued clips (placeholder videos, marked synthetic), ids as the simulator's."""
    records = []
    for row in design.clips.to_dict("records"):
        rec = {c: (None if isinstance(v, float) and pd.isna(v) else v) for c, v in row.items() if c in CLIP_COLUMNS}
        rec.update(video=write_media(media_root, f"placeholder {row['clip_id']}".encode()), webm="", poster="",
                   plan=row["plan"], loop=False, source_clip_id=row["source_clip_id"], sections=row["sections"],
                   metadata={"synthetic": True, "entry_id": row["entry_id"], "note": "test placeholder"})
        records.append(rec)
    return upsert_clips(records)


def _answer_at_once(study) -> None:
    """The test clips have real durations (the plan's) but the test client answers at once: do not require the
    clip to have played."""
    if any(f.name == "require_full_play" for f in study.sections.model._meta.get_fields()):
        study.sections.update(require_full_play=False)


def structure(responses: pd.DataFrame, clips: pd.DataFrame, assignments: pd.DataFrame) -> dict:
    """Per section type: clips per participant (set over participants), questions, whether every answer lies in its
    question's options, gesture option counts, and the clip columns with a value among the clips shown."""
    out = {}
    shown_clips = clips.reset_index(drop=True).set_index("clip_id", drop=False)
    for stype, r in responses.groupby("section_type", observed=True):
        stype = str(stype)
        ids = r["clip_id"].astype(str)
        kinds = SECTION_QUESTIONS[stype]
        in_options = all(set(str(a).split(";") if kinds[str(q)] in MULTI_SELECT_KINDS else [str(a)])
                         <= set(answer_values(kinds[str(q)])) for q, a in zip(r["question"], r["answer"]))
        cols = shown_clips.loc[sorted(set(ids)), list(CLIP_COLUMNS)]
        present = {c for c in CLIP_COLUMNS if (cols[c].notna() & cols[c].astype(str).str.strip().ne("")).any()}
        a = assignments[assignments["section_type"] == stype]
        n_options = set(a["options"].fillna("").astype(str).str.split(";").str.len()) if stype == "gesture_emotion" \
            else set()
        out[stype] = {"clips_per_participant": set(r.assign(c=ids).groupby("participant_id", observed=True)["c"]
                                                   .nunique()),
                      "questions": set(r["question"].astype(str)), "answers_in_options": in_options,
                      "n_options": n_options, "clip_columns": present}
    return out


def test_simulated_demo_study_has_the_structure_of_a_real_export(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    design = design_from_presets(("demo",))
    catalogue_from_design(design, settings.MEDIA_ROOT)
    study = create_study_from_preset("demo", "demo-sim", status=Study.Status.OPEN)
    _answer_at_once(study)
    for seed, gender in ((1, "female"), (2, "male"), (3, "female")):
        take_part(study, seed, gender)
    paths = write_study_csvs(study, tmp_path / "export")
    clips = read_clips(paths["clips"])
    real = structure(read_responses(paths["responses"], clips, read_participants(paths["participants"])), clips,
                     pd.read_csv(paths["assignments"], keep_default_na=False))

    sim = simulate_design(3, design, seed=5, completion_rate=1.0)
    sim_clips = read_clips(io.StringIO(sim.clips.to_csv(index=False)))
    sim_participants = read_participants(io.StringIO(sim.participants.to_csv(index=False)))
    simulated = structure(read_responses(io.StringIO(sim.responses.to_csv(index=False)), sim_clips, sim_participants),
                          sim_clips, sim.assignments)
    assert set(real) == set(simulated) == {s.section_type for s in design.sections}
    for stype in real:
        assert simulated[stype] == real[stype], stype
    assert set(sim.clips.columns) == set(clips.columns) - {"_line"} or list(sim.clips.columns) == list(CLIP_COLUMNS)
    assert set(sim.assignments["options"].str.split(";").explode()) - {""} <= set(GESTURE_EMOTIONS)


def test_run_report_uses_the_study_exclusion_rules(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    catalogue_from_design(design_from_presets(("demo",)), settings.MEDIA_ROOT)
    study = create_study_from_preset("demo", "demo-rules", status=Study.Status.OPEN)
    _answer_at_once(study)
    for seed in (1, 2):
        take_part(study, seed, "male")
    rules = {"min_rt_fraction": 0.1, "max_straightline": 0.9, "min_attention_pass": 0.5}
    study.exclusion_rules = rules
    study.save(update_fields=["exclusion_rules"])
    report = run_report(study, tmp_path / "report")
    meta = report["meta"]["exclusion_rules"]
    assert meta["source"] == "study settings" and meta["given"] == rules and meta["min_rt_fraction"] == 0.1
    assert "0.1 x the clip duration" in (tmp_path / "report" / "report.html").read_text(encoding="utf-8")
    study.exclusion_rules = {"max_straightline": 3}
    with pytest.raises(ValueError, match="max_straightline"):
        run_report(study, tmp_path / "report2")
