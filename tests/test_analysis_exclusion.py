"""Exclusion rules (analysis.exclusion) and their use by the report."""

import io

import numpy as np
import pandas as pd

from analysis import exclusion as X
from analysis.report import write_report
from analysis.simulate import simulate_study
from protocol.vocabulary import GAIT_EMOTIONS

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
    v = c.set_index("clip_id")[list(GAIT_EMOTIONS)].astype(float)
    top = v.max(axis=1)
    dominant = set(v.index[(top >= 0.5) & (v.eq(top, axis=0).sum(axis=1) == 1)])   # clips with an intended label
    n_victim = int(((r["participant_id"] == victim) & (r["section_type"] == "emotion_choice")
                    & r["clip_id"].isin(dominant)).sum())
    n_all = rep_all["recognition"]["gait_emotion"]["n_answers"]
    assert rep["recognition"]["gait_emotion"]["n_answers"] == n_all - n_victim
    assert rep_all["exclusions"] == [] and any(s.startswith("Exclusions: 1 of 8") for s in rep["meta"]["summary"])


# ---- a study's own rules (Study.exclusion_rules) ------------------------------------------------------------------
def test_rule_errors_name_the_key():
    assert X.rule_errors({}) == [] and X.rule_errors(None) == []
    assert X.rule_errors({"min_rt_fraction": 0.25, "max_straightline": 0.9, "min_attention_pass": 1.0}) == []
    errs = X.rule_errors({"min_rt_fraction": "fast", "max_straightline": 1.5, "min_straight": 2.5, "speed": 1,
                          "min_attention_pass": True})
    assert len(errs) == 5
    for key in ("min_rt_fraction", "max_straightline", "min_straight", "speed", "min_attention_pass"):
        assert sum(e.startswith(f"'{key}'") or f"rule '{key}'" in e for e in errs) == 1, (key, errs)
    assert X.rule_errors([1, 2]) and "JSON object" in X.rule_errors("x")[0]


def test_straightline_share_rule():
    rows = _rows("mostly", "theme_rating", [4] * 9 + [5], [9000] * 10) + _rows("varied", "theme_rating",
                                                                             [4] * 8 + [5, 6], [9000] * 10)
    t = X.straight_lining(pd.DataFrame(rows), max_straightline=0.9)
    assert t["participant_id"].tolist() == ["mostly"] and t["detail"].iloc[0].startswith("9 of 10 answers")
    assert X.straight_lining(pd.DataFrame(rows)).empty                       # default: all equal only


def test_attention_rule_and_not_applicable():
    parts = pd.DataFrame({"participant_id": ["a", "b", "c", "d"], "attention_passed": ["2", "1", "", "0"],
                          "attention_total": ["2", "2", "", "0"]})
    t, note = X.attention_failures(parts, 1.0)
    assert t["participant_id"].tolist() == ["b"] and "passed 1 of 2" in t["detail"].iloc[0]
    assert "2 of 4" in note
    assert X.attention_failures(parts, 0.5)[0].empty
    t, note = X.attention_failures(parts.drop(columns=list(X.ATTENTION_COLUMNS)), 1.0)
    assert t.empty and "not applicable" in note


def _report(r, c, p, **kw):
    import tempfile

    csvs = [io.StringIO(df.to_csv(index=False)) for df in (r, c, p)]
    with tempfile.TemporaryDirectory() as tmp:
        rep = write_report(*csvs, tmp, figures=False, **kw)
        html = open(f"{tmp}/report.html", encoding="utf-8").read()
    return rep, html


def test_report_applies_and_states_study_rules():
    r, c, p = simulate_study(10, seed=6, completion_rate=1.0)
    ids = sorted(p["participant_id"])
    p = p.copy()
    p["attention_passed"] = [1 if i == ids[3] else 2 for i in p["participant_id"]]
    p["attention_total"] = 2
    r = r.copy()
    r.loc[r["participant_id"] == ids[0], "response_ms"] = 2000           # 0.2 x 10 s: fast under 0.25, not 0.1
    rules = {"min_rt_fraction": 0.25, "max_straightline": 0.9, "min_attention_pass": 1.0}
    rep, html = _report(r, c, p, exclusion_rules=rules)
    got = {(e["participant_id"], e["rule"]) for e in rep["exclusions"]}
    assert (ids[0], "too_fast") in got and (ids[3], "failed_attention") in got
    meta = rep["meta"]["exclusion_rules"]
    assert meta["source"] == "study settings" and meta["max_straightline"] == 0.9 and meta["given"] == rules
    assert "at least 90%" in html and "Thresholds from the study settings" in html
    rep2, _ = _report(r, c, p, exclusion_rules={"min_rt_fraction": 0.1, "min_attention_pass": 0.5})
    assert not any(e["rule"] in ("too_fast", "failed_attention") for e in rep2["exclusions"])
    rep3, html3 = _report(r, c, p.drop(columns=list(X.ATTENTION_COLUMNS)))
    assert rep3["meta"]["exclusion_rules"]["source"] == "defaults"
    assert "not applicable" in rep3["meta"]["exclusion_rules"]["attention"]
    assert any(s.startswith("Attention checks: not applicable") for s in rep3["meta"]["summary"])
    import pytest

    with pytest.raises(ValueError, match="max_straightline"):
        _report(r, c, p, exclusion_rules={"max_straightline": 2})


def test_attention_check_answers_in_responses_are_counted():
    """Attention-check rows of responses.csv (section_type ATTENTION_CHECK) are not clip answers: analysis.io keeps
    them aside, and without participants.csv counts the attention rule counts them."""
    from protocol.vocabulary import ATTENTION_CHECK, attention_question

    r, c, p = simulate_study(6, seed=2, completion_rate=1.0)
    ids = sorted(p["participant_id"])
    checks = pd.DataFrame({"participant_id": [ids[0], ids[1], ids[1]], "section_type": ATTENTION_CHECK,
                           "clip_id": r["clip_id"].iloc[0], "question": attention_question("perceived", "sad"),
                           "answer": ["sad", "sad", "happy"], "response_ms": 3000})
    rep, _ = _report(pd.concat([r, checks], ignore_index=True), c, p.drop(columns=list(X.ATTENTION_COLUMNS)))
    assert [(e["participant_id"], e["rule"]) for e in rep["exclusions"] if e["rule"] == "failed_attention"] == [
        (ids[1], "failed_attention")]
    assert rep["meta"]["n_responses"] == len(r)


def test_cli_exclusion_rules(tmp_path):
    from analysis.__main__ import main
    from analysis.simulate import write_study

    paths = write_study(str(tmp_path / "s"), 6, seed=3)
    args = [paths["responses"], paths["clips"], paths["participants"], "--out", str(tmp_path / "r"), "--no-figures"]
    assert main([*args, "--exclusion-rules", '{"max_straightline": 5}']) == 2
    assert main([*args, "--exclusion-rules", "not json"]) == 2
    rules = tmp_path / "rules.json"
    rules.write_text('{"min_rt_fraction": 0.5, "min_straight": 4}', encoding="utf-8")
    assert main([*args, "--exclusion-rules", str(rules)]) == 0
    import json

    meta = json.loads((tmp_path / "r" / "report.json").read_text())["meta"]["exclusion_rules"]
    assert meta["min_rt_fraction"] == 0.5 and meta["min_straight"] == 4 and meta["source"] == "study settings"
