"""Question wording (REFERENCE.md section 4, verbatim) and answer validation of every section type."""
from __future__ import annotations

import pytest

from studyapp.questions import AnswerError, clean_answers, questions_for

TYPES = ["emotion_choice", "emotion_transition", "affect_likert", "naturalness", "gesture_emotion",
         "neutral_validation", "theme_rating", "theme_inversion"]


def labels(q):
    return [label for _, label in q.choices]


def test_table2_wording_verbatim():
    qs = {q.key: q for q in questions_for("affect_likert")}
    assert list(qs) == ["torso", "arms", "pace", "flow"]
    assert labels(qs["torso"]) == ["contracted, bowed", "somewhat contracted", "neither contracted nor expanded",
                                   "somewhat expanded", "expanded, stretched"]
    assert labels(qs["arms"])[4] == "expanded, away from the body"
    assert labels(qs["pace"]) == ["sustained, leisurely, slow", "somewhat sustained", "neither sustained nor hurried",
                                  "somewhat hurried", "hurried, sudden, fast"]
    assert labels(qs["flow"]) == ["free, relaxed, uncontrolled", "somewhat free", "neither free nor bound",
                                  "somewhat bound", "bound, tense, controlled"]
    assert [v for v, _ in qs["torso"].choices] == ["0", "1", "2", "3", "4"]


def test_naturalness_anchors():
    (q,) = questions_for("naturalness")
    assert dict(q.choices) == {"1": "not natural at all", "2": "", "3": "satisfactory", "4": "", "5": "very natural"}
    from studyapp.questions import NATURALNESS_ANCHORS_GESTURE

    (g,) = questions_for("naturalness", {"anchors": NATURALNESS_ANCHORS_GESTURE})
    assert labels(g)[0].startswith("Very Unnatural") and labels(g)[4].startswith("Looks great!")


def test_scales_and_choices():
    assert [v for v, _ in questions_for("theme_rating", clip_theme="sad")[0].choices] == [str(i) for i in range(1, 8)]
    inv = questions_for("theme_inversion", clip_theme="happy")[0]
    assert [v for v, _ in inv.choices] == [str(i) for i in range(-7, 8)]
    assert "sad" in dict(inv.choices)["-7"] and dict(inv.choices)["0"] == "neutral"
    nv = questions_for("neutral_validation")[0]
    assert [v for v, _ in nv.choices] == ["neutral", "happy", "sad", "energetic", "tired", "feminine", "masculine"]
    ge = questions_for("gesture_emotion", shown_options=["proud", "sad", "afraid", "amused"])[0]
    assert [v for v, _ in ge.choices] == ["proud", "sad", "afraid", "amused"]
    with pytest.raises(ValueError):
        questions_for("gesture_emotion")
    with pytest.raises(ValueError, match="unknown"):
        questions_for("dance_rating")
    tr = questions_for("emotion_transition")
    assert [q.key for q in tr] == ["initial", "final"] and all(q.kind == "multi" for q in tr)


def test_clean_answers():
    qs = questions_for("emotion_choice")
    assert clean_answers(qs, {"perceived": ["neutral", "sad"]}) == {"perceived": "sad;neutral"}
    with pytest.raises(AnswerError, match="Please answer"):
        clean_answers(qs, {"perceived": []})
    single = questions_for("theme_rating", clip_theme="tired")
    with pytest.raises(AnswerError, match="exactly one"):
        clean_answers(single, {"rating": ["1", "2"]})
    with pytest.raises(AnswerError, match="not an allowed"):
        clean_answers(single, {"rating": ["1.5"]})


@pytest.mark.parametrize("stype", TYPES)
def test_every_type_has_questions(stype):
    qs = questions_for(stype, clip_theme="happy", shown_options=["proud", "sad", "afraid", "amused"])
    assert qs and all(q.choices and q.text for q in qs)
