"""The researcher report: every analysis of the three papers from the three study exports.

:func:`write_report` reads and validates responses.csv, clips.csv and participants.csv, runs each analysis, and
writes into ``out_dir``:
- ``report.json`` (top-level keys of DESIGN.md plus ``transition_ad``-style extras, see :data:`TABLE_KEYS`),
- one CSV per table (``<key>.csv``), ``participants_summary.json``,
- figures ``fig_<name>.png`` and ``.svg``,
- ``report.html``, self-contained (CSS inline, figures as inline SVG).
Methods are described in docs/analysis.md and in each function's docstring.
"""

from __future__ import annotations

import datetime as _dt
import html
import io
import json
import math
import os
import re
import tempfile
import zipfile

import numpy as np
import pandas as pd

from protocol.vocabulary import MODALITIES

from . import (
    agreement,
    by_body,
    emotion,
    exclusion,
    likert,
    mixed,
    naturalness,
    norms,
    participants,
    recognition,
    themes,
    vad,
)
from . import figures as figure_mod
from . import viewing as viewing_mod
from .io import StudyData, load_study

TABLE_KEYS = ("exclusions", "exclusion_counts", "viewing_incomplete", "gait_emotion_ad", "transition_ad",
              "likert_consistency_ad", "likert_distribution",
              "naturalness", "naturalness_test", "vad_pearson", "theme_anova", "theme_descriptives", "theme_inversion",
              "neutral_validation", "demographic_differences", "agreement",
              "mixed_models", "clip_norms", "by_body")
"""Keys of report.json holding a list of records (one CSV each). ``participants``, ``viewing`` and ``meta`` are
objects."""
SCREENING_KEYS = ("exclusions", "exclusion_counts", "viewing_incomplete")
"""Tables about the data rather than findings: an empty one is not "no data for this analysis"."""

AD_LABEL_BLIND = ("It is label-blind: it compares two sets of four numbers without which emotion each number "
                  "belongs to, so intended happy (1,0,0,0) against perceived pure neutral (0,0,0,1) is not rejected; "
                  "whether emotions were recognised is answered by the recognition section (Wagner's Hu).")
"""One sentence shown beside seed 000's 4-value Anderson-Darling test wherever the report shows it."""

RECOGNITION_KEYS = {"gait_emotion": "Gait emotion (section emotion_choice)",
                    "gesture_emotion": "Gesture emotion (section gesture_emotion)"}
"""Keys of report.json ``recognition`` -> heading."""

RECOGNITION_METHOD = ("Confusion matrix, rows intended, columns perceived; an answer selecting k labels adds 1/k to "
                      "each. Gait: intended = the clip's dominant intended emotion (unique largest of happy..neutral, "
                      ">= 0.5; other clips left out); gesture: the clip's emotion_label. Hit rate = C_ii/row_i; "
                      "unbiased hit rate Hu = C_ii^2/(row_i col_i) and its chance value row_i col_i/N^2 (Wagner "
                      "1993); Cohen's kappa. Per participant: Hu and chance per emotion, arcsin(sqrt(x)), paired "
                      "t-test across participants (scipy.stats.ttest_rel), Holm-corrected across emotions.")

