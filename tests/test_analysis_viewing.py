"""viewing.csv in the analysis: the reader's checks (analysis.io.read_viewing), the viewing exclusion rules
(analysis.viewing), and the report's list of answers without a full view and per-rule removal counts."""

import io
import json
import tempfile

import numpy as np
import pandas as pd
import pytest

from analysis import exclusion as X
from analysis import viewing as V
from analysis.io import ValidationError, read_viewing
from analysis.report import write_report
from analysis.simulate import simulate_study
from protocol.vocabulary import VIEWING_COLUMNS, VIEWING_COLUMNS_V1, VIEWING_FIELDS

FULL = {"first_play_ms": 150, "ended_ms": 3200, "plays": 1, "pauses": 0, "seeks": 0, "stalls": 0, "stall_ms": 0,
        "hidden": 0}


def viewing_frame(responses: pd.DataFrame, overrides: dict | None = None) -> pd.DataFrame:
    """One full-view row per answered clip page of ``responses``; ``overrides`` maps participant_id -> a function
    (row index within that participant's pages) -> field changes (None = blank)."""
    pages = responses[["participant_id", "clip_id", "section_type"]].drop_duplicates().reset_index(drop=True)
    rows = []
    counter: dict[str, int] = {}
    for pid, clip, stype in pages.itertuples(index=False):
        i = counter.get(pid, 0)
        counter[pid] = i + 1
        change = (overrides or {}).get(pid, lambda i: {})(i)
        rows.append({"participant_id": pid, "clip_id": clip, "section_type": stype, **FULL, **change})
    return pd.DataFrame(rows, columns=list(VIEWING_COLUMNS))


def to_csv(df: pd.DataFrame) -> io.StringIO:
    return io.StringIO(df.to_csv(index=False))


# ---- reader -----------------------------------------------------------------------------------------------------

def test_read_viewing_blank_and_integer_fields():
    """A file of the first version (no record, page_ms, shows, startup_ms, hidden_ms columns) still reads."""
    text = ",".join(VIEWING_COLUMNS_V1) + "\np1,c1,emotion_choice,120,3000,2,1,0,0,0,1\np1,c2,emotion_choice" \
        + "," * 8 + "\n"
    df = read_viewing(io.StringIO(text))
    assert df["plays"].tolist()[0] == 2 and np.isnan(df["plays"].iloc[1])
    assert V.recorded(df).tolist() == [True, False]
    assert df["record"].tolist() == ["", ""] and df["hidden_ms"].isna().all()


def test_read_viewing_with_the_record_markers():
    head = ",".join(VIEWING_COLUMNS)
    rows = ["p1,c1,emotion_choice,120,3000,1,0,0,0,0,0,80,0,ok,4000,1",
            "p1,c2,emotion_choice,,,,,,,,,,,missing,3000,1",
            "p1,c3,emotion_choice,,,,,,,,,,,no_script,3500,1",
            "p1,c4,emotion_choice,120,3000,999,0,0,0,0,0,,,Implausible,5000,2"]
    df = read_viewing(io.StringIO(head + "\n" + "\n".join(rows) + "\n"))
    assert df["record"].tolist() == ["ok", "missing", "no_script", "implausible"]
    assert V.recorded(df).tolist() == [True, False, False, False]       # only trusted records are judged
    assert V.untrusted(df).tolist() == [False, True, False, True]
    assert df["shows"].tolist() == [1, 1, 1, 2] and df["page_ms"].iloc[0] == 4000
    summary = V.viewing_summary(df)
    assert (summary["n_recorded"], summary["n_record_missing"], summary["n_implausible"], summary["n_no_script"]) \
        == (1, 1, 1, 1)
    with pytest.raises(ValidationError, match="'record'.*'faked' is not blank or one of ok, missing"):
        read_viewing(io.StringIO(head + "\n" + rows[0].replace(",ok,", ",faked,") + "\n"))


@pytest.mark.parametrize("cell,words", [("-1", "non-negative integer"), ("1.5", "non-negative integer"),
                                        ("many", "'many'")])
def test_read_viewing_names_line_and_column(cell, words):
    text = ",".join(VIEWING_COLUMNS_V1) + f"\np1,c1,emotion_choice,120,3000,{cell},1,0,0,0,1\n"
    with pytest.raises(ValidationError) as exc:
        read_viewing(io.StringIO(text))
    message = str(exc.value)
    assert "viewing.csv line 2, column 'plays'" in message and words in message


