"""Per-clip norms: how each clip is perceived, from the answers of any study (a norming study, or a paper's).

One row per clip and normed question (:data:`NORMED_KINDS`: every label question -- gait emotions, gesture
emotions, the neutral validation choice -- and the theme scales), with the columns of
:data:`protocol.vocabulary.CLIP_NORMS_COLUMNS` then ``share_<label>`` for each label of the question's domain
(:func:`protocol.vocabulary.norms_domain`; cells of labels outside a row's domain are blank):

- ``n_ratings``: answers to the question for the clip (after the study's exclusion rules, which
  :func:`analysis.report.build_report` applies before calling :func:`clip_norms`);
- shares: the report's perceived vector -- each answer's selected labels weighted equally (an answer selecting k
  labels adds 1/k to each, l1 norm 1), averaged over the clip's answers (:func:`analysis.recognition.
  selection_weights`, the same vectors as :mod:`analysis.emotion`);
- ``intended``: the clip's dominant intended label -- gait: the unique largest of happy..neutral (``final_*`` for
  the question ``final``) when at least 0.5 (:func:`analysis.recognition.dominant_intended_label`); gesture: its
  ``emotion_label``; neutral validation: its theme (``neutral``); blank for theme scales and clips without one;
- ``top_label``, ``top_share``: the most chosen label (the first in the domain's order on a tie) and its share;
- ``intended_share`` with ``intended_ci_low``, ``intended_ci_high``: the 95 % Wilson score interval (Wilson 1927,
  statsmodels ``proportion_confint(method="wilson")``) of the intended label's share, from the share as the
  success rate and n_ratings as the trials when every answer chose one label; a multi-select answer counts 1/k
  per label, and then the trials are Kish's effective sample size (:func:`effective_n`), since fractional shares
  vary less than 0/1 answers (the plain count over-covers: 98 % instead of 95 % in bench_norms);
- ``entropy_bits``: Shannon entropy of the share vector in bits (scipy.stats.entropy, base 2; 0 = every answer
  the same single label, log2(L) = uniform);
- ``ad_statistic``, ``ad_p_value``: seed 000's 2-sample Anderson-Darling test of the 4 intended against the 4
  perceived components, computed exactly as :func:`analysis.emotion.gait_emotion_ad` (gait emotion questions only;
  label-blind, see the report's note);
- ``intensity_mean``: mean of the clip's norming ``intensity`` answers (1..5) in the same section;
  ``naturalness_mean``, ``naturalness_n``: mean and number of every ``naturalness`` answer (1..5) given to the clip
  in the study (a naturalness section's and a norming section's).

    E. B. Wilson. "Probable inference, the law of succession, and statistical inference." Journal of the American
    Statistical Association 22(158), 209-212, 1927.  L. Kish. *Survey Sampling*. Wiley, 1965.

:func:`read_clip_norms` reads a clip_norms.csv back (the pool rule ``norms``), checking every cell.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats
from statsmodels.stats.proportion import proportion_confint

from protocol.section_types.registry import LiveTuple
from protocol.vocabulary import (
    CLIP_NORMS_COLUMNS,
    FINAL_EMOTION_COLUMNS,
    GAIT_EMOTIONS,
    GAIT_MULTI,
    GESTURE_CHOICE,
    INVERSION,
    NEUTRAL_CHOICE,
    NORMS_SHARE_PREFIX,
    SECTION_QUESTIONS,
    THEME_RATING,
    norms_domain,
)

from .emotion import ad_2samp
from .io import Problem, ValidationError, _Collector, _read_raw
from .recognition import dominant_intended_label, selection_weights

NORMED_KINDS = (GAIT_MULTI, GESTURE_CHOICE, NEUTRAL_CHOICE, THEME_RATING, INVERSION)
"""Answer kinds whose per-clip distribution is normed: the label questions and the theme scales."""

NORMED_QUESTIONS = LiveTuple(lambda: tuple((s, q) for s, qs in SECTION_QUESTIONS.items() for q, kind in qs.items()
                                           if kind in NORMED_KINDS))
"""(section_type, question) pairs that get norms, in the protocol's order."""