METHODS = {
    "exclusions": "",  # depends on the rules in force: exclusion_method()
    "exclusion_counts": "Per rule: participants it excludes and their answers (rows of responses.csv) removed; "
                        "'any rule' counts each excluded participant once.",
    "viewing_incomplete": "Answers with a viewing record (viewing.csv) given before the clip had played to its end "
                          "(ended_ms blank): first_play_ms blank = never played; seeks = seek attempts; hidden = "
                          "times the page was hidden while the clip played. Answers without a record are not "
                          "listed.",
    "gait_emotion_ad": "Seed 000's test, kept for fidelity. Each answer -> indicator vector / number of labels; "
                       "mean over answers, l1-normalised; scipy.stats.anderson_ksamp (midrank) on the 4 intended vs "
                       "the 4 perceived components; p interpolated and capped to [0.001, 0.25]. " + AD_LABEL_BLIND,
    "transition_ad": "As above, for question 'initial' vs happy..neutral and 'final' vs final_*.",
    "likert_consistency_ad": "k samples = participants (each: all their values for gaits of that dominant intended "
                             "emotion); midrank k-sample Anderson-Darling.",
    "likert_distribution": "Share of each value 0..4 per dominant intended emotion and feature.",
    "naturalness": "Counts and shares of ratings 1..5 per origin and modality; share >= 3 = satisfactory.",
    "naturalness_test": "Mann-Whitney U (two-sided) and chi-square with Yates correction on >= 3 vs < 3 "
                        "(Fisher's exact when an expected count < 5).",
    "vad_pearson": "Intended (clip's emotion_label) and perceived words mapped to NRC-VAD; scipy.stats.pearsonr "
                   "with 95% Fisher-z confidence interval; n = answers.",
    "theme_anova": "pingouin.rm_anova, within = weight x n_features, subject = participant; Greenhouse-Geisser "
                   "corrected p; partial eta squared; participants with missing cells dropped.",
    "theme_descriptives": "Rating normalised (r - 1) / 6; mean and SE = SD/sqrt(n) over participants.",
    "theme_inversion": "Per-participant mean per theme; mean, SE, one-sample t-test against 0 (two-sided).",
    "neutral_validation": "Share of each of the seven choices.",
    "demographic_differences": "Pearson chi-square of group x perceived-label counts (no correction), Cramer's V; "
                               "groups with < 5 selections left out.",
    "agreement": "Ratings: ICC(2,1) and ICC(2,k) (two-way random raters, absolute agreement; clips = targets, "
                 "participants = raters; only participants who rated every clip of the set; F-based 95% CI as "
                 "pingouin.intraclass_corr). Choices: Fleiss' kappa on the clip x label table (multi-select 1/k), "
                 "95% CI by bootstrap over clips.",
    "clip_norms": "Per clip and question (analysis.norms): n_ratings; shares = the perceived vector (an answer "
                  "selecting k labels adds 1/k to each; mean over the clip's answers); intended = the dominant "
                  "intended label (gait: unique largest component >= 0.5; gesture: emotion_label; neutral "
                  "validation: the theme); its share with the 95% Wilson score interval (statsmodels "
                  "proportion_confint, method='wilson'; summed shares as successes); Shannon entropy in bits; "
                  "seed 000's 2-sample Anderson-Darling test as gait_emotion_ad (gait emotion questions); mean "
                  "norming intensity of the section; mean and n of the clip's naturalness answers. Written as "
                  "clip_norms.csv (docs/study.md).",
    "mixed_models": "statsmodels MixedLM (REML), crossed random intercepts for participant and clip as variance "
                    "components of a single group. Theme: rating ~ weight * n_features (centred, numeric) per "
                    "theme; Likert: value ~ dominant intended emotion (reference neutral) per feature. Wald z "
                    f"tests; at most {mixed.MAX_PARTICIPANTS} participants per model (seeded random sample).",
    "by_body": "Per body preset (clips.csv body) and measure: gait_emotion / gesture_emotion = overall hit rate "
               "(confusion matrix trace / total, k selected labels 1/k each) and Cohen's kappa; naturalness = share "
               "of ratings >= 3 and mean rating; n = answers. Clips without a body are left out.",
}

def exclusion_method(rules: dict) -> str:
    """The exclusion rules in force (resolved, :func:`analysis.exclusion.resolve_rules`) in one paragraph."""
    straight = ("all" if rules["max_straightline"] >= 1 else f"at least {rules['max_straightline']:.0%}")
    return (f"Excluded before every analysis: participants with more than {rules['max_fast_share']:.0%} of timed "
            f"answers faster than {rules['min_rt_fraction']:g} x the clip duration (too_fast); with {straight} of at "
            f"least {rules['min_straight']} answers of a rating-scale section equal (straight_lining); who passed "
            f"less than {rules['min_attention_pass']:.0%} of their attention checks (failed_attention, when "
            "participants.csv has attention columns)" + _viewing_method(rules)
            + ". The participants summary describes everyone.")


def _viewing_method(rules: dict) -> str:
    """The viewing rules in force as the end of exclusion_method's sentence ('' when both are off)."""
    bits = [f"; with more than {rules[key]:.0%} of their recorded answers {what} ({rule}, from viewing.csv)"
            for key, rule, what in (("max_unended_share", "answered_before_end", "given before the clip ended"),
                                    ("max_hidden_share", "tab_hidden", "with the page hidden during playback"))
            if rules[key] < 1]
    if rules.get("max_untrusted_share", 1.0) < 1:
        bits.append(f"; with more than {rules['max_untrusted_share']:.0%} of their answers' viewing records missing "
                    "or implausible (record_untrusted, from viewing.csv)")
    return "".join(bits)


METHODS["exclusions"] = exclusion_method(exclusion.resolve_rules())