def test_read_viewing_missing_column_and_unknown_participant():
    with pytest.raises(ValidationError, match="'hidden': required column"):
        read_viewing(io.StringIO(",".join(VIEWING_COLUMNS_V1[:-1]) + "\n"))
    participants = pd.DataFrame({"participant_id": ["p1"]})
    text = ",".join(VIEWING_COLUMNS) + "\np2,c1,emotion_choice" + ",1" * len(VIEWING_FIELDS) + "\n"
    with pytest.raises(ValidationError, match="unknown participant 'p2'"):
        read_viewing(io.StringIO(text), participants)


# ---- rules ------------------------------------------------------------------------------------------------------

def _rows(pid, n, unended=0, hidden=0, blank=0):
    out = []
    for i in range(n):
        row = {"participant_id": pid, "clip_id": f"c{i}", "section_type": "emotion_choice", **FULL}
        if i < unended:
            row["ended_ms"] = np.nan
        if i < hidden:
            row["hidden"] = 1
        if i >= n - blank:
            row.update({f: np.nan for f in VIEWING_FIELDS})
        out.append(row)
    return out


def test_viewing_rules_thresholds_and_unrecorded_answers():
    v = pd.DataFrame(_rows("rusher", 10, unended=6) + _rows("half", 10, unended=5) + _rows("hider", 10, hidden=3)
                     + _rows("nojs", 10, blank=10) + _rows("some", 4, unended=2, blank=2))
    table, note = V.viewing_exclusions(v, max_unended_share=0.5, max_hidden_share=0.2)
    got = {(r.participant_id, r.rule) for r in table.itertuples()}
    # 'some': 2 of 2 recorded answers before the end (the 2 without a record are not judged)
    assert got == {("rusher", "answered_before_end"), ("some", "answered_before_end"), ("hider", "tab_hidden")}
    assert "6 of 10 recorded answers given before the clip ended (limit 50%)" in set(table["detail"])
    assert note.startswith("viewing rules: applied to the 32 of 44 answers")
    off, _ = V.viewing_exclusions(v)                                    # defaults: both rules off
    assert off.empty
    assert V.viewing_exclusions(None)[1] == "viewing rules: not applicable (no viewing.csv)"
    assert "not applicable" in V.viewing_exclusions(pd.DataFrame(_rows("nojs", 3, blank=3)))[1]
    incomplete = V.incomplete_views(v)
    assert len(incomplete) == 6 + 5 + 2 and list(incomplete.columns) == V.INCOMPLETE_COLUMNS


def test_untrusted_records_rule():
    v = pd.DataFrame(_rows("faker", 10) + _rows("honest", 10) + _rows("nojs", 4, blank=4))
    v["record"] = "ok"
    v.loc[v["participant_id"] == "faker", "record"] = ["missing"] * 4 + ["implausible"] * 2 + ["ok"] * 4
    v.loc[v["participant_id"] == "nojs", "record"] = "no_script"
    table, note = V.viewing_exclusions(v, max_untrusted_share=0.5)
    assert [(r.participant_id, r.rule) for r in table.itertuples()] == [("faker", "record_untrusted")]
    assert "6 of 10 answers with the viewing record missing or implausible (limit 50%)" in set(table["detail"])
    assert "record_untrusted applied to all 24 answers" in note
    assert V.viewing_exclusions(v)[0].empty                              # off by default
    # the untrusted answers are not judged by the other rules: the faker's 4 ok answers are full views
    assert len(V.incomplete_views(v)) == 0
    assert X.rule_errors({"max_untrusted_share": 0.25}) == []
    assert X.resolve_rules({"max_untrusted_share": 0.5})["max_untrusted_share"] == 0.5


def test_viewing_rule_keys_are_validated():
    assert X.rule_errors({"max_unended_share": 0.2, "max_hidden_share": 0}) == []
    errors = X.rule_errors({"max_unended_share": 1.5, "max_hidden_share": "x"})
    assert any("'max_unended_share'" in e and "between 0 and 1" in e for e in errors)
    assert any("'max_hidden_share'" in e and "a number" in e for e in errors)


def test_removed_counts_per_rule_and_union():
    responses = pd.DataFrame({"participant_id": ["a"] * 3 + ["b"] * 5 + ["c"] * 2})
    table = pd.DataFrame({"participant_id": ["a", "b", "b"], "rule": ["too_fast", "too_fast", "tab_hidden"],
                          "detail": "", "n_answers": 0})
    counts = X.removed_counts(responses, table).set_index("rule")
    assert counts.loc["too_fast"].tolist() == [2, 8]
    assert counts.loc["tab_hidden"].tolist() == [1, 5]
    assert counts.loc["any rule"].tolist() == [2, 8]


