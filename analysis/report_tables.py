"""The report-table registry: each table of the researcher report registered once, with its key, title, method
text, the function that computes it, its figures and its line in the summary.

``analysis.report`` reads the registry for everything it writes (report.json keys, one CSV per table, the figures,
the summary, the notes and the HTML sections, all in registration order). A section type's own analysis is one
:func:`register_table` call::

    register_table(ReportTable(key="arousal_means", title="Arousal by intended emotion", method="Mean rating ...",
                               compute=lambda d: arousal_means(d.responses, d.clips),
                               summary=lambda t, alpha: [f"Arousal: {len(t)} emotions rated."]))

Screening tables (who was excluded, what was removed, answers without a full view) are registered too, with
``compute`` None: :func:`analysis.report.build_report` fills them from the exclusion step.
"""
from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

import pandas as pd

from protocol.vocabulary import MODALITIES

from . import agreement, by_body, emotion, exclusion, likert, mixed, naturalness, norms, participants, themes, vad
from . import figures as figure_mod


@dataclass(frozen=True)
class TableInputs:
    """What a table's ``compute`` reads: the kept answers (after exclusions), the clips, the participants, the
    significance level and the permutation count of the permutation tests."""

    responses: pd.DataFrame
    clips: pd.DataFrame
    participants: pd.DataFrame
    alpha: float = 0.05
    permutations: int = 0


@dataclass(frozen=True)
class FigureSpec:
    """One report figure: its file stem (``fig_<name>``) and ``make(tables, extras) -> Figure | None``."""

    name: str
    make: Callable[[dict, dict], object]


@dataclass(frozen=True)
class ReportTable:
    """One table of the report, described once.

    Attributes:
        key: report.json key and CSV stem.
        title: the HTML heading.
        method: the method text shown under it (docs/analysis.md has the long form).
        compute: ``compute(TableInputs) -> DataFrame``; None for a screening table build_report fills.
        figures: the figures drawn from it (shown above the table).
        summary: ``summary(table, alpha) -> lines`` for the report's summary (only called for a non-empty table).
        preface_notes / notes: ``(table) -> lines`` for the report's notes, before / after the list of empty tables.
        records: ``records(table) -> list of dicts`` for report.json (default: one dict per row).
        caution: a sentence shown beside the table ("Read with care").
        screening: a table about the data rather than a finding (an empty one is not "no data").
        empty_html: what the HTML shows for an empty table.
    """

    key: str
    title: str
    method: str
    compute: Callable[[TableInputs], pd.DataFrame] | None = None
    figures: tuple[FigureSpec, ...] = ()
    summary: Callable[[pd.DataFrame, float], list[str]] | None = None
    preface_notes: Callable[[pd.DataFrame], list[str]] | None = None
    notes: Callable[[pd.DataFrame], list[str]] | None = None
    records: Callable[[pd.DataFrame], list[dict]] | None = None
    caution: str = ""
    screening: bool = False
    empty_html: str = "<p>No data.</p>"


_REGISTRY: dict[str, ReportTable] = {}


def register_table(table: ReportTable) -> ReportTable:
    """Add ``table`` to the registry (a key registers once); returns it."""
    if table.key in _REGISTRY and _REGISTRY[table.key] is not table:
        raise ValueError(f"report table {table.key!r} is registered already")
    if not table.screening and table.compute is None:
        raise ValueError(f"report table {table.key!r}: a finding needs a compute function")
    _REGISTRY[table.key] = table
    return table


def unregister_table(key: str) -> None:
    """Remove a table (tests that register toy tables clean up with this)."""
    _REGISTRY.pop(key, None)


def report_tables() -> tuple[ReportTable, ...]:
    """Registered tables, in registration order (the order of report.json, the CSVs and the HTML)."""
    return tuple(_REGISTRY.values())


