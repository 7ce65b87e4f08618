"""Exclusion rules (analysis.exclusion) and their use by the report."""

import io

import numpy as np
import pandas as pd

from analysis import exclusion as X
from analysis.report import write_report
from analysis.simulate import simulate_study

CLIPS = pd.DataFrame({"duration_s": [10.0, 10.0, np.nan]}, index=["c1", "c2", "c3"])


def _rows(pid, section, values, ms, clips=("c1", "c2")):
    return [{"participant_id": pid, "section_type": section, "clip_id": clips[i % len(clips)], "question": "rating",
             "answer": str(v), "value": float(v), "response_ms": m} for i, (v, m) in enumerate(zip(values, ms))]


def test_too_fast_rule_threshold():
    rows = (_rows("fast", "theme_rating", range(1, 9), [1000] * 6 + [9000] * 2)      # 6 of 8 < 2.5 s: excluded
            + _rows("half", "theme_rating", range(1, 9), [1000] * 4 + [9000] * 4)    # 4 of 8 = 50 %: kept (> rule)
            + _rows("slow", "theme_rating", range(1, 9), [9000] * 8)
            + _rows("untimed", "theme_rating", range(1, 9), [100] * 8, clips=("c3",)))  # no clip duration: ignored
    t = X.fast_answers(pd.DataFrame(rows), CLIPS)
    assert t["participant_id"].tolist() == ["fast"]
    assert t["detail"].iloc[0].startswith("6 of 8 timed answers") and t["n_answers"].iloc[0] == 8


def test_straight_lining_needs_min_answers_and_scale_sections():
    rows = (_rows("flat", "theme_rating", [4] * 8, [9000] * 8)
            + _rows("short", "naturalness", [3] * 7, [9000] * 7)          # 7 < 8 answers: kept
            + _rows("varied", "theme_rating", [4] * 7 + [5], [9000] * 8))
    rows += [{**r, "section_type": "gesture_emotion", "value": np.nan} for r in _rows("cat", "x", [1] * 9, [9e3] * 9)]
    t = X.straight_lining(pd.DataFrame(rows))
    assert t["participant_id"].tolist() == ["flat"] and t["detail"].iloc[0] == "all 8 answers of theme_rating are 4"
    assert set(X.SCALE_SECTIONS) == {"affect_likert", "naturalness", "theme_rating", "theme_inversion"}


def test_report_excludes_and_lists_participant():
    r, c, p = simulate_study(8, seed=5)
    victim = sorted(r["participant_id"].unique())[0]
    r = r.copy()
    r.loc[r["participant_id"] == victim, "response_ms"] = 200
    csvs = [io.StringIO(df.to_csv(index=False)) for df in (r, c, p)]
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        rep = write_report(*csvs, tmp, figures=False)
        csvs = [io.StringIO(df.to_csv(index=False)) for df in (r, c, p)]
        rep_all = write_report(*csvs, tmp, figures=False, exclude=False)
    assert [e["participant_id"] for e in rep["exclusions"]] == [victim]
    assert rep["exclusions"][0]["rule"] == "too_fast"
    assert rep["participants"]["n_participants"] == 8 and rep["participants"]["n_excluded"] == 1
    n_victim = int(((r["participant_id"] == victim) & (r["section_type"] == "emotion_choice")).sum())
    n_all = rep_all["recognition"]["gait_emotion"]["n_answers"]
    assert rep["recognition"]["gait_emotion"]["n_answers"] == n_all - n_victim
    assert rep_all["exclusions"] == [] and any(s.startswith("Exclusions: 1 of 8") for s in rep["meta"]["summary"])
