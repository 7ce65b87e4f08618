"""Agreement between participants: intraclass correlation of ratings, Fleiss' kappa of categorical choices.

- Ratings (affect_likert per feature, theme_rating per theme): ICC with clips as targets and participants as raters
  (Shrout & Fleiss 1979; McGraw & Wong 1996), the forms and 95% confidence intervals of
  ``pingouin.intraclass_corr`` (equal to it in the tests).
- Categorical choices (emotion_choice, emotion_transition, gesture_emotion, neutral_validation): Fleiss' kappa
  (Fleiss 1971; ``statsmodels.stats.inter_rater.fleiss_kappa``) on the clip x label table.

    P. E. Shrout, J. L. Fleiss. "Intraclass correlations: uses in assessing rater reliability." Psychological
    Bulletin 86(2), 420-428, 1979.  K. O. McGraw, S. P. Wong. "Forming inferences about some intraclass correlation
    coefficients." Psychological Methods 1(1), 30-46, 1996.  J. L. Fleiss. "Measuring nominal scale agreement
    among many raters." Psychological Bulletin 76(5), 378-382, 1971.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.stats import f as f_dist
from statsmodels.stats.inter_rater import fleiss_kappa as sm_fleiss_kappa

from protocol.section_types import registered
from protocol.vocabulary import LABEL_CHOICES, MULTI_SELECT_KINDS

from .recognition import selection_weights

COLUMNS = ["section_type", "question", "statistic", "value", "ci_low", "ci_high", "n_raters", "n_items", "subset",
           "note"]
"""Columns of the ``agreement`` table (report.json: section_type .. n_items as DESIGN.md, then subset, note)."""

N_BOOT = 2000


def icc_two_way(matrix) -> pd.DataFrame:
    """ICC(2,1) and ICC(2,k) of an (n targets, k raters) complete matrix: two-way random effects, absolute
    agreement (Shrout & Fleiss 1979 ICC(2,1)/ICC(2,k); McGraw & Wong ICC(A,1)/ICC(A,k)), with pingouin's F test
    and 95% confidence interval (McGraw & Wong 1996).

    Why this form: participants are a random sample of the raters we want to generalise to (random raters, so a
    two-way random model, not the fixed-rater ICC(3)), and the scale values themselves carry meaning (a 4 means
    "expanded" on every participant's scale), so agreement is absolute, not just consistency of ranks. ICC(2,1)
    answers "how much does one participant's rating agree with another's"; ICC(2,k) is the reliability of the
    mean over the k participants, the value the papers' per-clip means rest on.

    Computed from the two-way ANOVA mean squares in numpy (the same formulas as ``pingouin.intraclass_corr``, which
    fits a long-format ANOVA and is slow for 10,000 raters). Returns rows ICC2 and ICC2k: statistic, value, F,
    df1, df2, p_value, ci_low, ci_high.
    """
    x = np.asarray(matrix, float)
    n, k = x.shape
    gm = x.mean()
    ss_total = ((x - gm) ** 2).sum()
    ss_rows = k * ((x.mean(axis=1) - gm) ** 2).sum()
    ss_cols = n * ((x.mean(axis=0) - gm) ** 2).sum()
    msb = ss_rows / (n - 1)
    msj = ss_cols / (k - 1)
    mse = (ss_total - ss_rows - ss_cols) / ((n - 1) * (k - 1))
    icc2 = (msb - mse) / (msb + (k - 1) * mse + k * (msj - mse) / n)
    icc2k = (msb - mse) / (msb + (msj - mse) / n)
    fk = msb / mse
    df1, df2 = n - 1, (n - 1) * (k - 1)
    p = f_dist.sf(fk, df1, df2)
    fj = msj / mse
    vn = df2 * (k * icc2 * fj + n * (1 + (k - 1) * icc2) - k * icc2) ** 2
    vd = df1 * k**2 * icc2**2 * fj**2 + (n * (1 + (k - 1) * icc2) - k * icc2) ** 2
    v = vn / vd
    f2u = f_dist.ppf(0.975, n - 1, v)
    f2l = f_dist.ppf(0.975, v, n - 1)
    lo = n * (msb - f2u * mse) / (f2u * (k * msj + (k * n - k - n) * mse) + n * msb)
    hi = n * (f2l * msb - mse) / (k * msj + (k * n - k - n) * mse + n * f2l * msb)
    return pd.DataFrame({"statistic": ["ICC2", "ICC2k"], "value": [icc2, icc2k], "F": fk, "df1": df1, "df2": df2,
                         "p_value": p, "ci_low": [lo, lo * k / (1 + lo * (k - 1))],
                         "ci_high": [hi, hi * k / (1 + hi * (k - 1))]})


def fleiss_kappa(table) -> float:
    """Fleiss' (1971) kappa of an (items, categories) table of rating counts.

    With the same number of ratings per item this is ``statsmodels.stats.inter_rater.fleiss_kappa(table)``. With
    unequal numbers (participants see different subsets of clips) the same estimator with per-item agreement
    P_i = (sum_j n_ij^2 - n_i) / (n_i (n_i - 1)) averaged over items and chance sum_j p_j^2, p_j = the share of
    category j among all ratings (Fleiss, Levin & Paik 2003, section 18.1); it equals statsmodels' when the n_i are
    equal. Items with fewer than 2 ratings are left out. Fractional counts (multi-select answers weighted 1/k)
    are accepted; the value is then an approximation.
    """
    t = np.asarray(table, float)
    t = t[t.sum(axis=1) >= 2 - 1e-9]
    if len(t) < 2:
        return float("nan")
    n_i = t.sum(axis=1)
    p_j = t.sum(axis=0) / t.sum()
    pe = (p_j**2).sum()
    if pe >= 1 - 1e-12:  # every rating in one category: kappa undefined
        return float("nan")
    if np.allclose(n_i, n_i[0]):
        return float(sm_fleiss_kappa(t))
    p_i = ((t**2).sum(axis=1) - n_i) / (n_i * (n_i - 1))
    return float((p_i.mean() - pe) / (1 - pe))


def _bootstrap_items(table: np.ndarray, rng) -> tuple[float, float]:
    """Percentile 95% interval of Fleiss' kappa over items resampled with replacement."""
    n = len(table)
    vals = np.array([fleiss_kappa(table[rng.integers(0, n, n)]) for _ in range(N_BOOT)])
    vals = vals[np.isfinite(vals)]
    return (float(np.quantile(vals, 0.025)), float(np.quantile(vals, 0.975))) if len(vals) else (np.nan, np.nan)


def _record(section, question, statistic, value, lo, hi, n_raters, n_items, subset="", note=""):
    return dict(zip(COLUMNS, (section, question, statistic, value, lo, hi, n_raters, n_items, subset, note)))


def rating_icc(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    """ICC (:func:`icc_two_way`) of the ratings of every section type declared with ``agreement="icc"``
    (protocol.section_types), per question, split into rater sets by its ``agreement_by`` clip column: affect_likert
    per feature over the rated gait clips, theme_rating per theme over that theme's clips. Targets are clips, raters
    participants; a participant who rated a clip twice contributes the mean. ICC needs a complete matrix, so only
    participants who rated every clip of the set are raters (``note`` says how many were left out). Returns the
    ``agreement`` columns."""
    rows = []
    sets = []
    for spec in registered():
        if spec.agreement != "icc":
            continue
        for question in spec.question_kinds:
            r = responses[(responses["section_type"] == spec.name) & (responses["question"] == question)]
            if not spec.agreement_by:
                sets.append((spec.name, question, "", r))
            elif len(r):
                by = clips[spec.agreement_by].reindex(r["clip_id"].astype(str)).to_numpy()
                for value in sorted(pd.unique(by[pd.notna(by)])):
                    sets.append((spec.name, question, str(value), r[by == value]))
    for section, question, subset, r in sets:
        if r.empty:
            continue
        wide = (pd.DataFrame({"p": r["participant_id"].astype(str).to_numpy(), "c": r["clip_id"].astype(str).to_numpy(),
                              "v": r["value"].to_numpy(float)})
                .pivot_table(index="c", columns="p", values="v", aggfunc="mean"))
        complete = wide.dropna(axis=1)
        dropped = wide.shape[1] - complete.shape[1]
        note = f"{dropped} participant(s) without every clip left out" if dropped else ""
        n, k = complete.shape
        if n < 2 or k < 2:
            rows.append(_record(section, question, "ICC2", np.nan, np.nan, np.nan, k, n, subset,
                                (note + "; " if note else "") + "fewer than 2 clips or complete raters"))
            continue
        icc = icc_two_way(complete.to_numpy())
        for _, s in icc.iterrows():
            rows.append(_record(section, question, s["statistic"], s["value"], s["ci_low"], s["ci_high"], k, n,
                                subset, note))
    return pd.DataFrame(rows, columns=COLUMNS)


def choice_fleiss_kappa(responses: pd.DataFrame, seed: int = 0) -> pd.DataFrame:
    """Fleiss' kappa (:func:`fleiss_kappa`) of each categorical question (answer kinds of
    protocol.vocabulary.LABEL_CHOICES) of the section types declared with ``agreement="kappa"``: items = clips,
    categories = the question's labels, counts = answers (multi-select answers add 1/k to each of their k labels).
    95% interval: percentile bootstrap over clips (2000 resamples, seeded), NaN for fewer than 3 clips. Returns the
    ``agreement`` columns."""
    rng = np.random.default_rng(seed)
    rows = []
    for spec in registered():
        if spec.agreement != "kappa":
            continue
        section = spec.name
        for question, kind in spec.question_kinds.items():
            if kind not in LABEL_CHOICES:
                continue
            r = responses[(responses["section_type"] == section) & (responses["question"] == question)]
            if r.empty:
                continue
            labels = LABEL_CHOICES[kind]
            w = selection_weights(r["answer"], labels)
            codes, items = pd.factorize(r["clip_id"].astype(str), sort=True)
            table = np.zeros((len(items), len(labels)))
            np.add.at(table, codes, w)
            used = table[table.sum(axis=1) >= 2 - 1e-9]
            kappa = fleiss_kappa(table)
            lo, hi = _bootstrap_items(used, rng) if len(used) >= 3 else (np.nan, np.nan)
            note = "multi-select answers weighted 1/k" if kind in MULTI_SELECT_KINDS else ""
            if len(used) < 2:
                note = "fewer than 2 clips with 2 or more answers"
            rows.append(_record(section, question, "fleiss_kappa", kappa, lo, hi,
                                int(r["participant_id"].nunique()), len(used), "", note))
    return pd.DataFrame(rows, columns=COLUMNS)


def agreement(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    """The report's ``agreement`` table: :func:`rating_icc` then :func:`choice_fleiss_kappa`."""
    parts = [t for t in (rating_icc(responses, clips), choice_fleiss_kappa(responses)) if len(t)]
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=COLUMNS)