# ---- report -----------------------------------------------------------------------------------------------------

def _report(r, c, p, viewing=None, **kw):
    csvs = [to_csv(df) for df in (r, c, p)]
    with tempfile.TemporaryDirectory() as tmp:
        rep = write_report(*csvs, tmp, figures=False, viewing_csv=to_csv(viewing) if viewing is not None else None,
                           **kw)
        html = open(f"{tmp}/report.html", encoding="utf-8").read()
        incomplete = pd.read_csv(f"{tmp}/viewing_incomplete.csv")
    return rep, html, incomplete


def test_report_lists_incomplete_views_and_what_each_rule_removed():
    r, c, p = simulate_study(8, seed=11, completion_rate=1.0)
    ids = sorted(p["participant_id"])
    rusher, hider = ids[1], ids[4]
    v = viewing_frame(r, {rusher: lambda i: {"ended_ms": None},                       # never waits for the end
                          hider: lambda i: {"hidden": 1 if i % 2 == 0 else 0},
                          ids[6]: lambda i: {"ended_ms": None} if i == 0 else {}})    # one early answer only
    rules = {"max_unended_share": 0.5, "max_hidden_share": 0.25}
    rep, html, incomplete = _report(r, c, p, v, exclusion_rules=rules)
    got = {(e["participant_id"], e["rule"]) for e in rep["exclusions"]}
    assert (rusher, "answered_before_end") in got and (hider, "tab_hidden") in got
    assert (ids[6], "answered_before_end") not in got
    counts = {e["rule"]: e for e in rep["exclusion_counts"]}
    n_rusher = int((r["participant_id"] == rusher).sum())
    assert counts["answered_before_end"]["participants"] == 1 and counts["answered_before_end"]["answers"] == n_rusher
    assert counts["tab_hidden"]["answers"] == int((r["participant_id"] == hider).sum())
    assert counts["any rule"]["participants"] == rep["participants"]["n_excluded"]
    n_pages_rusher = int((v["participant_id"] == rusher).sum())
    assert len(incomplete) == n_pages_rusher + 1 and set(incomplete["participant_id"]) == {rusher, ids[6]}
    assert rep["viewing"]["n_without_full_view"] == n_pages_rusher + 1
    summary = " ".join(rep["meta"]["summary"])
    assert f"Viewing: {n_pages_rusher + 1} of {len(v)} answers" in summary
    assert f"answered_before_end: 1 participant(s), {n_rusher} answers" in summary
    assert "Answers given without a full view of the clip" in html and "What each exclusion rule removed" in html
    assert "answered_before_end, from viewing.csv" in rep["meta"]["exclusion_rules"]["method"]


def test_report_without_viewing_csv_says_so():
    r, c, p = simulate_study(5, seed=12, completion_rate=1.0)
    rep, _, incomplete = _report(r, c, p)
    assert incomplete.empty and rep["viewing"] == {}
    assert any(s.startswith("Viewing: no viewing.csv") for s in rep["meta"]["summary"])
    assert rep["meta"]["exclusion_rules"]["viewing"] == "viewing rules: not applicable (no viewing.csv)"
    assert not any("no data for this analysis" in n and ("viewing" in n or "exclusion" in n)
                   for n in rep["meta"]["notes"])


def test_cli_reads_viewing(tmp_path):
    from analysis.__main__ import main
    from analysis.simulate import write_study

    paths = write_study(str(tmp_path / "s"), 5, seed=4)
    r = pd.read_csv(paths["responses"], dtype=str, keep_default_na=False)
    viewing = tmp_path / "viewing.csv"
    viewing_frame(r).to_csv(viewing, index=False)
    args = [paths["responses"], paths["clips"], paths["participants"], "--out", str(tmp_path / "r"), "--no-figures"]
    assert main([*args, "--viewing", str(tmp_path / "missing.csv")]) == 2
    assert main([*args, "--viewing", str(viewing)]) == 0
    rep = json.loads((tmp_path / "r" / "report.json").read_text())
    assert rep["viewing"]["n_recorded"] == len(viewing_frame(r)) and rep["viewing"]["n_without_full_view"] == 0
