"""Question wording (REFERENCE.md section 4, verbatim) and answer validation of every section type; the keys and
answer values are exactly protocol.vocabulary's."""
from __future__ import annotations

import pytest

from protocol.vocabulary import (
    GAIT_EMOTIONS,
    GESTURE_EMOTIONS,
    LIKERT_FEATURES,
    LIKERT_LEVELS,
    MULTI_SELECT_KINDS,
    NEUTRAL_CHOICES,
    SECTION_QUESTIONS,
    SECTION_TYPES,
    answer_values,
)
from studyapp.questions import AnswerError, clean_answers, questions_for

SHOWN = ["proud", "sad", "afraid", "amused"]


def labels(q):
    return [label for _, label in q.choices]


def values(q):
    return [value for value, _ in q.choices]


@pytest.mark.parametrize("stype", SECTION_TYPES)
def test_questions_are_the_protocols(stype):
    """Question keys = SECTION_QUESTIONS[section]; answer values = answer_values(kind), in order (gesture_emotion:
    the options shown, a subset of GESTURE_EMOTIONS)."""
    qs = questions_for(stype, clip_theme="happy", shown_options=SHOWN)
    assert [q.key for q in qs] == list(SECTION_QUESTIONS[stype])
    for q in qs:
        kind = SECTION_QUESTIONS[stype][q.key]
        assert q.answer_kind == kind
        assert (q.kind == "multi") == (kind in MULTI_SELECT_KINDS)
        if stype == "gesture_emotion":
            assert values(q) == SHOWN and set(values(q)) <= set(GESTURE_EMOTIONS)
        else:
            assert tuple(values(q)) == answer_values(kind)
        assert q.text and q.choices


def test_table2_wording_verbatim():
    qs = {q.key: q for q in questions_for("affect_likert")}
    assert tuple(qs) == LIKERT_FEATURES
    for key, (label, levels) in LIKERT_LEVELS.items():
        assert qs[key].text == label and labels(qs[key]) == list(levels)
    # spot checks against seed 000 Table 2
    assert labels(qs["torso"])[0] == "contracted, bowed" and labels(qs["arms"])[4] == "expanded, away from the body"
    assert labels(qs["pace"])[4] == "hurried, sudden, fast" and labels(qs["flow"])[2] == "neither free nor bound"
    assert qs["pace"].text == "Gait pace"


def test_naturalness_anchors():
    (q,) = questions_for("naturalness")
    assert dict(q.choices) == {"1": "not natural at all", "2": "", "3": "satisfactory", "4": "", "5": "very natural"}
    from studyapp.questions import NATURALNESS_ANCHORS_GESTURE

    (g,) = questions_for("naturalness", {"anchors": NATURALNESS_ANCHORS_GESTURE, "question": "How natural?"})
    assert labels(g)[0].startswith("Very Unnatural") and labels(g)[4].startswith("Looks great!")
    assert g.text == "How natural?"


def test_scales_and_choices():
    inv = questions_for("theme_inversion", clip_theme="happy")[0]
    assert "sad" in dict(inv.choices)["-7"] and dict(inv.choices)["0"] == "neutral"
    assert inv.text == "Does this walk look sad or happy?"
    assert questions_for("theme_rating", clip_theme="tired")[0].text == "How tired does this walk look?"
    nv = questions_for("neutral_validation")[0]
    assert tuple(values(nv)) == NEUTRAL_CHOICES and labels(nv)[0] == "Neutral"
    with pytest.raises(ValueError):
        questions_for("gesture_emotion")
    with pytest.raises(ValueError, match="not among its answers"):
        questions_for("gesture_emotion", shown_options=["proud", "happy"])
    with pytest.raises(ValueError, match="unknown"):
        questions_for("dance_rating")
    tr = questions_for("emotion_transition")
    assert all(q.kind == "multi" for q in tr)


def test_clean_answers():
    qs = questions_for("emotion_choice")
    chosen = [GAIT_EMOTIONS[3], GAIT_EMOTIONS[1]]
    assert clean_answers(qs, {"perceived": chosen}) == {"perceived": f"{GAIT_EMOTIONS[1]};{GAIT_EMOTIONS[3]}"}
    with pytest.raises(AnswerError, match="Please answer"):
        clean_answers(qs, {"perceived": []})
    with pytest.raises(AnswerError, match="not an allowed"):
        clean_answers(qs, {"perceived": ["joyous"]})
    single = questions_for("theme_rating", clip_theme="tired")
    with pytest.raises(AnswerError, match="exactly one"):
        clean_answers(single, {"rating": ["1", "2"]})
    with pytest.raises(AnswerError, match="not an allowed"):
        clean_answers(single, {"rating": ["1.5"]})
    with pytest.raises(AnswerError, match="not an allowed"):
        clean_answers(questions_for("gesture_emotion", shown_options=SHOWN), {"perceived": ["joyous"]})


def test_wording_covers_exactly_the_protocol():
    from protocol.section_types import get_section_type
    from studyapp.models import Section
    from studyapp.questions import WORDING

    assert set(WORDING) == set(SECTION_TYPES)
    for stype, wording in WORDING.items():
        assert set(wording.questions) == set(SECTION_QUESTIONS[stype]) and get_section_type(stype).label
    # the admin offers the question-bearing types, then the instruction and break pages (no wording of this kind)
    assert [value for value, _ in Section._meta.get_field("section_type").choices] == [
        *SECTION_TYPES, "instruction_page", "break_page"]
