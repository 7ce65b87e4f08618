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

A study's own thresholds (``Study.exclusion_rules``, a JSON object) replace the defaults; :func:`rule_errors` checks
such an object (the Study admin form calls it) and :func:`exclusions` applies it. Keys (:data:`RULES`):
``min_rt_fraction`` (the too-fast factor above), ``max_fast_share``, ``max_straightline`` (a participant is excluded
when at least this share of their answers in a rating-scale section have one value; 1.0 = all of them),
``min_straight`` (answers a section needs before straight-lining is judged) and ``min_attention_pass``
(**Failed attention checks**: excluded when ``attention_passed / attention_total`` of participants.csv is below it;
when the export has no such columns, or a participant met no check, the rule does not apply and the report says so),
and the three rules on how the clips were watched (viewing.csv, :mod:`analysis.viewing`; off unless set below 1):
``max_unended_share`` (answered before the clip ended), ``max_hidden_share`` (tab hidden during playback) and
``max_untrusted_share`` (viewing record missing or implausible).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from protocol.section_types.registry import LiveTuple
from protocol.vocabulary import ATTENTION_COLUMNS, INTEGER_RANGES, SECTION_QUESTIONS, attention_passed

from .viewing import viewing_exclusions

SCALE_SECTIONS = LiveTuple(lambda: tuple(s for s, qs in SECTION_QUESTIONS.items()
                                         if all(k in INTEGER_RANGES for k in qs.values())))
"""Sections whose answers are points of a rating scale (protocol.vocabulary: every question of an integer kind)."""

FAST_FRACTION, MAX_FAST_SHARE, MIN_STRAIGHT = 0.25, 0.5, 8
MAX_STRAIGHTLINE, MIN_ATTENTION_PASS = 1.0, 1.0
COLUMNS = ["participant_id", "rule", "detail", "n_answers"]


RULES: dict[str, tuple[type, float, float, float, str]] = {
    "min_rt_fraction": (float, 0.0, 10.0, FAST_FRACTION, "an answer faster than this x the clip duration is too fast"),
    "max_fast_share": (float, 0.0, 1.0, MAX_FAST_SHARE, "excluded when more than this share of answers is too fast"),
    "max_straightline": (float, 0.5, 1.0, MAX_STRAIGHTLINE, "excluded when at least this share of a rating-scale "
                                                            "section's answers have one value"),
    "min_straight": (int, 2, 10_000, MIN_STRAIGHT, "answers a section needs before straight-lining is judged"),
    "min_attention_pass": (float, 0.0, 1.0, MIN_ATTENTION_PASS, "excluded when the share of attention checks "
                                                                "passed is below this"),
    "max_unended_share": (float, 0.0, 1.0, 1.0, "excluded when more than this share of answers with a viewing record "
                                                "came before the clip ended (1 = off)"),
    "max_hidden_share": (float, 0.0, 1.0, 1.0, "excluded when more than this share of answers with a viewing record "
                                               "had the page hidden while the clip played (1 = off)"),
    "max_untrusted_share": (float, 0.0, 1.0, 1.0, "excluded when more than this share of answers have their viewing "
                                                  "record missing or implausible (1 = off)"),
}
"""Exclusion rule key -> (type, lowest, highest, default, meaning). ``Study.exclusion_rules`` uses these keys."""


def rule_errors(rules) -> list[str]:
    """Every problem of an exclusion-rules object (``Study.exclusion_rules``), each message naming its key; [] when
    usable. Keys must be among :data:`RULES`, values numbers (integers for ``min_straight``) within their range;
    an empty object means the defaults."""
    if rules is None:
        return []
    if not isinstance(rules, dict):
        return [f"exclusion rules must be a JSON object of rule: number, got {type(rules).__name__}"]
    errors = []
    for key, value in rules.items():
        if key not in RULES:
            errors.append(f"unknown exclusion rule {key!r} (rules: {', '.join(RULES)})")
            continue
        kind, lo, hi, _, meaning = RULES[key]
        ok_type = (isinstance(value, int) if kind is int else isinstance(value, (int, float))) \
            and not isinstance(value, bool)
        if not ok_type:
            errors.append(f"{key!r} takes {'an integer' if kind is int else 'a number'}, got {value!r} ({meaning})")
        elif not (lo <= value <= hi) or value != value:
            errors.append(f"{key!r} must be between {lo:g} and {hi:g}, got {value!r} ({meaning})")
    return errors


