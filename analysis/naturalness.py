"""Naturalness / plausibility ratings (seed 000 section 6.3.4, seed 003 section 6.3.2 and Fig. 8).

Section ``naturalness``: each answer is a 1..5 rating of one clip; the clip's ``origin`` (generated | source |
imported: a researcher's own stimulus) and ``modality`` (gait | gesture | other) come from clips.csv. A rating
>= 3 counts as "satisfactory" / "plausible", the criterion both papers use.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

RATINGS = (1, 2, 3, 4, 5)


def _rows(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    r = responses[responses["section_type"] == "naturalness"]
    c = clips.reindex(r["clip_id"])
    return pd.DataFrame({"participant_id": r["participant_id"].to_numpy(), "origin": c["origin"].to_numpy(),
                         "modality": c["modality"].to_numpy(), "value": r["value"].to_numpy(float)})


def naturalness(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    """Counts and shares of each rating 1..5 and the share of ratings >= 3, per origin and modality.

    Returns origin, modality, count_1..count_5, share_1..share_5, share_at_least_3, n, mean (one row per
    (origin, modality) present in the data).
    """
    d = _rows(responses, clips)
    cols = ["origin", "modality", *[f"count_{k}" for k in RATINGS], *[f"share_{k}" for k in RATINGS],
            "share_at_least_3", "n", "mean"]
    if d.empty:
        return pd.DataFrame(columns=cols)
    counts = pd.crosstab([d["origin"], d["modality"]], d["value"]).reindex(columns=[float(k) for k in RATINGS],
                                                                          fill_value=0)
    counts.columns = [f"count_{k}" for k in RATINGS]
    n = counts.sum(axis=1)
    out = counts.copy()
    for k in RATINGS:
        out[f"share_{k}"] = counts[f"count_{k}"] / n
    out["share_at_least_3"] = counts[["count_3", "count_4", "count_5"]].sum(axis=1) / n
    out["n"] = n
    out["mean"] = d.groupby(["origin", "modality"])["value"].mean()
    return out.reset_index()[cols]


def naturalness_test(responses: pd.DataFrame, clips: pd.DataFrame, alpha: float = 0.05) -> pd.DataFrame:
    """Generated vs source ratings, per modality, by two tests (both two-sided):

    - Mann-Whitney U on the 1..5 ratings (scipy.stats.mannwhitneyu, asymptotic with tie correction);
      ``rank_biserial`` = 2 U_generated / (n_generated n_source) - 1 (> 0: generated rated higher).
    - Pearson chi-square on the 2 x 2 table origin x (rating >= 3, rating < 3) (scipy.stats.chi2_contingency,
      Yates continuity correction); Fisher's exact test replaces it (``share_test`` says which) when an expected
      count is below 5.

    Answers are treated as independent observations, as in both papers, although one participant rates several
    clips. Returns modality, n_generated, n_source, share_generated, share_source, mwu_U, mwu_p, rank_biserial,
    share_test, share_stat, share_p, reject_mwu, reject_share.
    """
    d = _rows(responses, clips)
    rows = []
    for modality, g in d.groupby("modality", sort=True):
        gen = g.loc[g["origin"] == "generated", "value"].to_numpy()
        src = g.loc[g["origin"] == "source", "value"].to_numpy()
        if len(gen) == 0 or len(src) == 0:
            continue
        mw = stats.mannwhitneyu(gen, src, alternative="two-sided", method="asymptotic")
        table = np.array([[(gen >= 3).sum(), (gen < 3).sum()], [(src >= 3).sum(), (src < 3).sum()]])
        if (table.sum(axis=0) == 0).any():
            test, stat, p = "none (all in one category)", np.nan, 1.0
        else:
            chi = stats.chi2_contingency(table, correction=True)
            if (chi.expected_freq < 5).any():
                fe = stats.fisher_exact(table)
                test, stat, p = "fisher_exact", float(fe.statistic), float(fe.pvalue)
            else:
                test, stat, p = "chi2_yates", float(chi.statistic), float(chi.pvalue)
        rows.append({"modality": modality, "n_generated": len(gen), "n_source": len(src),
                     "share_generated": float((gen >= 3).mean()), "share_source": float((src >= 3).mean()),
                     "mwu_U": float(mw.statistic), "mwu_p": float(mw.pvalue),
                     "rank_biserial": 2 * float(mw.statistic) / (len(gen) * len(src)) - 1,
                     "share_test": test, "share_stat": stat, "share_p": p,
                     "reject_mwu": bool(mw.pvalue < alpha), "reject_share": bool(p < alpha)})
    return pd.DataFrame(rows, columns=["modality", "n_generated", "n_source", "share_generated", "share_source",
                                       "mwu_U", "mwu_p", "rank_biserial", "share_test", "share_stat", "share_p",
                                       "reject_mwu", "reject_share"])
