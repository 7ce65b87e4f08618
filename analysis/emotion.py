"""Intended vs perceived gait emotions: seed 000 sections 6.3.1 (single emotions) and 6.3.2 (transitions).

How a multi-select answer becomes a vector: the answer ``"happy;neutral"`` becomes the indicator vector over
(happy, sad, angry, neutral) divided by the number of labels selected, here (0.5, 0, 0, 0.5), so every answer has
l1 norm 1. A clip's perceived vector is the arithmetic mean of these vectors over all its answers (one per
participant in the seed study), then l1-normalised. The intended vector is the clip's (happy, sad, angry, neutral)
from clips.csv, l1-normalised (``final_*`` for the final emotion of a transition).

Test: the 2-sample Anderson-Darling test (Scholz & Stephens 1987; scipy.stats.anderson_ksamp, midrank variant)
between the four components of the intended vector and the four components of the perceived vector, exactly as
seed 000 treats the two vectors as "sets of probability values". scipy's statistic is the normalised
(A2kN - (k - 1)) / sigma and can be negative; its p-value is interpolated from tabulated critical values and capped
to [0.001, 0.25] (``p_capped`` True, ``p_display`` "> 0.25" or "< 0.001"). With ``permutations > 0`` a permutation
p-value (scipy.stats.PermutationMethod) is added in ``p_perm``; with two samples of four values it takes at most
C(8, 4) = 70 distinct relabellings, so the exact permutation distribution is used.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
from scipy import stats

from protocol.vocabulary import FINAL_EMOTION_COLUMNS, GAIT_EMOTIONS

P_FLOOR, P_CEIL = 0.001, 0.25


def answer_vectors(answers: pd.Series) -> np.ndarray:
    """Multi-select answers ("happy;neutral") -> (N, 4) array: indicator / number selected, columns in
    GAIT_EMOTIONS order. Labels must already be validated (lower case, no spaces)."""
    ind = np.column_stack([
        answers.str.contains(rf"(?:^|;){e}(?:;|$)", regex=True).to_numpy(dtype=float) for e in GAIT_EMOTIONS
    ])
    n = ind.sum(axis=1, keepdims=True)
    if (n == 0).any():
        raise ValueError("an answer selects no gait emotion")
    return ind / n


def ad_2samp(x, y, alpha: float = 0.05, permutations: int = 0, rng=0) -> dict:
    """Two-sample Anderson-Darling test (midrank) of samples ``x`` and ``y`` (1-D).

    Returns statistic (scipy's normalised form), p_value (interpolated, capped), p_capped, p_display, reject
    (p_value < alpha; capped values compared as they are), and p_perm (NaN unless permutations > 0).
    """
    return ad_ksamp([np.asarray(x, float), np.asarray(y, float)], alpha, permutations, rng)


def ad_ksamp(samples, alpha: float = 0.05, permutations: int = 0, rng=0) -> dict:
    """k-sample Anderson-Darling test (Scholz & Stephens 1987, midrank), scipy.stats.anderson_ksamp.

    ``samples``: sequence of 1-D arrays. All-identical data (no distinct observations) gives statistic NaN,
    p_value 1.0 (nothing to reject).
    """
    samples = [np.asarray(s, float) for s in samples]
    pool = np.concatenate(samples)
    if np.unique(pool).size < 2:
        return {"statistic": np.nan, "p_value": 1.0, "p_capped": False, "p_display": "1 (identical values)",
                "reject": False, "p_perm": np.nan}
    if all(s.size == 1 for s in samples):
        # Equal sample sizes of one: the statistic is the same for every relabelling, its variance is 0.
        return {"statistic": np.nan, "p_value": np.nan, "p_capped": False,
                "p_display": "n/a (every sample has one value)", "reject": False, "p_perm": np.nan}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        try:
            res = stats.anderson_ksamp(samples, variant="midrank")
        except (ValueError, ZeroDivisionError) as exc:  # variance of A2 not positive (degenerate design)
            return {"statistic": np.nan, "p_value": np.nan, "p_capped": False,
                    "p_display": f"n/a ({exc})", "reject": False, "p_perm": np.nan}
        p_perm = np.nan
        if permutations:
            perm = stats.anderson_ksamp(samples, variant="midrank",
                                        method=stats.PermutationMethod(n_resamples=permutations, rng=rng))
            p_perm = float(perm.pvalue)
    p = float(res.pvalue)
    capped = p >= P_CEIL or p <= P_FLOOR
    display = "> 0.25" if p >= P_CEIL else "< 0.001" if p <= P_FLOOR else f"{p:.3f}"
    return {"statistic": float(res.statistic), "p_value": p, "p_capped": capped, "p_display": display,
            "reject": bool(p < alpha), "p_perm": p_perm}


def perceived_by_clip(responses: pd.DataFrame, section: str, question: str) -> pd.DataFrame:
    """Mean perceived vector per clip for one (section_type, question): DataFrame indexed by clip_id with the
    four GAIT_EMOTIONS columns (l1-normalised) and n (number of answers). Vectorised groupby."""
    r = responses[(responses["section_type"] == section) & (responses["question"] == question)]
    if r.empty:
        return pd.DataFrame(columns=[*GAIT_EMOTIONS, "n"])
    vec = pd.DataFrame(answer_vectors(r["answer"]), columns=list(GAIT_EMOTIONS), index=r.index)
    vec["clip_id"] = r["clip_id"].to_numpy()
    g = vec.groupby("clip_id", sort=True)
    mean = g[list(GAIT_EMOTIONS)].mean()
    mean = mean.div(mean.sum(axis=1), axis=0)
    mean["n"] = g.size()
    return mean


def _ad_table(perceived: pd.DataFrame, intended: pd.DataFrame, alpha, permutations) -> pd.DataFrame:
    rows = []
    for clip_id, p in perceived.iterrows():
        want = intended.loc[clip_id].to_numpy(float)
        got = p[list(GAIT_EMOTIONS)].to_numpy(float)
        res = ad_2samp(want, got, alpha, permutations)
        rows.append({"clip_id": clip_id, **{k: res[k] for k in ("statistic", "p_value", "p_capped", "reject")},
                     "n": int(p["n"]), "p_display": res["p_display"], "p_perm": res["p_perm"],
                     **{f"intended_{e}": w for e, w in zip(GAIT_EMOTIONS, want, strict=True)},
                     **{f"perceived_{e}": v for e, v in zip(GAIT_EMOTIONS, got, strict=True)}})
    return pd.DataFrame(rows, columns=_COLUMNS)


_COLUMNS = ["clip_id", "statistic", "p_value", "p_capped", "reject", "n", "p_display", "p_perm",
            *[f"intended_{e}" for e in GAIT_EMOTIONS], *[f"perceived_{e}" for e in GAIT_EMOTIONS]]


def gait_emotion_ad(responses: pd.DataFrame, clips: pd.DataFrame, alpha: float = 0.05,
                    permutations: int = 0) -> pd.DataFrame:
    """Seed 000 section 6.3.1 / Table 3: per gait clip of section ``emotion_choice``, 2-sample Anderson-Darling
    test between the intended emotion vector and the l1-normalised mean perceived vector.

    Clips without an intended vector (an unlabelled real walk) are left out. Returns one row per clip: clip_id,
    statistic, p_value, p_capped, reject, n (answers), p_display, p_perm,
    intended_<e>, perceived_<e> for e in (happy, sad, angry, neutral).
    """
    perceived = perceived_by_clip(responses, "emotion_choice", "perceived")
    intended = clips[list(GAIT_EMOTIONS)]
    labelled = intended.index[intended.notna().all(axis=1)]
    return _ad_table(perceived[perceived.index.isin(labelled)], intended, alpha, permutations)


def transition_ad(responses: pd.DataFrame, clips: pd.DataFrame, alpha: float = 0.05,
                  permutations: int = 0) -> pd.DataFrame:
    """Seed 000 section 6.3.2: the same test for the initial (question ``initial`` vs happy..neutral) and the final
    (question ``final`` vs final_*) emotions of transition clips (section ``emotion_transition``).

    Returns the columns of :func:`gait_emotion_ad` plus ``phase`` (initial | final) after clip_id.
    """
    parts = []
    for phase, cols in (("initial", GAIT_EMOTIONS), ("final", FINAL_EMOTION_COLUMNS)):
        perceived = perceived_by_clip(responses, "emotion_transition", phase)
        intended = clips[list(cols)].set_axis(list(GAIT_EMOTIONS), axis=1)
        t = _ad_table(perceived, intended, alpha, permutations)
        t.insert(1, "phase", phase)
        parts.append(t)
    out = pd.concat(parts, ignore_index=True)
    order = out["phase"].map({"initial": 0, "final": 1})
    return out.assign(_o=order).sort_values(["clip_id", "_o"]).drop(columns="_o").reset_index(drop=True)