def resolve_rules(rules: dict | None = None) -> dict:
    """The defaults of :data:`RULES` updated with ``rules``; ValueError listing :func:`rule_errors` when invalid."""
    errors = rule_errors(rules)
    if errors:
        raise ValueError("exclusion rules: " + "; ".join(errors))
    out = {key: spec[3] for key, spec in RULES.items()}
    out.update({k: RULES[k][0](v) for k, v in (rules or {}).items()})
    return out


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


def straight_lining(responses: pd.DataFrame, min_straight: int = MIN_STRAIGHT,
                    max_straightline: float = MAX_STRAIGHTLINE) -> pd.DataFrame:
    """Participants who gave one and the same value to at least ``max_straightline`` (default 1.0: all) of at least
    ``min_straight`` answers of a rating-scale section (:data:`SCALE_SECTIONS`). Returns rows participant_id, rule
    ``straight_lining``, detail, n_answers."""
    r = responses[responses["section_type"].isin(list(SCALE_SECTIONS))]
    # only each section's own scale questions: a norming section's intensity and naturalness are other scales
    own = r["section_type"].astype(str).str.cat(r["question"].astype(str), sep="|").isin(
        {f"{s}|{q}" for s in SCALE_SECTIONS for q in SECTION_QUESTIONS[s]})
    r = r[own.to_numpy()]
    d = pd.DataFrame({"p": r["participant_id"].astype(str).to_numpy(), "s": r["section_type"].astype(str).to_numpy(),
                      "v": r["value"].to_numpy(float)}).dropna(subset=["v"])
    per_value = d.groupby(["p", "s", "v"], sort=True).size().rename("k").reset_index()
    modal = per_value.sort_values(["p", "s", "k", "v"], ascending=[True, True, False, True], kind="stable")
    modal = modal.drop_duplicates(["p", "s"]).set_index(["p", "s"])
    n = d.groupby(["p", "s"], sort=True).size()
    g = modal.assign(size=n.reindex(modal.index).to_numpy())
    bad = g[(g["size"] >= min_straight) & (g["k"] >= max_straightline * g["size"] - 1e-9)].reset_index()
    return pd.DataFrame({"participant_id": bad["p"].to_numpy(dtype=object), "rule": "straight_lining",
                         "detail": [f"all {int(n)} answers of {s} are {v:g}" if k == n else
                                    f"{int(k)} of {int(n)} answers of {s} are {v:g} (limit {max_straightline:.0%})"
                                    for s, n, v, k in zip(bad["s"], bad["size"], bad["v"], bad["k"])],
                         "n_answers": bad["size"].to_numpy(int)}, columns=COLUMNS)


def attention_counts(checks) -> pd.DataFrame:
    """Attention-check answers (responses.csv rows of section_type ATTENTION_CHECK: participant_id, question,
    answer; a DataFrame or a dict of lists as analysis.io keeps them) -> participants.csv-like rows participant_id +
    :data:`ATTENTION_COLUMNS` (passed, total)."""
    passed_col, total_col = ATTENTION_COLUMNS
    checks = pd.DataFrame(checks)
    ok = [attention_passed(q, a) for q, a in zip(checks["question"].astype(str), checks["answer"].astype(str))]
    g = pd.DataFrame({"participant_id": checks["participant_id"].astype(str).to_numpy(), "ok": ok}).groupby(
        "participant_id", sort=True)["ok"].agg(["sum", "size"])
    return pd.DataFrame({"participant_id": g.index.to_numpy(dtype=object), passed_col: g["sum"].to_numpy(int),
                         total_col: g["size"].to_numpy(int)})


