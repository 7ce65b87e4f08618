"""Screening on how each clip was watched (viewing.csv, read by :func:`analysis.io.read_viewing`): the answers
given without a full view, and three exclusion rules on the viewing record.

A *full view* is an answer whose clip reached its end before the answer (``ended_ms`` set). Only *trusted* records
are judged (:func:`recorded`): ``record`` = ``ok``, or, in an export from before the ``record`` column, at least one
field set. Answers with ``record`` ``no_script`` (a browser without JavaScript), ``missing`` (the answer came
without the record the page sends: not from the page) or ``implausible`` (a record the time on the page cannot
explain, e.g. more plays than fit in it) are neither full nor incomplete views: they are counted apart.

- **Record missing or implausible** (rule ``record_untrusted``): a participant is excluded when more than
  ``max_untrusted_share`` of all their answers have ``record`` ``missing`` or ``implausible`` (answers from a
  browser without JavaScript do not count against anyone).

- **Answered before the clip ended** (rule ``answered_before_end``): a participant is excluded when more than
  ``max_unended_share`` of their recorded answers were given before their clip had played to its end.
- **Tab hidden during playback** (rule ``tab_hidden``): a participant is excluded when more than
  ``max_hidden_share`` of their recorded answers had the page hidden (another tab, a minimised window) at least
  once while the clip played.

The thresholds default to 1.0 (a share can never be more than all: the rule is off) so a study opts in through
``Study.exclusion_rules``; the report states the thresholds and what each rule removed.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from protocol.vocabulary import VIEWING_FIELDS

COLUMNS = ["participant_id", "rule", "detail", "n_answers"]
"""Exclusion rows, as :data:`analysis.exclusion.COLUMNS`."""

INCOMPLETE_COLUMNS = ["participant_id", "clip_id", "section_type", "first_play_ms", "plays", "pauses", "seeks",
                      "hidden"]
"""Columns of :func:`incomplete_views` (the viewing.csv fields that say why the view was not full)."""


UNTRUSTED_RECORDS = ("missing", "implausible")
"""``record`` values that count against a participant (rule ``record_untrusted``)."""


def _records(viewing: pd.DataFrame) -> np.ndarray:
    """The ``record`` column as strings ('' where absent or blank: an export from before the column)."""
    if "record" not in viewing.columns:
        return np.full(len(viewing), "", dtype=object)
    return viewing["record"].fillna("").astype(str).str.strip().str.lower().to_numpy()


def recorded(viewing: pd.DataFrame) -> np.ndarray:
    """Rows (bool, one per answer) that carry a trusted viewing record: ``record`` ok, or (an export without the
    ``record`` column or with it blank) at least one field not blank."""
    records = _records(viewing)
    any_field = viewing[list(VIEWING_FIELDS)].notna().any(axis=1).to_numpy()
    return (records == "ok") | ((records == "") & any_field)


def untrusted(viewing: pd.DataFrame) -> np.ndarray:
    """Rows (bool) whose record is ``missing`` or ``implausible``."""
    return np.isin(_records(viewing), UNTRUSTED_RECORDS)


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
    records = _records(viewing)
    return {"n_answers": len(viewing), "n_recorded": int(rec.sum()), "n_full_view": int((rec & ended).sum()),
            "n_record_missing": int((records == "missing").sum()), "n_no_script": int((records == "no_script").sum()),
            "n_implausible": int((records == "implausible").sum()),
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


def untrusted_exclusions(viewing: pd.DataFrame, max_share: float) -> pd.DataFrame:
    """Participants with more than ``max_share`` of all their answers' records missing or implausible (rule
    ``record_untrusted``); exclusion rows (:data:`COLUMNS`), n_answers = all their answers."""
    d = pd.DataFrame({"p": viewing["participant_id"].astype(str).to_numpy(), "bad": untrusted(viewing)})
    g = d.groupby("p", sort=True)["bad"].agg(["sum", "size"])
    bad = g[g["sum"] > max_share * g["size"] + 1e-9]
    return pd.DataFrame({"participant_id": bad.index.to_numpy(dtype=object), "rule": "record_untrusted",
                         "detail": [f"{int(s)} of {int(n)} answers with the viewing record missing or implausible "
                                    f"(limit {max_share:.0%})" for s, n in zip(bad["sum"], bad["size"])],
                         "n_answers": bad["size"].to_numpy(int)}, columns=COLUMNS)


def viewing_exclusions(viewing: pd.DataFrame | None, max_unended_share: float = 1.0,
                       max_hidden_share: float = 1.0, max_untrusted_share: float = 1.0) -> tuple[pd.DataFrame, str]:
    """The three viewing rules (module docstring). Returns (exclusion rows, a sentence saying whether they
    applied): without viewing.csv they do not apply; the two on trusted records not when no answer has one."""
    empty = pd.DataFrame(columns=COLUMNS)
    if viewing is None:
        return empty, "viewing rules: not applicable (no viewing.csv)"
    n_rec = int(recorded(viewing).sum())
    flagged = untrusted_exclusions(viewing, max_untrusted_share) if max_untrusted_share < 1 else empty
    untrusted_note = (f"; record_untrusted applied to all {len(viewing)} answers" if max_untrusted_share < 1
                      else "")
    if not n_rec:
        return flagged, ("viewing rules: not applicable (no answer in viewing.csv has a viewing record)"
                         + untrusted_note)
    parts = [flagged,
             share_exclusions(viewing, viewing["ended_ms"].isna().to_numpy(), max_unended_share,
                              "answered_before_end", "given before the clip ended"),
             share_exclusions(viewing, viewing["hidden"].to_numpy(float) > 0, max_hidden_share, "tab_hidden",
                              "with the page hidden while the clip played")]
    parts = [p for p in parts if len(p)]
    table = pd.concat(parts, ignore_index=True) if parts else empty
    return table, (f"viewing rules: applied to the {n_rec} of {len(viewing)} answers with a viewing record"
                   + untrusted_note)