def get_table(key: str) -> ReportTable:
    """The registered table ``key``; KeyError listing the registered keys."""
    try:
        return _REGISTRY[key]
    except KeyError:
        raise KeyError(f"no report table {key!r} (registered: {', '.join(_REGISTRY)})") from None


class TableKeys(Sequence):
    """Live tuple-like view of the registered keys (``analysis.report.TABLE_KEYS``)."""

    def __getitem__(self, i):
        return tuple(_REGISTRY)[i]

    def __len__(self) -> int:
        return len(_REGISTRY)

    def __iter__(self) -> Iterator[str]:
        return iter(tuple(_REGISTRY))

    def __contains__(self, key) -> bool:
        return key in _REGISTRY

    def __repr__(self) -> str:
        return repr(tuple(_REGISTRY))


# ---- the exclusion rules in words ------------------------------------------------------------------------------------
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


AD_LABEL_BLIND = ("It is label-blind: it compares two sets of four numbers without which emotion each number "
                  "belongs to, so intended happy (1,0,0,0) against perceived pure neutral (0,0,0,1) is not rejected; "
                  "whether emotions were recognised is answered by the recognition section (Wagner's Hu).")
"""One sentence shown beside seed 000's 4-value Anderson-Darling test wherever the report shows it."""


# ---- summary lines and notes of the built-in tables ---------------------------------------------------------------
def _ad_pure_notes(key: str) -> Callable[[pd.DataFrame], list[str]]:
    """The note on rejected clips with a single intended emotion (the AD test's floor)."""
    def notes(t: pd.DataFrame) -> list[str]:
        if t.empty:
            return []
        intended = t[[c for c in t.columns if c.startswith("intended_")]].to_numpy()
        pure = t.loc[t["reject"].to_numpy() & ((intended > 0).sum(axis=1) == 1), "clip_id"].unique()
        if not len(pure):
            return []
        return [f"{key}: rejected clip(s) {', '.join(map(str, pure))} have a single intended emotion; against any "
                "perceived vector with four non-zero components the 4-value AD test gives about 2.1, p ~ 0.04 (2.111 "
                "without ties, as seed 000's Gait 2) whatever their size. Judge the vectors in the figure."]
    return notes


def _gait_ad_summary(g: pd.DataFrame, alpha: float) -> list[str]:
    return [f"Seed 000's 4-value Anderson-Darling test, single emotions: for {int((~g['reject']).sum())} of {len(g)} "
            f"gaits the null hypothesis (intended and perceived emotion vectors from the same distribution) is not "
            f"rejected at alpha = {alpha}. {AD_LABEL_BLIND}"]


def _transition_summary(t: pd.DataFrame, alpha: float) -> list[str]:
    ok = t.groupby("clip_id")["reject"].any()
    return [f"Transitions (seed 000's AD test): not rejected for {int((~ok).sum())} of {len(ok)} gaits "
            "(initial and final)."]


def _likert_summary(lc: pd.DataFrame, alpha: float) -> list[str]:
    return [f"Pose affective features: consistency across participants rejected in {int(lc['reject'].sum())} of "
            f"{len(lc)} emotion x feature tests."]


def _naturalness_summary(n: pd.DataFrame, alpha: float) -> list[str]:
    return [f"Naturalness, {row['modality']} {row['origin']}: {row['share_at_least_3']:.1%} of {int(row['n'])}"
            f" ratings >= 3." for _, row in n.iterrows()]


def _naturalness_records(df: pd.DataFrame) -> list[dict]:
    """report.json's naturalness rows: the counts of ratings 1..5 as one object, then the rest."""
    recs = df.to_dict("records")
    for rec in recs:
        rec["counts"] = {str(k): int(rec[f"count_{k}"]) for k in naturalness.RATINGS}
    order = ["origin", "modality", "counts", "share_at_least_3", "n"]
    return [{**{k: rec[k] for k in order}, **{k: v for k, v in rec.items() if k not in order}} for rec in recs]


