"""Pose affective feature ratings (seed 000 section 6.3.3, Table 2, Fig. 8).

Section ``affect_likert``: for a gait clip, each participant rates torso, arms, pace and flow on 0..4.
A clip's *emotion* is its dominant intended emotion: the argmax of (happy, sad, angry, neutral) in clips.csv
(ties go to the first in that order).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from protocol.vocabulary import GAIT_EMOTIONS, LIKERT_FEATURES

from .adtest import anderson_ksamp_groups
from .emotion import P_CEIL, P_FLOOR, ad_ksamp

LIKERT_VALUES = (0, 1, 2, 3, 4)


def dominant_emotion(clips: pd.DataFrame) -> pd.Series:
    """clip_id -> dominant intended gait emotion (argmax of happy..neutral); NaN where a clip has no vector."""
    v = clips[list(GAIT_EMOTIONS)]
    has = v.notna().all(axis=1)
    lab = pd.Series(np.asarray(GAIT_EMOTIONS, dtype=object)[np.nan_to_num(v.to_numpy(float), nan=-1).argmax(1)],
                    index=clips.index)
    return lab.where(has)


def _likert_rows(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    r = responses[responses["section_type"] == "affect_likert"]
    emo = dominant_emotion(clips)
    return pd.DataFrame({"participant_id": r["participant_id"].to_numpy(), "clip_id": r["clip_id"].to_numpy(),
                         "emotion": emo.reindex(r["clip_id"]).to_numpy(), "feature": r["question"].to_numpy(),
                         "value": r["value"].to_numpy()})


def likert_consistency_ad(responses: pd.DataFrame, clips: pd.DataFrame, alpha: float = 0.05,
                          by: str = "emotion", permutations: int = 0) -> pd.DataFrame:
    """k-sample Anderson-Darling test of consistency across participants (seed 000 section 6.3.3).

    Null hypothesis: the Likert values given by all participants come from the same distribution. One test per
    group and feature; the k samples are the participants, participant i's sample being all of i's values in the
    group. Grouping ``by="emotion"`` (default): a group is all gait clips with the same dominant intended emotion,
    so a participant who rated two sad gaits contributes a sample of two values. ``by="clip"``: one test per
    clip, as worded in seed 000 ("for each gait ... k being the number of users"); then every sample usually has
    one value, and with equal sample sizes of one the statistic is invariant to relabelling, so the test has no
    power -- reported for fidelity, with ``mean_sample_size`` to show it (statistic and p are NaN when every
    sample has one value). Participants with no value in a group are
    not among its k samples. Method: the midrank k-sample AD statistic of scipy.stats.anderson_ksamp computed from a
    count table (:mod:`analysis.adtest`, checked against scipy in the tests), p interpolated and capped to
    [0.001, 0.25] as scipy does; with permutations > 0, scipy's permutation p-value instead.

    Returns: emotion, feature, statistic, p_value, k, p_capped, p_display, reject, n (values), mean_sample_size
    (and clip_id first when by="clip").
    """
    if by not in ("emotion", "clip"):
        raise ValueError(f"by must be 'emotion' or 'clip', not {by!r}")
    d = _likert_rows(responses, clips)
    keys = ["emotion", "feature"] if by == "emotion" else ["clip_id", "emotion", "feature"]
    rows = []
    if d.empty:
        return pd.DataFrame(columns=[*keys, "statistic", "p_value", "k", "p_capped", "p_display", "reject", "n",
                                     "mean_sample_size"])
    for key, g in d.groupby(keys, sort=True):
        pid = g["participant_id"].to_numpy()
        vals = g["value"].to_numpy(float)
        k = len(np.unique(pid))
        if permutations:
            order = np.argsort(pid, kind="stable")
            cuts = np.flatnonzero(pid[order][1:] != pid[order][:-1]) + 1
            res = ad_ksamp(np.split(vals[order], cuts), alpha, permutations)
            stat, p = res["statistic"], res["p_value"]
        else:
            stat, p = anderson_ksamp_groups(vals, pid)
        if np.isnan(p):
            display = "n/a (k < 2)" if k < 2 else "n/a (every sample has one value)" if k == len(g) else "n/a"
            capped, reject = False, False
        else:
            capped = p >= P_CEIL or p <= P_FLOOR
            display = "> 0.25" if p >= P_CEIL else "< 0.001" if p <= P_FLOOR else f"{p:.3f}"
            reject = bool(p < alpha)
        rows.append({**dict(zip(keys, key)), "statistic": stat, "p_value": p, "k": k, "p_capped": capped,
                     "p_display": display, "reject": reject, "n": len(g), "mean_sample_size": len(g) / k})
    return pd.DataFrame(rows)


def likert_distribution(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    """Share of each Likert value 0..4 per dominant intended emotion and feature (seed 000 Fig. 8).

    Returns emotion, feature, value, share, count, n (all values of that emotion and feature); every value 0..4
    appears, with share 0 where nobody chose it. Shares of a (emotion, feature) sum to 1.
    """
    d = _likert_rows(responses, clips)
    cols = ["emotion", "feature", "value", "share", "count", "n"]
    if d.empty:
        return pd.DataFrame(columns=cols)
    counts = d.groupby(["emotion", "feature", "value"]).size()
    present_e, present_f = set(d["emotion"].unique()), set(d["feature"].unique())
    emotions = [e for e in GAIT_EMOTIONS if e in present_e]
    features = [f for f in LIKERT_FEATURES if f in present_f]
    full = pd.MultiIndex.from_product([emotions, features, [float(v) for v in LIKERT_VALUES]],
                                      names=["emotion", "feature", "value"])
    counts = counts.reindex(full, fill_value=0)
    n = counts.groupby(level=["emotion", "feature"]).transform("sum")
    out = pd.DataFrame({"count": counts, "n": n}).reset_index()
    out["share"] = np.where(out["n"] > 0, out["count"] / out["n"].where(out["n"] > 0, 1), np.nan)
    out["value"] = out["value"].astype(int)
    return out[cols]