TITLES = {
    "exclusions": "Excluded participants and why",
    "exclusion_counts": "What each exclusion rule removed",
    "viewing_incomplete": "Answers given without a full view of the clip",
    "gait_emotion_ad": "Single gait emotions: seed 000's test, 2-sample Anderson-Darling of the 4 intended vs the 4 "
                       "perceived values (seed 000 6.3.1)",
    "transition_ad": "Emotion transitions: seed 000's test, initial and final, 2-sample Anderson-Darling (seed 000 "
                     "6.3.2)",
    "likert_consistency_ad": "Pose affective features: consistency across participants, k-sample Anderson-Darling "
                             "(seed 000 6.3.3)",
    "likert_distribution": "Pose affective features: share of each Likert value (seed 000 Fig. 8)",
    "naturalness": "Naturalness ratings by origin and modality (seed 000 6.3.4, seed 003 6.3.2)",
    "naturalness_test": "Naturalness: generated vs source",
    "vad_pearson": "Gesture emotions: intended vs perceived VAD, Pearson r (seed 003 6.3.1)",
    "theme_anova": "Theme ratings: two-way RM-ANOVA weight x number of features (seed 004 Table IV)",
    "theme_descriptives": "Theme ratings: normalised mean and SE per cell (seed 004 Fig. 7)",
    "theme_inversion": "Inverted themes: mean, SE and one-sample t-test against 0 (seed 004 Fig. 8)",
    "neutral_validation": "Neutral input walk: 7-way forced choice (seed 004 Table I)",
    "demographic_differences": "Perceived emotions across gender and age group, chi-square (seed 000 6.2)",
    "agreement": "Agreement between participants: ICC of ratings, Fleiss' kappa of choices",
    "mixed_models": "Mixed models with crossed random intercepts (participant, clip) beside the papers' tests",
    "clip_norms": "Per-clip norms: perceived shares, intended share with its Wilson interval, entropy",
    "by_body": "Recognition and naturalness by the human body shown (clips.csv body)",
}


def analyse(data: StudyData, alpha: float = 0.05, permutations: int = 0) -> tuple[dict, dict]:
    """Run every analysis on validated data. Returns (tables: key -> DataFrame, extras: participants summary,
    VAD pairs for the figure)."""
    r, c, p = data.responses, data.clips, data.participants
    tables = {
        "gait_emotion_ad": emotion.gait_emotion_ad(r, c, alpha, permutations),
        "transition_ad": emotion.transition_ad(r, c, alpha, permutations),
        "likert_consistency_ad": likert.likert_consistency_ad(r, c, alpha),
        "likert_distribution": likert.likert_distribution(r, c),
        "naturalness": naturalness.naturalness(r, c),
        "naturalness_test": naturalness.naturalness_test(r, c, alpha),
        "vad_pearson": vad.vad_pearson(r, c),
        "theme_anova": themes.theme_anova(r, c),
        "theme_descriptives": themes.theme_descriptives(r, c),
        "theme_inversion": themes.theme_inversion(r, c, alpha),
        "neutral_validation": themes.neutral_validation(r),
        "demographic_differences": participants.demographic_differences(r, p, alpha),
        "agreement": agreement.agreement(r, c),
        "mixed_models": mixed.mixed_models(r, c),
        "clip_norms": norms.clip_norms(r, c),
        "by_body": by_body.by_body(r, c),
    }
    extras = {"participants": participants.participant_summary(p, r), "vad_pairs": vad.vad_pairs(r, c),
              "recognition": {"gait_emotion": recognition.gait_recognition(r, c, alpha),
                              "gesture_emotion": recognition.gesture_recognition(r, c, alpha)}}
    return tables, extras


