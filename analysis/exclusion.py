"""Exclusion of inattentive participants before the analysis: too-fast answers and straight-lining on scales.

Two pre-registered-style rules, applied by :func:`analysis.report.build_report` (``exclusions=True``, the default)
and listed with their reasons in the report (key ``exclusions``):

- **Too fast.** An answer is too fast when its ``response_ms`` is below ``fast_fraction`` (default 0.25) times the
  clip's ``duration_s``: the participant cannot have watched the clip. A participant is excluded when more than
  ``max_fast_share`` (default 0.5) of their timed answers to clips with a known duration are too fast (a few
  replays or quick answers to a clip already seen are normal). Answers without a time or a duration do not count.
- **Straight-lining.** A participant is excluded when, in a rating-scale section (affect_likert, naturalness,
  theme_rating, theme_inversion), they gave at least ``min_straight`` (default 8) answers and all of them have the
  same value: a participant who uses one point of the scale for every clip carries no information about the clips
  (cf. Meade & Craig 2012 on careless responding; Curran 2016 on long-string indices).

    A. W. Meade, S. B. Craig. "Identifying careless responses in survey data." Psychological Methods 17(3),
    437-455, 2012.  P. G. Curran. "Methods for the detection of carelessly invalid responses in survey data."
    Journal of Experimental Social Psychology 66, 4-19, 2016.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from study_protocol import INTEGER_RANGES, SECTION_QUESTIONS

SCALE_SECTIONS = tuple(s for s, qs in SECTION_QUESTIONS.items() if all(k in INTEGER_RANGES for k in qs.values()))
"""Sections whose answers are points of a rating scale (study_protocol: every question of an integer kind)."""

FAST_FRACTION, MAX_FAST_SHARE, MIN_STRAIGHT = 0.25, 0.5, 8
COLUMNS = ["participant_id", "rule", "detail", "n_answers"]


def fast_answers(responses: pd.DataFrame, clips: pd.DataFrame, fast_fraction: float = FAST_FRACTION,
                 max_fast_share: float = MAX_FAST_SHARE) -> pd.DataFrame:
    """Participants with more than ``max_fast_share`` of their timed answers faster than ``fast_fraction`` x the
    clip's duration. Returns rows participant_id, rule ``too_fast``, detail, n_answers (timed answers)."""
    dur = clips["duration_s"].reindex(responses["clip_id"].astype(str)).to_numpy(float) * 1000.0
    ms = responses["response_ms"].to_numpy(float)
    timed = np.isfinite(ms) & np.isfinite(dur) & (dur > 0)
    d = pd.DataFrame({"p": responses["participant_id"].astype(str).to_numpy()[timed],
                      "fast": ms[timed] < fast_fraction * dur[timed]})
    g = d.groupby("p", sort=True)["fast"].agg(["sum", "size"])
    bad = g[g["sum"] > max_fast_share * g["size"]]
    return pd.DataFrame({"participant_id": bad.index.to_numpy(dtype=object), "rule": "too_fast",
                         "detail": [f"{int(s)} of {int(n)} timed answers faster than {fast_fraction:g} x the clip "
                                    f"duration (limit {max_fast_share:.0%})" for s, n in zip(bad["sum"], bad["size"])],
                         "n_answers": bad["size"].to_numpy(int)}, columns=COLUMNS)


def straight_lining(responses: pd.DataFrame, min_straight: int = MIN_STRAIGHT) -> pd.DataFrame:
    """Participants who gave one and the same value to all of at least ``min_straight`` answers of a rating-scale
    section (:data:`SCALE_SECTIONS`). Returns rows participant_id, rule ``straight_lining``, detail, n_answers."""
    r = responses[responses["section_type"].isin(SCALE_SECTIONS)]
    d = pd.DataFrame({"p": r["participant_id"].astype(str).to_numpy(), "s": r["section_type"].astype(str).to_numpy(),
                      "v": r["value"].to_numpy(float)})
    g = d.groupby(["p", "s"], sort=True)["v"].agg(["min", "max", "size"])
    bad = g[(g["size"] >= min_straight) & (g["min"] == g["max"])].reset_index()
    return pd.DataFrame({"participant_id": bad["p"].to_numpy(dtype=object), "rule": "straight_lining",
                         "detail": [f"all {int(n)} answers of {s} are {v:g}"
                                    for s, n, v in zip(bad["s"], bad["size"], bad["min"])],
                         "n_answers": bad["size"].to_numpy(int)}, columns=COLUMNS)


def exclusions(responses: pd.DataFrame, clips: pd.DataFrame, fast_fraction: float = FAST_FRACTION,
               max_fast_share: float = MAX_FAST_SHARE, min_straight: int = MIN_STRAIGHT) -> pd.DataFrame:
    """Who is excluded and why: one row per participant and rule that applies (a participant may have several).
    Columns participant_id, rule (too_fast | straight_lining), detail, n_answers."""
    parts = [t for t in (fast_answers(responses, clips, fast_fraction, max_fast_share),
                         straight_lining(responses, min_straight)) if len(t)]
    if not parts:
        return pd.DataFrame(columns=COLUMNS)
    return pd.concat(parts, ignore_index=True).sort_values(["participant_id", "rule"], kind="stable").reset_index(
        drop=True)


def apply_exclusions(responses: pd.DataFrame, table: pd.DataFrame) -> pd.DataFrame:
    """``responses`` without the answers of the participants in ``table`` (categoricals keep only used values)."""
    if table.empty:
        return responses
    out = responses[~responses["participant_id"].astype(str).isin(set(table["participant_id"]))].copy()
    for c in out.columns:
        if isinstance(out[c].dtype, pd.CategoricalDtype):
            out[c] = out[c].cat.remove_unused_categories()
    return out
