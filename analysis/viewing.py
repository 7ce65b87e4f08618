"""Screening on how each clip was watched (viewing.csv, read by :func:`analysis.io.read_viewing`): the answers
given without a full view, and two exclusion rules on the viewing record.

A *full view* is an answer whose clip reached its end before the answer (``ended_ms`` set). Answers without a
record (every field blank: no JavaScript, an older page) are neither full nor incomplete views: they are counted
apart and never judged.

- **Answered before the clip ended** (rule ``answered_before_end``): a participant is excluded when more than
  ``max_unended_share`` of their recorded answers were given before their clip had played to its end.
- **Tab hidden during playback** (rule ``tab_hidden``): a participant is excluded when more than
  ``max_hidden_share`` of their recorded answers had the page hidden (another tab, a minimised window) at least
  once while the clip played.

Both thresholds default to 1.0 (a share can never be more than all: the rule is off) so a study opts in through
``Study.exclusion_rules``; the report states the thresholds and what each rule removed.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from study_protocol import VIEWING_FIELDS

COLUMNS = ["participant_id", "rule", "detail", "n_answers"]
"""Exclusion rows, as :data:`analysis.exclusion.COLUMNS`."""

INCOMPLETE_COLUMNS = ["participant_id", "clip_id", "section_type", "first_play_ms", "plays", "pauses", "seeks",
                      "hidden"]
"""Columns of :func:`incomplete_views` (the viewing.csv fields that say why the view was not full)."""


def recorded(viewing: pd.DataFrame) -> np.ndarray:
    """Rows (bool, one per answer) that carry a viewing record: at least one field not blank."""
    return viewing[list(VIEWING_FIELDS)].notna().any(axis=1).to_numpy()


def incomplete_views(viewing: pd.DataFrame) -> pd.DataFrame:
    """The recorded answers given before their clip reached its end (``ended_ms`` blank), in file order; columns
    :data:`INCOMPLETE_COLUMNS`."""
    mask = recorded(viewing) & viewing["ended_ms"].isna().to_numpy()
    return viewing.loc[mask, INCOMPLETE_COLUMNS].reset_index(drop=True)


def viewing_summary(viewing: pd.DataFrame | None) -> dict:
    """Counts over all answers of viewing.csv: answers, recorded, full views, without a full view, with the page
    hidden during playback, with a seek attempt, with a stall. {} without viewing.csv."""
    if viewing is None:
        return {}
    rec = recorded(viewing)
    ended = viewing["ended_ms"].notna().to_numpy()
    return {"n_answers": len(viewing), "n_recorded": int(rec.sum()), "n_full_view": int((rec & ended).sum()),
            "n_without_full_view": int((rec & ~ended).sum()),
            "n_hidden": int((viewing["hidden"].to_numpy(float) > 0).sum()),
            "n_seek_attempts": int((viewing["seeks"].to_numpy(float) > 0).sum()),
            "n_stalled": int((viewing["stalls"].to_numpy(float) > 0).sum())}


def share_exclusions(viewing: pd.DataFrame, flagged: np.ndarray, max_share: float, rule: str,
                     what: str) -> pd.DataFrame:
    """Participants with more than ``max_share`` of their recorded answers ``flagged`` (bool per row). Returns
    exclusion rows (:data:`COLUMNS`): rule, a detail naming ``what`` was counted, n_answers = recorded answers."""
    rec = recorded(viewing)
    d = pd.DataFrame({"p": viewing["participant_id"].astype(str).to_numpy()[rec], "bad": np.asarray(flagged)[rec]})
    g = d.groupby("p", sort=True)["bad"].agg(["sum", "size"])
    bad = g[g["sum"] > max_share * g["size"] + 1e-9]
    return pd.DataFrame({"participant_id": bad.index.to_numpy(dtype=object), "rule": rule,
                         "detail": [f"{int(s)} of {int(n)} recorded answers {what} (limit {max_share:.0%})"
                                    for s, n in zip(bad["sum"], bad["size"])],
                         "n_answers": bad["size"].to_numpy(int)}, columns=COLUMNS)


def viewing_exclusions(viewing: pd.DataFrame | None, max_unended_share: float = 1.0,
                       max_hidden_share: float = 1.0) -> tuple[pd.DataFrame, str]:
    """The two viewing rules (module docstring). Returns (exclusion rows, a sentence saying whether they applied):
    without viewing.csv, or when no answer has a record, they do not apply."""
    empty = pd.DataFrame(columns=COLUMNS)
    if viewing is None:
        return empty, "viewing rules: not applicable (no viewing.csv)"
    n_rec = int(recorded(viewing).sum())
    if not n_rec:
        return empty, "viewing rules: not applicable (no answer in viewing.csv has a viewing record)"
    parts = [share_exclusions(viewing, viewing["ended_ms"].isna().to_numpy(), max_unended_share,
                              "answered_before_end", "given before the clip ended"),
             share_exclusions(viewing, viewing["hidden"].to_numpy(float) > 0, max_hidden_share, "tab_hidden",
                              "with the page hidden while the clip played")]
    parts = [p for p in parts if len(p)]
    table = pd.concat(parts, ignore_index=True) if parts else empty
    return table, f"viewing rules: applied to the {n_rec} of {len(viewing)} answers with a viewing record"