def _clean(v):
    """numpy/pandas scalars -> JSON types; NaN/inf/NaT -> None."""
    if isinstance(v, dict):
        return {str(k): _clean(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_clean(x) for x in v]
    if isinstance(v, (np.bool_, bool)):
        return bool(v)
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return None if not math.isfinite(float(v)) else float(v)
    if v is pd.NaT or v is None:
        return None
    return v


def _records(df: pd.DataFrame, key: str) -> list[dict]:
    recs = df.to_dict("records")
    if key == "naturalness":
        for rec in recs:
            rec["counts"] = {str(k): int(rec[f"count_{k}"]) for k in naturalness.RATINGS}
        order = ["origin", "modality", "counts", "share_at_least_3", "n"]
        recs = [{**{k: rec[k] for k in order}, **{k: v for k, v in rec.items() if k not in order}} for rec in recs]
    return _clean(recs)


def _recognition_summary(name: str, res: dict, alpha: float) -> str | None:
    if not res or res["n_answers"] == 0:
        return None
    rates = res["rates"].set_index("label")
    tests = res["participant_tests"]
    above = tests[tests["reject"] & (tests["mean_diff_asin"] > 0)]
    hits = ", ".join(f"{lab} {rates.loc[lab, 'hit_rate']:.2f}" for lab in res["labels"]
                     if np.isfinite(rates.loc[lab, "hit_rate"]))
    hu = ", ".join(f"{lab} {rates.loc[lab, 'unbiased_hit_rate']:.2f} "
                   f"(chance {rates.loc[lab, 'chance_unbiased_hit_rate']:.2f})"
                   for lab in res["labels"] if rates.loc[lab, "n"] > 0)
    return (f"{name} recognition ({res['n_answers']} answers): hit rate {hits}; unbiased hit rate Hu {hu}; Hu above "
            f"chance (paired t on arcsine, Holm, alpha = {alpha}) for {len(above)} of "
            f"{int(tests['p_value'].notna().sum())} emotions; Cohen's kappa = {res['kappa']:.2f}.")


def _viewing_sentence(summary: dict) -> str:
    """One summary line on how the clips were watched (analysis.viewing.viewing_summary)."""
    if not summary:
        return "Viewing: no viewing.csv given; answers were not screened on how the clips were watched."
    if not summary["n_recorded"]:
        return f"Viewing: none of the {summary['n_answers']} answers in viewing.csv has a viewing record."
    return (f"Viewing: {summary['n_without_full_view']} of {summary['n_recorded']} answers with a viewing record "
            f"were given without a full view of the clip; {summary['n_hidden']} had the page hidden during playback, "
            f"{summary['n_seek_attempts']} a seek attempt, {summary['n_stalled']} a stall"
            + (f" ({summary['n_answers'] - summary['n_recorded']} answers without a trusted record"
               + _untrusted_counts(summary) + ")" if summary["n_answers"] > summary["n_recorded"] else "") + ".")


def _untrusted_counts(summary: dict) -> str:
    """': 2 missing, 1 implausible, 3 without JavaScript' for the record markers that occur ('' for none)."""
    parts = [f"{summary.get(key, 0)} {what}" for key, what in (("n_record_missing", "missing"),
                                                                ("n_implausible", "implausible"),
                                                                ("n_no_script", "without JavaScript"))
             if summary.get(key, 0)]
    return (": " + ", ".join(parts)) if parts else ""


def _summary(tables: dict, parts: dict, alpha: float, recog: dict | None = None, exclude: bool = True,
             viewing: dict | None = None) -> list[str]:
    """Plain-language headline findings: recognition first, then the papers' tests."""
    out = []
    for key, res in (recog or {}).items():
        line = _recognition_summary(RECOGNITION_KEYS[key].split(" (")[0], res, alpha)
        if line:
            out.append(line)
    g = tables["gait_emotion_ad"]
    if len(g):
        out.append(f"Seed 000's 4-value Anderson-Darling test, single emotions: for {int((~g['reject']).sum())} of "
                   f"{len(g)} gaits the null hypothesis (intended and perceived emotion vectors from the same "
                   f"distribution) is not rejected at alpha = {alpha}. {AD_LABEL_BLIND}")
    t = tables["transition_ad"]
    if len(t):
        ok = t.groupby("clip_id")["reject"].any()
        out.append(f"Transitions (seed 000's AD test): not rejected for {int((~ok).sum())} of {len(ok)} gaits "
                   "(initial and final).")
    lc = tables["likert_consistency_ad"]
    if len(lc):
        out.append(f"Pose affective features: consistency across participants rejected in {int(lc['reject'].sum())} "
                   f"of {len(lc)} emotion x feature tests.")
    n = tables["naturalness"]
    for _, row in n.iterrows():
        out.append(f"Naturalness, {row['modality']} {row['origin']}: {row['share_at_least_3']:.1%} of {int(row['n'])}"
                   f" ratings >= 3.")
    v = tables["vad_pearson"]
    if len(v):
        out.append("Gesture VAD correlation: " + ", ".join(f"{r['dimension']} r = {r['r']:.2f}"
                                                            for _, r in v.iterrows()) + ".")
    a = tables["theme_anova"]
    if len(a):
        sig = a[a["p_gg"] < alpha]
        out.append(f"Theme RM-ANOVA: {len(sig)} of {len(a)} effects significant (Greenhouse-Geisser p < {alpha}).")
    inv = tables["theme_inversion"]
    if len(inv):
        out.append(f"Inversion: mean rating below 0 with p < {alpha} for "
                   f"{int(((inv['mean'] < 0) & inv['reject']).sum())} of {len(inv)} themes.")
    ag = tables.get("agreement", pd.DataFrame())
    if len(ag):
        icc = ag[ag["statistic"] == "ICC2"].dropna(subset=["value"])
        fk = ag[ag["statistic"] == "fleiss_kappa"].dropna(subset=["value"])
        bits = []
        if len(icc):
            bits.append(f"single-rater ICC(2,1) of ratings {icc['value'].min():.2f} to {icc['value'].max():.2f}")
        if len(fk):
            bits.append("Fleiss' kappa " + ", ".join(f"{r['section_type']}/{r['question']} {r['value']:.2f}"
                                                     for _, r in fk.iterrows()))
        if bits:
            out.append("Agreement between participants: " + "; ".join(bits) + ".")
    mm = tables.get("mixed_models", pd.DataFrame())
    if len(mm):
        fx = mm[(mm["kind"] == "fixed") & (mm["term"] != "Intercept")]
        out.append(f"Mixed models (crossed random participant and clip intercepts): "
                   f"{int((fx['p_value'] < alpha).sum())} of {len(fx)} fixed effects with p < {alpha}.")
    ex = tables.get("exclusions", pd.DataFrame())
    if exclude:
        by_rule = ex.groupby("rule")["participant_id"].nunique().to_dict() if len(ex) else {}
        out.append(f"Exclusions: {parts.get('n_excluded', 0)} of {parts.get('n_participants', 0)} participants "
                   "excluded before the analyses" + (" (" + ", ".join(f"{k}: {v}" for k, v in by_rule.items()) + ")"
                                                      if by_rule else "") + ".")
        if ex.attrs.get("attention", "").startswith("failed_attention: not applicable"):
            out.append("Attention checks: " + ex.attrs["attention"].split(": ", 1)[1] + ".")
        counts = tables.get("exclusion_counts", pd.DataFrame())
        if len(counts) > 1:
            out.append("Removed per rule: " + "; ".join(f"{r['rule']}: {r['participants']} participant(s), "
                                                        f"{r['answers']} answers" for _, r in counts.iterrows()) + ".")
    else:
        out.append("Exclusions: not applied (--no-exclusions).")
    out.append(_viewing_sentence(viewing or {}))
    if parts.get("synthetic"):
        out.insert(0, "SYNTHETIC DATA: every participant is simulated (ids 'sim-'); these are not findings.")
    return out


def _exclusion_meta(exclude: bool, given: dict | None, rules: dict, excl: pd.DataFrame) -> dict:
    """report.json ``meta.exclusion_rules``: applied or not, where the thresholds come from, each threshold, and
    whether the attention-check rule could apply."""
    out = {"applied": exclude, "source": "study settings" if given else "defaults", **rules,
           "given": dict(given or {}), "method": exclusion_method(rules)}
    if exclude:
        out["attention"] = excl.attrs.get("attention", "")
        out["viewing"] = excl.attrs.get("viewing", "")
    return out


def build_report(data: StudyData, alpha: float = 0.05, permutations: int = 0,
                 exclude: bool = True, exclusion_rules: dict | None = None) -> tuple[dict, dict, dict]:
    """Analyse and assemble the report dict. Returns (report, tables, extras).

    ``exclude`` (default True) applies the exclusion rules of :mod:`analysis.exclusion` before every analysis; the
    table ``exclusions`` lists who was excluded and why, the participants summary still describes everyone.
    ``exclusion_rules`` (a study's ``Study.exclusion_rules``; None or {} = the defaults) sets their thresholds;
    ValueError naming the key when it is not valid (:func:`analysis.exclusion.rule_errors`)."""
    if not 0 < alpha < 1:
        raise ValueError(f"alpha must be in (0, 1), not {alpha}")
    if permutations < 0:
        raise ValueError(f"permutations must be >= 0, not {permutations}")
    rules = exclusion.resolve_rules(exclusion_rules)
    excl = (exclusion.exclusions(data.responses, data.clips, participants=data.participants, rules=rules,
                                 viewing=data.viewing)
            if exclude else pd.DataFrame(columns=exclusion.COLUMNS))
    kept = StudyData(exclusion.apply_exclusions(data.responses, excl), data.clips, data.participants,
                     data.ignored_columns, data.viewing)
    tables, extras = analyse(kept, alpha, permutations)
    tables["exclusions"] = excl
    tables["exclusion_counts"] = (exclusion.removed_counts(data.responses, excl) if exclude
                                  else pd.DataFrame(columns=["rule", "participants", "answers"]))
    tables["viewing_incomplete"] = (viewing_mod.incomplete_views(data.viewing) if data.viewing is not None
                                    else pd.DataFrame(columns=viewing_mod.INCOMPLETE_COLUMNS))
    viewing_summary = viewing_mod.viewing_summary(data.viewing)
    if len(excl):
        extras["participants"] = participants.participant_summary(data.participants, data.responses)
    extras["participants"]["n_excluded"] = int(excl["participant_id"].nunique())
    report = {k: _records(tables[k], k) for k in TABLE_KEYS}
    report["participants"] = _clean(extras["participants"])
    report["viewing"] = _clean(viewing_summary)
    report["recognition"] = {k: _clean(recognition.recognition_json(v)) for k, v in extras["recognition"].items()}
    notes = []
    a = tables["theme_anova"]
    if len(a) and a["n_dropped"].max() > 0:
        notes.append(f"Theme RM-ANOVA: participants with missing cells were dropped per theme "
                     f"(up to {int(a['n_dropped'].max())} per theme).")
    for k in TABLE_KEYS:
        if tables[k].empty and k not in SCREENING_KEYS:
            notes.append(f"{k}: no data for this analysis in responses.csv.")
    for key in ("gait_emotion_ad", "transition_ad"):
        t = tables[key]
        if t.empty:
            continue
        intended = t[[c for c in t.columns if c.startswith("intended_")]].to_numpy()
        pure = t.loc[t["reject"].to_numpy() & ((intended > 0).sum(axis=1) == 1), "clip_id"].unique()
        if len(pure):
            notes.append(f"{key}: rejected clip(s) {', '.join(map(str, pure))} have a single intended emotion; "
                         "against any perceived vector with four non-zero components the 4-value AD test gives about "
                         "2.1, p ~ 0.04 (2.111 without ties, as seed 000's Gait 2) whatever their size. Judge the "
                         "vectors in the figure.")
    for name, cols in data.ignored_columns.items():
        notes.append(f"{name}: unknown column(s) not used: {', '.join(cols)}.")
    synthetic = bool(extras["participants"].get("synthetic"))
    if synthetic:
        notes.insert(0, "synthetic: all participants are simulated by analysis.simulate; not data from people.")
    report["meta"] = _clean({
        "generated_at": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "alpha": alpha, "permutations": permutations, "synthetic": synthetic,
        "exclusion_rules": _exclusion_meta(exclude, exclusion_rules, rules, excl),
        "n_responses": len(data.responses), "n_clips": len(data.clips), "n_participants": len(data.participants),
        "summary": _summary(tables, extras["participants"], alpha, extras["recognition"], exclude, viewing_summary),
        "notes": notes,
        "methods": "docs/analysis.md",
    })
    return report, tables, extras


def _make_figures(tables: dict, extras: dict) -> dict:
    return {
        "fig_emotion_vectors": figure_mod.fig_emotion_vectors(tables["gait_emotion_ad"]),
        "fig_transitions": figure_mod.fig_transitions(tables["transition_ad"]),
        "fig_likert": figure_mod.fig_likert(tables["likert_distribution"]),
        "fig_vad": figure_mod.fig_vad(extras["vad_pairs"], tables["vad_pearson"]),
        "fig_naturalness": figure_mod.fig_naturalness(tables["naturalness"]),
        "fig_theme_ratings": figure_mod.fig_theme_ratings(tables["theme_descriptives"]),
        "fig_inversion": figure_mod.fig_inversion(tables["theme_inversion"]),
        "fig_confusion": figure_mod.fig_confusion({RECOGNITION_KEYS[k].split(" (")[0]: v
                                                   for k, v in extras["recognition"].items()}),
        **{f"fig_clip_norms_{m}": figure_mod.fig_clip_norms(tables["clip_norms"], m) for m in MODALITIES},
    }


def write_report(responses_csv, clips_csv, participants_csv, out_dir, alpha: float = 0.05,
                 permutations: int = 0, *, figures: bool = True, exclude: bool = True,
                 exclusion_rules: dict | None = None, viewing_csv=None) -> dict:
    """Validate the three exports (paths or text file objects), analyse, and write the report folder.

    ``figures=False`` skips the PNG/SVG figures (the HTML then has tables only); the analyses are the same.
    ``exclude=False`` analyses every participant (no exclusion rules, :mod:`analysis.exclusion`);
    ``exclusion_rules`` are a study's thresholds (``Study.exclusion_rules``), stated in the report.
    ``viewing_csv`` (optional) is viewing.csv: the report then lists the answers given without a full view and the
    viewing exclusion rules can apply.
    Raises :class:`analysis.io.ValidationError` (listing file, line and column of each problem) on invalid input.
    Returns the report dict (also written as ``out_dir/report.json``).
    """
    data = load_study(responses_csv, clips_csv, participants_csv, viewing_csv)
    report, tables, extras = build_report(data, alpha, permutations, exclude, exclusion_rules)
    os.makedirs(out_dir, exist_ok=True)
    for k in TABLE_KEYS:
        tables[k].to_csv(os.path.join(out_dir, f"{k}.csv"), index=False)
    for k, res in extras["recognition"].items():
        recognition.recognition_table(res).to_csv(os.path.join(out_dir, f"recognition_{k}.csv"), index=False)
        res["confusion"].to_csv(os.path.join(out_dir, f"confusion_{k}.csv"))
    with open(os.path.join(out_dir, "participants_summary.json"), "w") as f:
        json.dump(report["participants"], f, indent=2)
    figs = {}
    if figures:
        for name, fig in _make_figures(tables, extras).items():
            if fig is not None:
                figs[name] = figure_mod.save_figure(fig, out_dir, name)
    report["meta"]["figures"] = {k: {t: os.path.basename(p) for t, p in v.items()} for k, v in figs.items()}
    with open(os.path.join(out_dir, "report.json"), "w") as f:
        json.dump(report, f, indent=1, allow_nan=False)
    with open(os.path.join(out_dir, "report.html"), "w", encoding="utf-8") as f:
        f.write(render_html(report, tables, figs, extras))
    return report


def report_zip_bytes(responses_csv, clips_csv, participants_csv, alpha: float = 0.05, permutations: int = 0,
                     *, figures: bool = True, exclude: bool = True,
                     exclusion_rules: dict | None = None, viewing_csv=None) -> tuple[dict, bytes]:
    """Run :func:`write_report` into a temporary folder and return (report dict, the folder as a zip archive's
    bytes) -- for a download view. Raises ValidationError like write_report."""
    with tempfile.TemporaryDirectory() as tmp:
        report = write_report(responses_csv, clips_csv, participants_csv, tmp, alpha, permutations, figures=figures,
                              exclude=exclude, exclusion_rules=exclusion_rules, viewing_csv=viewing_csv)
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
            for name in sorted(os.listdir(tmp)):
                zf.write(os.path.join(tmp, name), arcname=f"report/{name}")
    return report, buf.getvalue()


CSS = """body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.5em}h2{font-size:1.15em;margin-top:2em;border-bottom:1px solid #ccc}
table{border-collapse:collapse;font-size:.8em;margin:.5em 0}td,th{border:1px solid #ddd;padding:2px 6px;
text-align:right}th{background:#f3f3f3}.banner{background:#fff3cd;border:1px solid #e0c36a;padding:.6em 1em;
font-weight:bold}.fig svg{max-width:100%;height:auto}details{margin:.3em 0}ul.summary li{margin:.2em 0}
.wide{overflow-x:auto}.method{color:#555;font-size:.85em}.tables{display:flex;flex-wrap:wrap;gap:1.5em;align-items:flex-start}"""

FIG_FOR_TABLE = {"clip_norms": tuple(f"fig_clip_norms_{m}" for m in MODALITIES),
                 "gait_emotion_ad": "fig_emotion_vectors", "transition_ad": "fig_transitions",
                 "likert_distribution": "fig_likert", "vad_pearson": "fig_vad", "naturalness": "fig_naturalness",
                 "theme_descriptives": "fig_theme_ratings", "theme_inversion": "fig_inversion"}
MAX_HTML_ROWS = 60
EMPTY_TABLE_HTML = {"exclusions": "<p>No participant excluded.</p>", "exclusion_counts": "<p>Nothing removed.</p>",
                    "viewing_incomplete": "<p>None (or no viewing.csv).</p>",
                    "by_body": "<p>No clip names a human body (clips.csv without a body column).</p>"}


def _inline_svg(path: str) -> str:
    with open(path, encoding="utf-8") as f:
        svg = f.read()
    svg = re.sub(r"^<\?xml[^>]*>\s*", "", svg)
    return re.sub(r"^<!DOCTYPE[^>]*>\s*", "", svg)


def _table_html(df: pd.DataFrame) -> str:
    shown = df.head(MAX_HTML_ROWS)
    body = "<div class='wide'>" + shown.to_html(index=False, na_rep="", float_format=lambda x: f"{x:.4g}",
                                                border=0) + "</div>"
    if len(df) > MAX_HTML_ROWS:
        body = (f"<details><summary>{len(df)} rows (first {MAX_HTML_ROWS} shown; all in the CSV)</summary>"
                f"{body}</details>")
    return body


def _participants_html(ps: dict) -> str:
    def fmt(v):
        return "" if v is None else f"{v:.4g}" if isinstance(v, float) else str(v)

    scalars = [(k, ps[k]) for k in ("n_participants", "n_completed", "completion_rate", "n_with_responses",
                                    "n_responses", "responses_per_participant", "synthetic") if k in ps]
    dur, ms = ps.get("duration_s", {}), ps.get("response_ms", {})
    scalars += [("duration_s median (completed)", dur.get("median")), ("duration_s q25..q75",
                f"{fmt(dur.get('q25'))} .. {fmt(dur.get('q75'))}"), ("response_ms median", ms.get("median"))]
    out = ["<div class='tables'><table><tbody>"]
    out += [f"<tr><th>{html.escape(k)}</th><td>{html.escape(fmt(v))}</td></tr>" for k, v in scalars]
    out.append("</tbody></table>")
    for key in ("status", "gender", "age_group"):
        rows = "".join(f"<tr><td>{html.escape(k)}</td><td>{v}</td></tr>" for k, v in ps.get(key, {}).items())
        out.append(f"<table><thead><tr><th>{key}</th><th>n</th></tr></thead><tbody>{rows}</tbody></table>")
    cross = ps.get("gender_by_age_group", {})
    if cross:
        ages = sorted({a for row in cross.values() for a in row})
        head = "".join(f"<th>{html.escape(a)}</th>" for a in ages)
        rows = "".join(f"<tr><th>{html.escape(g)}</th>" + "".join(f"<td>{row.get(a, 0)}</td>" for a in ages)
                       + "</tr>" for g, row in cross.items())
        out.append(f"<table><thead><tr><th>gender \\ age</th>{head}</tr></thead><tbody>{rows}</tbody></table>")
    out.append("</div>")
    return "".join(out)


def _recognition_html(extras: dict, figs: dict) -> str:
    h = html.escape
    out = ["<h2 id='recognition'>Emotion recognition against chance: hit rate, unbiased hit rate (Wagner 1993), "
           f"Cohen's kappa</h2><p class='method'>{h(RECOGNITION_METHOD)}</p>"]
    if "fig_confusion" in figs:
        out.append(f"<div class='fig'>{_inline_svg(figs['fig_confusion']['svg'])}</div>")
    for key, res in extras.get("recognition", {}).items():
        out.append(f"<h3>{h(RECOGNITION_KEYS[key])}</h3>")
        if not res or res["n_answers"] == 0:
            out.append("<p>No data.</p>")
            continue
        out.append(f"<p>{res['n_answers']} answers ({res.get('n_excluded', 0)} left out: no intended label); "
                   f"Cohen's kappa = {res['kappa']:.3f}.</p><div class='tables'>")
        out.append(_table_html(recognition.recognition_table(res)))
        out.append("<div class='wide'>" + res["confusion"].to_html(float_format=lambda x: f"{x:.4g}", border=0)
                   + "</div></div>")
    return "".join(out)


def render_html(report: dict, tables: dict, figs: dict, extras: dict | None = None) -> str:
    """A self-contained HTML page: summary, recognition, participants, each table with its figure inline (SVG)."""
    meta = report["meta"]
    h = html.escape
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>Study report</title>"
             f"<style>{CSS}</style></head><body><h1>Perceptual study report</h1>"]
    if meta.get("synthetic"):
        parts.append("<p class='banner'>SYNTHETIC DATA: all participants were simulated (analysis.simulate). "
                     "Nothing here describes real people.</p>")
    parts.append(f"<p>Generated {h(meta['generated_at'])}; alpha = {meta['alpha']}; permutations = "
                 f"{meta['permutations']}; {meta['n_participants']} participants, {meta['n_responses']} answers, "
                 f"{meta['n_clips']} clips. Methods: docs/analysis.md.</p>")
    parts.append("<h2>Summary</h2><ul class='summary'>" + "".join(f"<li>{h(s)}</li>" for s in meta["summary"])
                 + "</ul>")
    if meta["notes"]:
        parts.append("<h2>Notes</h2><ul>" + "".join(f"<li>{h(s)}</li>" for s in meta["notes"]) + "</ul>")
    if extras:
        parts.append(_recognition_html(extras, figs))
    parts.append("<h2>Participants</h2>" + _participants_html(report["participants"]))
    for k in TABLE_KEYS:
        method = meta.get("exclusion_rules", {}).get("method") if k == "exclusions" else None
        parts.append(f"<h2 id='{k}'>{h(TITLES[k])}</h2><p class='method'>{h(method or METHODS[k])}</p>")
        if k == "exclusions" and meta.get("exclusion_rules", {}).get("applied"):
            ex_meta = meta["exclusion_rules"]
            parts.append(f"<p class='method'>Thresholds from the {h(ex_meta['source'])}. "
                         f"{h(ex_meta.get('attention', ''))}. {h(ex_meta.get('viewing', ''))}.</p>")
        df = tables[k]
        if df.empty:
            parts.append(EMPTY_TABLE_HTML.get(k, "<p>No data.</p>"))
            continue
        shown = FIG_FOR_TABLE.get(k, ())
        for fig in (shown,) if isinstance(shown, str) else shown:
            if fig in figs:
                parts.append(f"<div class='fig'>{_inline_svg(figs[fig]['svg'])}</div>")
        if k in ("gait_emotion_ad", "transition_ad"):
            parts.append(f"<p class='method'><b>Read with care:</b> {h(AD_LABEL_BLIND)}</p>")
        parts.append(_table_html(df))
    parts.append("</body></html>")
    return "\n".join(parts)