def _vad_summary(v: pd.DataFrame, alpha: float) -> list[str]:
    return ["Gesture VAD correlation: " + ", ".join(f"{r['dimension']} r = {r['r']:.2f}" for _, r in v.iterrows())
            + "."]


def _anova_summary(a: pd.DataFrame, alpha: float) -> list[str]:
    sig = a[a["p_gg"] < alpha]
    return [f"Theme RM-ANOVA: {len(sig)} of {len(a)} effects significant (Greenhouse-Geisser p < {alpha})."]


def _anova_notes(a: pd.DataFrame) -> list[str]:
    if len(a) and a["n_dropped"].max() > 0:
        return [f"Theme RM-ANOVA: participants with missing cells were dropped per theme "
                f"(up to {int(a['n_dropped'].max())} per theme)."]
    return []


def _inversion_summary(inv: pd.DataFrame, alpha: float) -> list[str]:
    return [f"Inversion: mean rating below 0 with p < {alpha} for {int(((inv['mean'] < 0) & inv['reject']).sum())} "
            f"of {len(inv)} themes."]


def _agreement_summary(ag: pd.DataFrame, alpha: float) -> list[str]:
    icc = ag[ag["statistic"] == "ICC2"].dropna(subset=["value"])
    fk = ag[ag["statistic"] == "fleiss_kappa"].dropna(subset=["value"])
    bits = []
    if len(icc):
        bits.append(f"single-rater ICC(2,1) of ratings {icc['value'].min():.2f} to {icc['value'].max():.2f}")
    if len(fk):
        bits.append("Fleiss' kappa " + ", ".join(f"{r['section_type']}/{r['question']} {r['value']:.2f}"
                                                 for _, r in fk.iterrows()))
    return ["Agreement between participants: " + "; ".join(bits) + "."] if bits else []


def _mixed_summary(mm: pd.DataFrame, alpha: float) -> list[str]:
    fx = mm[(mm["kind"] == "fixed") & (mm["term"] != "Intercept")]
    return [f"Mixed models (crossed random participant and clip intercepts): {int((fx['p_value'] < alpha).sum())} "
            f"of {len(fx)} fixed effects with p < {alpha}."]


def _clip_norm_figure(modality: str) -> FigureSpec:
    return FigureSpec(f"fig_clip_norms_{modality}", lambda t, x: figure_mod.fig_clip_norms(t["clip_norms"], modality))


# ---- the built-in tables, in report order ---------------------------------------------------------------------------
register_table(ReportTable(
    "exclusions", "Excluded participants and why", exclusion_method(exclusion.resolve_rules()), screening=True,
    empty_html="<p>No participant excluded.</p>"))
register_table(ReportTable(
    "exclusion_counts", "What each exclusion rule removed",
    "Per rule: participants it excludes and their answers (rows of responses.csv) removed; 'any rule' counts each "
    "excluded participant once.", screening=True, empty_html="<p>Nothing removed.</p>"))
register_table(ReportTable(
    "viewing_incomplete", "Answers given without a full view of the clip",
    "Answers with a viewing record (viewing.csv) given before the clip had played to its end (ended_ms blank): "
    "first_play_ms blank = never played; seeks = seek attempts; hidden = times the page was hidden while the clip "
    "played. Answers without a record are not listed.", screening=True,
    empty_html="<p>None (or no viewing.csv).</p>"))
register_table(ReportTable(
    "gait_emotion_ad", "Single gait emotions: seed 000's test, 2-sample Anderson-Darling of the 4 intended vs the 4 "
                       "perceived values (seed 000 6.3.1)",
    "Seed 000's test, kept for fidelity. Each answer -> indicator vector / number of labels; mean over answers, "
    "l1-normalised; scipy.stats.anderson_ksamp (midrank) on the 4 intended vs the 4 perceived components; p "
    "interpolated and capped to [0.001, 0.25]. " + AD_LABEL_BLIND,
    compute=lambda d: emotion.gait_emotion_ad(d.responses, d.clips, d.alpha, d.permutations),
    figures=(FigureSpec("fig_emotion_vectors", lambda t, x: figure_mod.fig_emotion_vectors(t["gait_emotion_ad"])),),
    summary=_gait_ad_summary, notes=_ad_pure_notes("gait_emotion_ad"), caution=AD_LABEL_BLIND))
