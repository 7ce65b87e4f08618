"""Intended vs perceived gesture emotions in VAD space (seed 003 section 6.3.1, Fig. 7).

Section ``gesture_emotion``: each answer is one emotion category (a forced choice among four). The perceived
category is mapped to (valence, arousal, dominance) with the NRC-VAD lexicon (:data:`protocol.vocabulary.GESTURE_VAD`).
The intended VAD of a clip is the NRC-VAD row of its ``emotion_label``; a clip whose label is blank or not in the
lexicon uses its ``valence, arousal, dominance`` columns. Each answer gives one (intended, perceived) pair.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from protocol.vocabulary import GESTURE_VAD, VAD_DIMENSIONS


def intended_vad(clips: pd.DataFrame) -> pd.DataFrame:
    """clip_id -> intended (valence, arousal, dominance): NRC-VAD of emotion_label, else the clip's VAD columns."""
    lex = pd.DataFrame.from_dict(GESTURE_VAD, orient="index", columns=list(VAD_DIMENSIONS))
    from_label = lex.reindex(clips["emotion_label"]).set_axis(clips.index)
    return from_label.fillna(clips[list(VAD_DIMENSIONS)])


def vad_pairs(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    """One row per gesture_emotion answer: clip_id, intended_label, perceived_label, intended_<d>, perceived_<d>."""
    r = responses[responses["section_type"] == "gesture_emotion"]
    lex = pd.DataFrame.from_dict(GESTURE_VAD, orient="index", columns=list(VAD_DIMENSIONS))
    want = intended_vad(clips).reindex(r["clip_id"])
    got = lex.reindex(r["answer"])
    out = pd.DataFrame({"clip_id": r["clip_id"].to_numpy(),
                        "intended_label": clips["emotion_label"].reindex(r["clip_id"]).to_numpy(),
                        "perceived_label": r["answer"].to_numpy()})
    for d in VAD_DIMENSIONS:
        out[f"intended_{d}"] = want[d].to_numpy()
        out[f"perceived_{d}"] = got[d].to_numpy()
    return out


def vad_pearson(responses: pd.DataFrame, clips: pd.DataFrame, confidence: float = 0.95) -> pd.DataFrame:
    """Pearson correlation between intended and perceived values per VAD dimension (seed 003 section 6.3.1).

    scipy.stats.pearsonr (two-sided p from the exact t distribution of r under bivariate normality) and its
    ``confidence_interval`` (Fisher z transform). n = number of answers. A dimension with constant intended or
    perceived values gives r = NaN.

    Returns dimension, r, p_value, ci_low, ci_high, n.
    """
    pairs = vad_pairs(responses, clips)
    rows = []
    if pairs.empty:
        return pd.DataFrame(columns=["dimension", "r", "p_value", "ci_low", "ci_high", "n"])
    for d in VAD_DIMENSIONS:
        x, y = pairs[f"intended_{d}"].to_numpy(float), pairs[f"perceived_{d}"].to_numpy(float)
        n = len(x)
        if n < 3 or np.ptp(x) == 0 or np.ptp(y) == 0:
            rows.append({"dimension": d, "r": np.nan, "p_value": np.nan, "ci_low": np.nan, "ci_high": np.nan,
                         "n": n})
            continue
        res = stats.pearsonr(x, y)
        ci = res.confidence_interval(confidence_level=confidence)
        rows.append({"dimension": d, "r": float(res.statistic), "p_value": float(res.pvalue),
                     "ci_low": float(ci.low), "ci_high": float(ci.high), "n": n})
    return pd.DataFrame(rows, columns=["dimension", "r", "p_value", "ci_low", "ci_high", "n"])
