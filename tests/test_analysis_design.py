"""The simulator's design comes from a study preset and its plan (analysis.design), without Django."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from analysis.design import PAPER_PRESETS, DesignError, design_from_presets, pool_mask
from analysis.simulate import simulate_design
from generation.plans.schema import load_plan
from protocol.presets import PRESET_PLANS, PRESETS
from protocol.vocabulary import GAIT_EMOTIONS, SECTION_QUESTIONS


def test_counts_and_pools_come_from_preset_and_plan():
    d = design_from_presets(PAPER_PRESETS)
    assert [s.section_type for s in d.sections] == [s["section_type"] for p in PAPER_PRESETS
                                                   for s in PRESETS[p]["sections"]]
    for sec in d.sections:
        spec = PRESETS[sec.preset]["sections"][sec.order - 1 - [s.preset for s in d.sections].index(sec.preset)]
        assert sec.n_per_participant == spec.get("clips_per_participant", 0) and sec.options == spec.get("options",
                                                                                                           {})
        assert set(d.clips["plan"].iloc[sec.pool]) <= {PRESET_PLANS[sec.preset]}
    plans = {name: load_plan(name) for name in ("seed000", "seed003", "seed004")}
    by_type = {s.section_type: s for s in d.sections if s.reuse is None and s.section_type != "naturalness"}
    singles = [e for e in plans["seed000"].entries if e.generator == "gait_net" and "emotion" in e.inputs]
    transitions = [e for e in plans["seed000"].entries if "transition" in e.inputs]
    gestures = [e for e in plans["seed003"].entries if e.generator == "gesture_net"]
    themes = [e for e in plans["seed004"].entries if e.generator == "rbf" and e.inputs["weight"] > 0]
    assert len(by_type["emotion_choice"].pool) == len(singles)
    assert len(by_type["emotion_transition"].pool) == len(transitions)
    assert len(by_type["gesture_emotion"].pool) == len(gestures)
    assert len(by_type["theme_rating"].pool) == len(themes)
    # transition intents are the plan's (0.8 of the emotion, the rest neutral), not a constant of the simulator
    tr = d.clips.iloc[by_type["emotion_transition"].pool]
    want = sorted(round(max(e.inputs["transition"]["initial"]), 3) for e in transitions)
    assert sorted(tr[list(GAIT_EMOTIONS)].max(axis=1).round(3)) == want


@pytest.mark.parametrize("preset", ["demo", "gestures_ieeevr2021"])
def test_simulated_participants_follow_the_design(preset):
    d = design_from_presets((preset,))
    sim = simulate_design(30, d, seed=3, completion_rate=1.0)
    per = sim.assignments.groupby(["participant_id", "section_order"]).size().unstack()
    for sec in d.sections:
        src = d.sections[sec.reuse] if sec.reuse is not None else sec
        want = sum(src.naturalness_counts()) if src.mixed_naturalness else (src.n_per_participant or len(src.pool))
        assert (per[sec.order] == want).all(), sec
    asked = set(zip(sim.responses["section_type"], sim.responses["question"]))
    assert asked == {(s.section_type, q) for s in d.sections for q in SECTION_QUESTIONS[s.section_type]}
    # no clip twice for one participant, except the reusing section; a naturalness section never shows a generated
    # clip and its source together (studyapp.participant.assignment)
    a = sim.assignments.merge(pd.DataFrame({"section_order": [s.order for s in d.sections],
                                            "reuse": [s.reuse is not None for s in d.sections]}))
    assert not a[~a["reuse"]].duplicated(["participant_id", "clip_id"]).any()
    src = dict(zip(d.clips["clip_id"], d.clips["source_clip_id"]))
    for _, shown in a[a["section_type"] == "naturalness"].groupby(["participant_id", "section_order"]):
        ids = set(shown["clip_id"])
        assert not any(src[c] in ids for c in ids if src[c])
    opts = sim.assignments.loc[sim.assignments["section_type"] == "gesture_emotion", "options"].str.split(";")
    gesture = next(s for s in d.sections if s.section_type == "gesture_emotion")
    assert (opts.str.len() == gesture.n_options()).all()


def test_pool_filters_and_errors():
    clips = pd.DataFrame({"clip_id": ["a", "b", "c"], "modality": ["gait", "gait", "gesture"],
                          "origin": ["generated", "source", "generated"], "weight": [0.4, np.nan, -0.7],
                          "theme": ["happy", "", "sad"], "final_happy": [np.nan, 0.5, np.nan], "plan": "p"})
    assert pool_mask(clips, {"weight__gt": 0}).tolist() == [True, False, False]
    assert pool_mask(clips, {"rbf": True, "modality": "gait"}).tolist() == [True, False, False]
    assert pool_mask(clips, {"transition": True}).tolist() == [False, True, False]
    assert pool_mask(clips, {"origin": ["source", "generated"], "weight__isnull": True}).tolist() == [False, True,
                                                                                                     False]
    with pytest.raises(DesignError, match="frobnicate"):
        pool_mask(clips, {"frobnicate": 1})
    with pytest.raises(DesignError, match="unknown preset"):
        design_from_presets(("nope",))
    with pytest.raises(DesignError, match=r"preset 'gait_ismar2020', section 1 \(emotion_choice\).*seed004"):
        design_from_presets(("gait_ismar2020",), plans={"gait_ismar2020": "seed004"})


def test_no_django_imported():
    code = ("import sys, analysis.simulate, analysis.design, analysis.report; "
            "sys.exit(any(m.split('.')[0] == 'django' for m in sys.modules))")
    assert subprocess.run([sys.executable, "-c", code], capture_output=True).returncode == 0


def test_preset_anchors_are_the_study_apps():
    """study_presets keeps the naturalness anchors as plain text (no Django); studyapp.questions marks the same
    strings for translation. They must not drift apart."""
    from protocol import presets as study_presets
    from studyapp import questions

    assert study_presets.NATURALNESS_ANCHORS_GAIT == {k: str(v) for k, v in questions.NATURALNESS_ANCHORS_GAIT.items()}
    assert study_presets.NATURALNESS_ANCHORS_GESTURE == {k: str(v) for k, v in
                                                         questions.NATURALNESS_ANCHORS_GESTURE.items()}