register_table(ReportTable(
    "transition_ad", "Emotion transitions: seed 000's test, initial and final, 2-sample Anderson-Darling (seed 000 "
                     "6.3.2)",
    "As above, for question 'initial' vs happy..neutral and 'final' vs final_*.",
    compute=lambda d: emotion.transition_ad(d.responses, d.clips, d.alpha, d.permutations),
    figures=(FigureSpec("fig_transitions", lambda t, x: figure_mod.fig_transitions(t["transition_ad"])),),
    summary=_transition_summary, notes=_ad_pure_notes("transition_ad"), caution=AD_LABEL_BLIND))
register_table(ReportTable(
    "likert_consistency_ad", "Pose affective features: consistency across participants, k-sample Anderson-Darling "
                             "(seed 000 6.3.3)",
    "k samples = participants (each: all their values for gaits of that dominant intended emotion); midrank k-sample "
    "Anderson-Darling.",
    compute=lambda d: likert.likert_consistency_ad(d.responses, d.clips, d.alpha), summary=_likert_summary))
register_table(ReportTable(
    "likert_distribution", "Pose affective features: share of each Likert value (seed 000 Fig. 8)",
    "Share of each value 0..4 per dominant intended emotion and feature.",
    compute=lambda d: likert.likert_distribution(d.responses, d.clips),
    figures=(FigureSpec("fig_likert", lambda t, x: figure_mod.fig_likert(t["likert_distribution"])),)))
register_table(ReportTable(
    "naturalness", "Naturalness ratings by origin and modality (seed 000 6.3.4, seed 003 6.3.2)",
    "Counts and shares of ratings 1..5 per origin and modality; share >= 3 = satisfactory.",
    compute=lambda d: naturalness.naturalness(d.responses, d.clips),
    figures=(FigureSpec("fig_naturalness", lambda t, x: figure_mod.fig_naturalness(t["naturalness"])),),
    summary=_naturalness_summary, records=_naturalness_records))
register_table(ReportTable(
    "naturalness_test", "Naturalness: generated vs source",
    "Mann-Whitney U (two-sided) and chi-square with Yates correction on >= 3 vs < 3 (Fisher's exact when an expected "
    "count < 5).", compute=lambda d: naturalness.naturalness_test(d.responses, d.clips, d.alpha)))
register_table(ReportTable(
    "vad_pearson", "Gesture emotions: intended vs perceived VAD, Pearson r (seed 003 6.3.1)",
    "Intended (clip's emotion_label) and perceived words mapped to NRC-VAD; scipy.stats.pearsonr with 95% Fisher-z "
    "confidence interval; n = answers.", compute=lambda d: vad.vad_pearson(d.responses, d.clips),
    figures=(FigureSpec("fig_vad", lambda t, x: figure_mod.fig_vad(x["vad_pairs"], t["vad_pearson"])),),
    summary=_vad_summary))
register_table(ReportTable(
    "theme_anova", "Theme ratings: two-way RM-ANOVA weight x number of features (seed 004 Table IV)",
    "pingouin.rm_anova, within = weight x n_features, subject = participant; Greenhouse-Geisser corrected p; partial "
    "eta squared; participants with missing cells dropped.", compute=lambda d: themes.theme_anova(d.responses, d.clips),
    summary=_anova_summary, preface_notes=_anova_notes))
register_table(ReportTable(
    "theme_descriptives", "Theme ratings: normalised mean and SE per cell (seed 004 Fig. 7)",
    "Rating normalised (r - 1) / 6; mean and SE = SD/sqrt(n) over participants.",
    compute=lambda d: themes.theme_descriptives(d.responses, d.clips),
    figures=(FigureSpec("fig_theme_ratings", lambda t, x: figure_mod.fig_theme_ratings(t["theme_descriptives"])),)))