def attention_failures(participants: pd.DataFrame | None, min_attention_pass: float = MIN_ATTENTION_PASS,
                       checks=None) -> tuple[pd.DataFrame, str]:
    """Participants who passed less than ``min_attention_pass`` of their attention checks (participants.csv columns
    :data:`ATTENTION_COLUMNS`: passed, total; without them, counted from the attention-check answers ``checks``).
    Returns (rows participant_id, rule ``failed_attention``, detail, n_answers = checks met; a sentence saying
    whether and to whom the rule applied). Without either the rule does not apply; participants with a blank or
    zero total are not judged."""
    passed_col, total_col = ATTENTION_COLUMNS
    if participants is None or passed_col not in participants.columns or total_col not in participants.columns:
        if checks is not None and len(pd.DataFrame(checks)):
            participants = attention_counts(checks)
        else:
            return pd.DataFrame(columns=COLUMNS), (f"failed_attention: not applicable (participants.csv has no "
                                                   f"{passed_col}/{total_col} columns)")
    ids = participants["participant_id"].astype(str).to_numpy() if "participant_id" in participants.columns \
        else participants.index.astype(str).to_numpy()
    passed = pd.to_numeric(participants[passed_col], errors="coerce").to_numpy(float)
    total = pd.to_numeric(participants[total_col], errors="coerce").to_numpy(float)
    judged = np.isfinite(passed) & np.isfinite(total) & (total > 0)
    share = np.where(judged, passed / np.where(judged, total, 1.0), np.nan)
    bad = judged & (share < min_attention_pass - 1e-9)
    table = pd.DataFrame({"participant_id": ids[bad].astype(object), "rule": "failed_attention",
                          "detail": [f"passed {int(a)} of {int(t)} attention checks (need {min_attention_pass:.0%})"
                                     for a, t in zip(passed[bad], total[bad])],
                          "n_answers": total[bad].astype(int)}, columns=COLUMNS)
    if not judged.any():
        return table, "failed_attention: not applicable (no participant met an attention check)"
    return table, (f"failed_attention: applied to the {int(judged.sum())} of {len(ids)} participants who met an "
                   f"attention check")


def exclusions(responses: pd.DataFrame, clips: pd.DataFrame, fast_fraction: float = FAST_FRACTION,
               max_fast_share: float = MAX_FAST_SHARE, min_straight: int = MIN_STRAIGHT, *,
               participants: pd.DataFrame | None = None, rules: dict | None = None,
               viewing: pd.DataFrame | None = None) -> pd.DataFrame:
    """Who is excluded and why: one row per participant and rule that applies (a participant may have several).
    Columns participant_id, rule (too_fast | straight_lining | failed_attention | answered_before_end |
    tab_hidden | record_untrusted), detail, n_answers.

    ``rules`` (a ``Study.exclusion_rules`` object, checked by :func:`rule_errors`; ValueError when invalid) replaces
    the keyword thresholds; ``participants`` (participants.csv) enables the attention-check rule and ``viewing``
    (viewing.csv) the viewing rules. The sentences on their applicability are in ``table.attrs["attention"]`` and
    ``table.attrs["viewing"]``."""
    r = resolve_rules(rules)
    if rules is not None:
        fast_fraction, max_fast_share, min_straight = r["min_rt_fraction"], r["max_fast_share"], r["min_straight"]
    max_straightline, min_attention = r["max_straightline"], r["min_attention_pass"]
    attention, attention_note = attention_failures(participants, min_attention, responses.attrs.get("attention_checks"))
    watched, viewing_note = viewing_exclusions(viewing, r["max_unended_share"], r["max_hidden_share"],
                                               r["max_untrusted_share"])
    parts = [t for t in (fast_answers(responses, clips, fast_fraction, max_fast_share),
                         straight_lining(responses, min_straight, max_straightline), attention, watched) if len(t)]
    if not parts:
        out = pd.DataFrame(columns=COLUMNS)
    else:
        out = pd.concat(parts, ignore_index=True).sort_values(["participant_id", "rule"], kind="stable").reset_index(
            drop=True)
    out.attrs["attention"] = attention_note
    out.attrs["viewing"] = viewing_note
    return out


def removed_counts(responses: pd.DataFrame, table: pd.DataFrame) -> pd.DataFrame:
    """What each exclusion rule removed: rows rule, participants (excluded by this rule), answers (their rows of
    responses.csv), and a last row ``any rule`` for the union (a participant hit by two rules counts once there)."""
    pid = responses["participant_id"].astype(str)
    per_participant = pid.value_counts()
    rows = []
    groups = [(rule, set(g["participant_id"].astype(str))) for rule, g in table.groupby("rule", sort=True)]
    for rule, people in [*groups, ("any rule", set(table["participant_id"].astype(str)))]:
        rows.append({"rule": rule, "participants": len(people),
                     "answers": int(per_participant.reindex(sorted(people)).fillna(0).sum())})
    return pd.DataFrame(rows, columns=["rule", "participants", "answers"])


def apply_exclusions(responses: pd.DataFrame, table: pd.DataFrame) -> pd.DataFrame:
    """``responses`` without the answers of the participants in ``table`` (categoricals keep only used values)."""
    if table.empty:
        return responses
    out = responses[~responses["participant_id"].astype(str).isin(set(table["participant_id"]))].copy()
    for c in out.columns:
        if isinstance(out[c].dtype, pd.CategoricalDtype):
            out[c] = out[c].cat.remove_unused_categories()
    return out
