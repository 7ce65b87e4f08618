"""Participant summary and demographic differences (seed 000 section 6.2, seed 003 section 6.2)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from protocol.section_types import SectionType, registered
from protocol.vocabulary import LABEL_CHOICES, MULTI_SELECT_KINDS

from .recognition import selection_weights

SYNTHETIC_PREFIX = "sim-"


def participant_summary(participants: pd.DataFrame, responses: pd.DataFrame) -> dict:
    """Counts, completion, demographics and durations as a JSON-ready dict.

    Keys: n_participants, n_completed, completion_rate, n_with_responses, n_responses, responses_per_participant
    (mean over participants with responses), status, gender, age_group (value -> count), gender_by_age_group
    (gender -> age group -> count), duration_s (median, mean, q25, q75, n over participants with both
    timestamps; completed participants only), response_ms (median, mean; answers with a time),
    synthetic (True when every participant id starts with "sim-", the simulator's mark).
    """
    p = participants
    n = len(p)
    done = p[p["completed"]]
    dur = done["duration_s"].dropna()
    per = responses.groupby("participant_id", observed=True).size()
    ms = responses["response_ms"].dropna()
    crosstab = pd.crosstab(p["gender"], p["age_group"]) if n else pd.DataFrame()

    def _counts(s: pd.Series) -> dict:
        return {str(k): int(v) for k, v in s.value_counts().sort_index().items()}

    def _q(x: pd.Series, q: float):
        return float(x.quantile(q)) if len(x) else None

    return {
        "n_participants": n,
        "n_completed": int(len(done)),
        "completion_rate": float(len(done) / n) if n else None,
        "n_with_responses": int(len(per)),
        "n_responses": int(len(responses)),
        "responses_per_participant": float(per.mean()) if len(per) else None,
        "status": _counts(p["status"]),
        "gender": _counts(p["gender"]),
        "age_group": _counts(p["age_group"]),
        "gender_by_age_group": {str(g): {str(a): int(v) for a, v in row.items()} for g, row in crosstab.iterrows()},
        "duration_s": {"median": _q(dur, 0.5), "mean": float(dur.mean()) if len(dur) else None,
                       "q25": _q(dur, 0.25), "q75": _q(dur, 0.75), "n": int(len(dur))},
        "response_ms": {"median": _q(ms, 0.5), "mean": float(ms.mean()) if len(ms) else None, "n": int(len(ms))},
        "synthetic": bool(n) and bool(p["participant_id"].str.startswith(SYNTHETIC_PREFIX).all()),
    }


def _label_counts(responses: pd.DataFrame, participants: pd.DataFrame, spec: SectionType, factor: str
                  ) -> pd.DataFrame:
    """Contingency table group x perceived label: how often each label was selected by each group (a multi-select
    answer selects each of its labels once)."""
    question = spec.demographics
    r = responses[(responses["section_type"] == spec.name) & (responses["question"] == question)]
    group = participants[factor].reindex(r["participant_id"]).to_numpy()
    kind = spec.question_kinds[question]
    if kind in MULTI_SELECT_KINDS:
        labels = LABEL_CHOICES[kind]
        ind = pd.DataFrame((selection_weights(r["answer"], labels) > 0).astype(int), columns=list(labels))
        ind["group"] = group
        return ind.groupby("group").sum()
    return pd.crosstab(pd.Series(group, name="group"), pd.Series(r["answer"].to_numpy(), name="label"))


def demographic_differences(responses: pd.DataFrame, participants: pd.DataFrame,
                            alpha: float = 0.05) -> pd.DataFrame:
    """Whether perceived emotions differ across gender and age group (seed 000 section 6.2).

    For each section type declaring a ``demographics`` question (protocol.section_types; emotion_choice: each selected
    gait emotion counts once; gesture_emotion: the chosen category) and each factor (gender, age_group), Pearson's
    chi-square test of independence on the table group x label counts (scipy.stats.chi2_contingency, no continuity
    correction; empty rows/columns removed), with Cramer's V = sqrt(chi2 / (N (min(r, c) - 1))). Groups (including
    "undisclosed") with fewer than ``min_count`` = 5 selections are left out and listed. Selections are treated as
    independent although one participant answers several clips; clips are assigned at random, so groups see the
    same clips on average.

    ``share_expected_below_5`` is the share of cells with an expected count below 5 (Cochran's rule asks for at
    most 0.2 for the chi-square approximation to hold).

    Returns section, factor, chi2, dof, p_value, cramers_v, n, share_expected_below_5, groups, left_out, reject.
    """
    rows = []
    for spec in registered():
        if not spec.demographics:
            continue
        section = spec.name
        for factor in ("gender", "age_group"):
            t = _label_counts(responses, participants, spec, factor)
            if t.empty:
                continue
            small = t.index[t.sum(axis=1) < 5]
            t = t.drop(index=small)
            t = t.loc[t.sum(axis=1) > 0, t.sum(axis=0) > 0]
            if t.shape[0] < 2 or t.shape[1] < 2:
                continue
            res = stats.chi2_contingency(t.to_numpy(), correction=False)
            n = int(t.to_numpy().sum())
            v = float(np.sqrt(res.statistic / (n * (min(t.shape) - 1))))
            rows.append({"section": section, "factor": factor, "chi2": float(res.statistic), "dof": int(res.dof),
                         "p_value": float(res.pvalue), "cramers_v": v, "n": n,
                         "share_expected_below_5": float((res.expected_freq < 5).mean()),
                         "groups": ";".join(map(str, t.index)), "left_out": ";".join(map(str, small)),
                         "reject": bool(res.pvalue < alpha)})
    return pd.DataFrame(rows, columns=["section", "factor", "chi2", "dof", "p_value", "cramers_v", "n",
                                       "share_expected_below_5", "groups", "left_out", "reject"])