register_table(ReportTable(
    "theme_inversion", "Inverted themes: mean, SE and one-sample t-test against 0 (seed 004 Fig. 8)",
    "Per-participant mean per theme; mean, SE, one-sample t-test against 0 (two-sided).",
    compute=lambda d: themes.theme_inversion(d.responses, d.clips, d.alpha),
    figures=(FigureSpec("fig_inversion", lambda t, x: figure_mod.fig_inversion(t["theme_inversion"])),),
    summary=_inversion_summary))
register_table(ReportTable(
    "neutral_validation", "Neutral input walk: 7-way forced choice (seed 004 Table I)",
    "Share of each of the seven choices.", compute=lambda d: themes.neutral_validation(d.responses)))
register_table(ReportTable(
    "demographic_differences", "Perceived emotions across gender and age group, chi-square (seed 000 6.2)",
    "Pearson chi-square of group x perceived-label counts (no correction), Cramer's V; groups with < 5 selections "
    "left out.", compute=lambda d: participants.demographic_differences(d.responses, d.participants, d.alpha)))
register_table(ReportTable(
    "agreement", "Agreement between participants: ICC of ratings, Fleiss' kappa of choices",
    "Ratings: ICC(2,1) and ICC(2,k) (two-way random raters, absolute agreement; clips = targets, participants = "
    "raters; only participants who rated every clip of the set; F-based 95% CI as pingouin.intraclass_corr). "
    "Choices: Fleiss' kappa on the clip x label table (multi-select 1/k), 95% CI by bootstrap over clips.",
    compute=lambda d: agreement.agreement(d.responses, d.clips), summary=_agreement_summary))
register_table(ReportTable(
    "mixed_models", "Mixed models with crossed random intercepts (participant, clip) beside the papers' tests",
    "statsmodels MixedLM (REML), crossed random intercepts for participant and clip as variance components of a "
    "single group. Theme: rating ~ weight * n_features (centred, numeric) per theme; Likert: value ~ dominant "
    "intended emotion (reference neutral) per feature. Wald z tests; at most "
    f"{mixed.MAX_PARTICIPANTS} participants per model (seeded random sample).",
    compute=lambda d: mixed.mixed_models(d.responses, d.clips), summary=_mixed_summary))
register_table(ReportTable(
    "clip_norms", "Per-clip norms: perceived shares, intended share with its Wilson interval, entropy",
    "Per clip and question (analysis.norms): n_ratings; shares = the perceived vector (an answer selecting k labels "
    "adds 1/k to each; mean over the clip's answers); intended = the dominant intended label (gait: unique largest "
    "component >= 0.5; gesture: emotion_label; neutral validation: the theme); its share with the 95% Wilson score "
    "interval (statsmodels proportion_confint, method='wilson'; summed shares as successes); Shannon entropy in bits; "
    "seed 000's 2-sample Anderson-Darling test as gait_emotion_ad (gait emotion questions); mean norming intensity "
    "of the section; mean and n of the clip's naturalness answers. Written as clip_norms.csv (docs/study.md).",
    compute=lambda d: norms.clip_norms(d.responses, d.clips),
    figures=tuple(_clip_norm_figure(m) for m in MODALITIES)))
register_table(ReportTable(
    "by_body", "Recognition and naturalness by the human body shown (clips.csv body)",
    "Per body preset (clips.csv body) and measure: gait_emotion / gesture_emotion = overall hit rate (confusion "
    "matrix trace / total, k selected labels 1/k each) and Cohen's kappa; naturalness = share of ratings >= 3 and "
    "mean rating; n = answers. Clips without a body are left out.",
    compute=lambda d: by_body.by_body(d.responses, d.clips),
    empty_html="<p>No clip names a human body (clips.csv without a body column).</p>"))