CONFIDENCE = 0.95
SHARE_SUM_TOLERANCE = 1e-3
"""A row's shares must sum to 1 within this (clip_norms.csv is written with full float precision)."""


def share_column(label: str) -> str:
    return f"{NORMS_SHARE_PREFIX}{label}"


def _intended(clips: pd.DataFrame, section_type: str, question: str, domain: tuple[str, ...]) -> pd.Series:
    """clip_id -> intended label of the question (NaN where none)."""
    kind = SECTION_QUESTIONS[section_type][question]
    if kind == GAIT_MULTI:
        cols = FINAL_EMOTION_COLUMNS if question == "final" else GAIT_EMOTIONS
        return dominant_intended_label(clips[list(cols)].set_axis(list(GAIT_EMOTIONS), axis=1))
    column = {GESTURE_CHOICE: "emotion_label", NEUTRAL_CHOICE: "theme"}.get(kind)
    if column is None:
        return pd.Series(np.nan, index=clips.index, dtype=object)
    labels = clips[column].astype(str)
    return labels.where(labels.isin(domain))


def effective_n(p: np.ndarray, variance: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Kish's effective sample size of a mean share: n * p (1 - p) / variance of the per-answer shares (all (C,)).

    Single-label answers are 0 or 1, their variance is p (1 - p) and n_eff = n, so the interval is the plain
    Wilson interval. A multi-select answer gives 1/k to each of its k labels; the shares vary less than 0/1
    answers (variance <= p (1 - p), Bhatia-Davis), so n_eff >= n and the interval is narrower where the plain
    count would be conservative. Where the variance is 0 (every answer the same) or p is 0 or 1, n is kept.

        L. Kish. *Survey Sampling*. Wiley, 1965 (the design effect, section 8.2).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        out = n * p * (1 - p) / variance
    keep = ~np.isfinite(out) | (variance <= 1e-12) | (p <= 0) | (p >= 1)
    return np.where(keep, n, np.maximum(out, n))


def _group_means(codes: np.ndarray, values: np.ndarray, n_groups: int) -> tuple[np.ndarray, np.ndarray]:
    """Per-group (sum, count) of ``values`` (N,) or (N, L) for integer group ``codes`` (N,)."""
    sums = np.zeros((n_groups, *values.shape[1:]))
    np.add.at(sums, codes, values)
    return sums, np.bincount(codes, minlength=n_groups).astype(float)


def _clip_scale_means(responses: pd.DataFrame, mask: np.ndarray) -> pd.DataFrame:
    """clip_id -> mean and n of the ``value`` of the rows in ``mask``."""
    r = responses.loc[mask, ["clip_id", "value"]]
    g = r.assign(clip_id=r["clip_id"].astype(str)).groupby("clip_id", sort=False)["value"]
    return pd.DataFrame({"mean": g.mean(), "n": g.size()})


def _question_norms(responses: pd.DataFrame, clips: pd.DataFrame, section_type: str, question: str,
                    naturalness: pd.DataFrame) -> pd.DataFrame:
    sec = responses["section_type"].astype(str).to_numpy()
    qst = responses["question"].astype(str).to_numpy()
    r = responses[(sec == section_type) & (qst == question)]
    if r.empty:
        return pd.DataFrame()
    domain = norms_domain(section_type, question)
    weights = selection_weights(r["answer"], domain)                       # (N, L), rows sum to 1
    clip_codes, clip_ids = pd.factorize(r["clip_id"].astype(str).to_numpy(), sort=True)
    sums, n = _group_means(clip_codes, weights, len(clip_ids))
    shares = sums / n[:, None]
    shares /= shares.sum(axis=1, keepdims=True)
    c = clips.reindex(clip_ids)
    intended = _intended(c, section_type, question, domain).to_numpy(dtype=object)
    index = {lab: j for j, lab in enumerate(domain)}
    has = np.array([isinstance(x, str) for x in intended])
    j = np.array([index.get(x, 0) if ok else 0 for x, ok in zip(intended, has)], dtype=int)
    intended_share = np.where(has, shares[np.arange(len(j)), j], np.nan)
    low, high = np.full(len(j), np.nan), np.full(len(j), np.nan)
    if has.any():
        x = weights[np.arange(len(weights)), j[clip_codes]]                 # each answer's intended share
        mean_sq = _group_means(clip_codes, x ** 2, len(clip_ids))[0] / n
        n_eff = effective_n(intended_share, mean_sq - intended_share ** 2, n)
        low[has], high[has] = proportion_confint(intended_share[has] * n_eff[has], n_eff[has],
                                                 alpha=1 - CONFIDENCE, method="wilson")
    top = shares.argmax(axis=1)
    out = pd.DataFrame({
        "clip_id": clip_ids, "modality": c["modality"].to_numpy(), "section_type": section_type,
        "question": question, "n_ratings": n.astype(int),
        "intended": np.where(has, intended, None),
        "top_label": np.asarray(domain, dtype=object)[top], "top_share": shares[np.arange(len(top)), top],
        "intended_share": intended_share, "intended_ci_low": low, "intended_ci_high": high,
        "entropy_bits": stats.entropy(shares, base=2, axis=1),
        "ad_statistic": np.nan, "ad_p_value": np.nan,
    })
    if SECTION_QUESTIONS[section_type][question] == GAIT_MULTI:
        cols = FINAL_EMOTION_COLUMNS if question == "final" else GAIT_EMOTIONS
        want = c[list(cols)].to_numpy(float)
        for i in range(len(out)):
            if np.isfinite(want[i]).all():
                res = ad_2samp(want[i], shares[i])
                out.loc[i, ["ad_statistic", "ad_p_value"]] = res["statistic"], res["p_value"]
    intensity = _clip_scale_means(responses, (sec == section_type) & (qst == "intensity"))
    out["intensity_mean"] = intensity["mean"].reindex(clip_ids).to_numpy()
    out["naturalness_mean"] = naturalness["mean"].reindex(clip_ids).to_numpy()
    out["naturalness_n"] = naturalness["n"].reindex(clip_ids).fillna(0).astype(int).to_numpy()
    for k, label in enumerate(domain):
        out[share_column(label)] = shares[:, k]
    return out


def clip_norms(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    """Norms of every clip answered in ``responses`` (validated, :func:`analysis.io.read_responses`; the
    participants to keep already chosen) with ``clips`` (:func:`analysis.io.read_clips`).

    Returns one row per (clip, normed question), rows ordered by the protocol's sections and questions, then
    clip_id; columns :data:`protocol.vocabulary.CLIP_NORMS_COLUMNS` then ``share_<label>`` for the union of the domains
    present (in the order met). Empty (with the fixed columns) when no normed question was answered.
    """
    naturalness = _clip_scale_means(responses, (responses["question"].astype(str) == "naturalness").to_numpy())
    parts = [t for s, q in NORMED_QUESTIONS if not (t := _question_norms(responses, clips, s, q, naturalness)).empty]
    if not parts:
        return pd.DataFrame(columns=list(CLIP_NORMS_COLUMNS))
    shares = list(dict.fromkeys(col for t in parts for col in t.columns if col.startswith(NORMS_SHARE_PREFIX)))
    out = pd.concat(parts, ignore_index=True)
    return out[[*CLIP_NORMS_COLUMNS, *shares]]


# ---- reading clip_norms.csv back ------------------------------------------------------------------------
_NUMERIC = ("n_ratings", "top_share", "intended_share", "intended_ci_low", "intended_ci_high", "entropy_bits",
            "ad_statistic", "ad_p_value", "intensity_mean", "naturalness_mean", "naturalness_n")
_REQUIRED_CELLS = ("clip_id", "section_type", "question", "n_ratings", "top_label", "top_share")


def read_clip_norms(src, known_clips=None) -> pd.DataFrame:
    """Read and validate a clip_norms.csv (a path or text file object).

    Every problem is gathered into one :class:`analysis.io.ValidationError` naming file, line and column: a missing
    column of :data:`protocol.vocabulary.CLIP_NORMS_COLUMNS`; a blank required cell; a number that is not one; an
    unknown (section_type, question); with ``known_clips`` (an iterable of clip ids) a clip not among them; shares
    outside 0..1, a share of a label outside the question's domain, shares of a row that do not sum to 1 (within
    :data:`SHARE_SUM_TOLERANCE`), or a missing share column of a row's domain. Returns the rows with numeric
    columns as float (NaN where blank) and ``_line`` (file line number).
    """
    df, name = _read_raw(src, "clip_norms.csv")
    col = _Collector(name)
    missing = [c for c in CLIP_NORMS_COLUMNS if c not in df.columns]
    for c in missing:
        col.add(0, c, f"required column is missing (expected columns: {', '.join(CLIP_NORMS_COLUMNS)}, then "
                      f"{NORMS_SHARE_PREFIX}<label>)")
    if missing:
        raise ValidationError(col.problems, col.total)
    for c in CLIP_NORMS_COLUMNS:
        if c not in _NUMERIC:
            df[c] = df[c].str.strip()
    for c in _REQUIRED_CELLS:
        col.add_mask(df, (df[c].str.strip() == "").to_numpy(), c, f"{c} is empty")
    for c in _NUMERIC:
        raw = df[c].str.strip()
        value = pd.to_numeric(raw, errors="coerce")
        col.add_mask(df, ((raw != "") & value.isna()).to_numpy(), c, lambda v: f"{v!r} is not a number")
        df[c] = value
    share_cols = [c for c in df.columns if c.startswith(NORMS_SHARE_PREFIX)]
    shares = pd.DataFrame({c: pd.to_numeric(df[c].str.strip(), errors="coerce") for c in share_cols})
    for c in share_cols:
        raw = df[c].str.strip()
        col.add_mask(df, ((raw != "") & shares[c].isna()).to_numpy(), c, lambda v: f"{v!r} is not a number")
        col.add_mask(df, ((shares[c] < 0) | (shares[c] > 1)).to_numpy(), c, lambda v: f"share {v!r} is not in 0..1")
    if known_clips is not None:
        known = set(map(str, known_clips))
        col.add_mask(df, ~df["clip_id"].isin(known).to_numpy() & (df["clip_id"] != "").to_numpy(), "clip_id",
                     lambda v: f"unknown clip {v!r} (not in the catalogue)")
    pairs = df["section_type"].str.cat(df["question"], sep="|")
    for pair in pairs.unique():
        rows = (pairs == pair).to_numpy()
        section_type, _, question = pair.partition("|")
        if question not in SECTION_QUESTIONS.get(section_type, {}) or \
                SECTION_QUESTIONS[section_type][question] not in NORMED_KINDS:
            col.add_mask(df, rows, "question", f"({section_type!r}, {question!r}) is not a normed question "
                                               f"({', '.join(f'{s}/{q}' for s, q in NORMED_QUESTIONS)})")
            continue
        domain = [share_column(lab) for lab in norms_domain(section_type, question)]
        for c in domain:
            if c not in shares.columns:
                col.add_mask(df, rows, c, f"column {c} is missing (the shares of {section_type}/{question})")
        present = [c for c in domain if c in shares.columns]
        for c in share_cols:
            if c not in domain:
                col.add_mask(df, rows & shares[c].notna().to_numpy(), c,
                             f"{c} is not a label of {section_type}/{question}; leave it blank")
        if present:
            total = shares.loc[rows, present].sum(axis=1, min_count=1).to_numpy()
            bad = np.zeros(len(df), bool)
            bad[np.flatnonzero(rows)] = ~(np.abs(total - 1) <= SHARE_SUM_TOLERANCE)
            sums = dict(zip(np.flatnonzero(rows), total))
            lines = df["_line"].to_numpy()
            for i in np.flatnonzero(bad)[:20]:
                cells = shares.loc[df.index[i], present].dropna()
                col.add(int(lines[i]), ", ".join(cells.index) or ", ".join(present),
                        f"shares of {section_type}/{question} sum to {sums[i]:.4g}, not 1 "
                        f"({' + '.join(f'{v:.4g}' for v in cells)})")
            col.total += max(0, int(bad.sum()) - min(20, int(bad.sum())))
    if col.total:
        raise ValidationError(sorted(col.problems, key=lambda p: (p.line, p.column)), col.total)
    for c in share_cols:
        df[c] = shares[c]
    return df.reset_index(drop=True)


__all__ = ["NORMED_QUESTIONS", "Problem", "ValidationError", "clip_norms", "read_clip_norms", "share_column"]
