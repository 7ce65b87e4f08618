"""Recognition and naturalness broken down by the human body a clip shows (clips.csv ``body``: the preset name).

Body shape is a factor of emotion perception; a plan can cross its conditions with body presets
(``render: {body_preset: ...}``). Per body and measure: the overall hit rate of the forced-choice questions (the
trace of the confusion matrix over its total, answers with k labels counting 1/k each, as in
:mod:`analysis.recognition`) with Cohen's kappa, and the naturalness share of ratings >= 3 with the mean rating.
Clips without a body (other looks, videos, old catalogues) are left out.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from . import naturalness as naturalness_mod
from . import recognition

COLUMNS = ["body", "measure", "n", "value", "mean", "kappa"]


def by_body(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    """One row per (body, measure) present: measure "gait_emotion" / "gesture_emotion" (value = hit rate, kappa) or
    "naturalness" (value = share of ratings >= 3, mean = mean rating); n = answers."""
    if "body" not in clips.columns:
        return pd.DataFrame(columns=COLUMNS)
    rows = []
    for body in sorted(b for b in clips["body"].dropna().unique() if str(b).strip()):
        ids = clips.index[clips["body"] == body]
        sub_r = responses[responses["clip_id"].astype(str).isin(ids)]
        sub_c = clips.loc[ids]
        for measure, fn in (("gait_emotion", recognition.gait_recognition),
                            ("gesture_emotion", recognition.gesture_recognition)):
            if recognition._answers(sub_r, "emotion_choice" if measure == "gait_emotion" else measure).empty:
                continue
            res = fn(sub_r, sub_c)
            conf = res["confusion"].to_numpy(dtype=float)
            if res["n_answers"] == 0 or conf.sum() == 0:
                continue
            rows.append({"body": body, "measure": measure, "n": res["n_answers"],
                         "value": float(np.trace(conf) / conf.sum()), "mean": np.nan, "kappa": res["kappa"]})
        nat = naturalness_mod.naturalness(sub_r, sub_c)
        if not nat.empty:
            n = nat["n"].sum()
            rows.append({"body": body, "measure": "naturalness", "n": int(n),
                         "value": float((nat["share_at_least_3"] * nat["n"]).sum() / n),
                         "mean": float((nat["mean"] * nat["n"]).sum() / n), "kappa": np.nan})
    return pd.DataFrame(rows, columns=COLUMNS)
