"""Linear mixed models with crossed random intercepts for participant and clip, beside the papers' tests.

The papers analyse ratings with RM-ANOVA over participants' cell means (seed 004) or treat answers as independent
(seed 000); both ignore that clips are a sample too. A model with crossed random effects for participants and
items (Baayen, Davidson & Bates 2008) generalises over both:

    rating_pc = X_pc beta + u_p + w_c + e_pc,   u_p ~ N(0, s2_participant), w_c ~ N(0, s2_clip), e ~ N(0, s2)

Fitted by REML with statsmodels MixedLM in its documented recipe for crossed effects: a single group holding all
rows, with the two random intercepts as variance components (``vc_formula={"participant": "0 + C(participant)",
"clip": "0 + C(clip)"}``, ``re_formula="0"``).

    R. H. Baayen, D. J. Davidson, D. M. Bates. "Mixed-effects modeling with crossed random effects for subjects and
    items." Journal of Memory and Language 59(4), 390-412, 2008.

Models of the report:
- :func:`theme_mixed_models`: per theme, theme_rating ~ weight x n_features (both numeric, centred at their means
  over the theme's clips, so the main effects are slopes at the average of the other factor);
- :func:`likert_mixed_models`: per feature (torso, arms, pace, flow), affect_likert value ~ the clip's dominant
  intended emotion (treatment coding, reference neutral).
The single-group fit works with dense n x n matrices, so large studies are fitted on a random sample of
``max_participants`` participants (seeded; ``n_participants`` in the table says how many were used).
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import statsmodels.formula.api as smf

from protocol.vocabulary import GAIT_EMOTIONS, LIKERT_FEATURES

from .likert import dominant_emotion

MAX_PARTICIPANTS = 60
"""Participants used per model at most (a seeded random sample beyond that): statsmodels fits a single group of
all rows, about 1 s per model at 1,000 rows, so the cap keeps the 10,000-participant report in its time budget."""

COLUMNS = ["model", "subset", "kind", "term", "estimate", "se", "z", "p_value", "ci_low", "ci_high", "n_obs",
           "n_participants", "n_clips", "converged"]
"""Columns of the ``mixed_models`` table: kind is ``fixed`` (a coefficient) or ``variance`` (participant, clip,
residual variance; se/z/p blank)."""


def crossed_mixed_model(data: pd.DataFrame, formula: str, model: str = "", subset: str = "") -> pd.DataFrame:
    """Fit ``formula`` (a patsy formula on ``data``'s columns) with crossed random intercepts for columns
    ``participant`` and ``clip`` (statsmodels MixedLM, single group + variance components, REML).

    Returns tidy rows (:data:`COLUMNS`): every fixed effect with its Wald se, z, p and 95% interval, then the
    variance components participant, clip and residual.
    """
    d = data.assign(_group=1)
    n_obs, n_p, n_c = len(d), d["participant"].nunique(), d["clip"].nunique()
    base = {"model": model, "subset": subset, "n_obs": n_obs, "n_participants": n_p, "n_clips": n_c}
    vc = {"participant": "0 + C(participant)", "clip": "0 + C(clip)"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = smf.mixedlm(formula, d, groups="_group", re_formula="0", vc_formula=vc).fit(
            reml=True, method=["lbfgs", "bfgs", "cg"])  # tried in turn until one converges
    ci = fit.conf_int()
    rows = []
    for term in fit.fe_params.index:
        rows.append({**base, "kind": "fixed", "term": _term_name(term), "estimate": fit.fe_params[term],
                     "se": fit.bse_fe[term], "z": fit.tvalues[term], "p_value": fit.pvalues[term],
                     "ci_low": ci.loc[term, 0], "ci_high": ci.loc[term, 1], "converged": bool(fit.converged)})
    vcomp = dict(zip(fit.model.exog_vc.names, np.atleast_1d(fit.vcomp)))
    for name in ("participant", "clip"):
        rows.append({**base, "kind": "variance", "term": name, "estimate": vcomp.get(name, np.nan),
                     "converged": bool(fit.converged)})
    rows.append({**base, "kind": "variance", "term": "residual", "estimate": fit.scale,
                 "converged": bool(fit.converged)})
    return pd.DataFrame(rows, columns=COLUMNS)


def _term_name(term: str) -> str:
    """Patsy's "C(emotion, Treatment('neutral'))[T.happy]" -> "emotion[happy]"; other names unchanged."""
    if term.startswith("C(") and "[T." in term:
        var = term[2:].split(",")[0].split(")")[0]
        return f"{var}[{term.split('[T.', 1)[1].rstrip(']')}]"
    return term


def _sample_participants(d: pd.DataFrame, max_participants: int, seed: int) -> pd.DataFrame:
    ids = np.sort(d["participant"].unique())
    if len(ids) <= max_participants:
        return d
    keep = np.random.default_rng(seed).choice(ids, max_participants, replace=False)
    return d[d["participant"].isin(keep)]


def theme_mixed_models(responses: pd.DataFrame, clips: pd.DataFrame, max_participants: int = MAX_PARTICIPANTS,
                       seed: int = 0) -> pd.DataFrame:
    """Per theme: rating ~ weight_c * n_features_c + (1 | participant) + (1 | clip), section ``theme_rating``
    (seed 004's design; the RM-ANOVA's factors as numeric predictors, centred). Tidy rows (:data:`COLUMNS`)."""
    r = responses[responses["section_type"] == "theme_rating"]
    if r.empty:
        return pd.DataFrame(columns=COLUMNS)
    cid = r["clip_id"].astype(str)
    d = pd.DataFrame({"participant": r["participant_id"].astype(str).to_numpy(), "clip": cid.to_numpy(),
                      "rating": r["value"].to_numpy(float),
                      "theme": clips["theme"].reindex(cid).to_numpy(),
                      "weight": clips["weight"].reindex(cid).to_numpy(float),
                      "n_features": clips["n_features"].reindex(cid).to_numpy(float)})
    out = []
    for theme, g in d.groupby("theme", sort=True):
        g = _sample_participants(g, max_participants, seed)
        if g["clip"].nunique() < 2 or g["participant"].nunique() < 2:
            continue
        g = g.assign(weight_c=g["weight"] - g["weight"].mean(), n_features_c=g["n_features"] - g["n_features"].mean())
        terms = [t for t in ("weight_c", "n_features_c") if g[t].std() > 0]
        rhs = " * ".join(terms) if terms else "1"
        out.append(crossed_mixed_model(g, f"rating ~ {rhs}", "theme_rating ~ weight * n_features", str(theme)))
    return pd.concat(out, ignore_index=True) if out else pd.DataFrame(columns=COLUMNS)


def likert_mixed_models(responses: pd.DataFrame, clips: pd.DataFrame, max_participants: int = MAX_PARTICIPANTS,
                        seed: int = 0) -> pd.DataFrame:
    """Per Likert feature: value ~ C(emotion, reference neutral) + (1 | participant) + (1 | clip), section
    ``affect_likert``; emotion = the clip's dominant intended emotion (:func:`analysis.likert.dominant_emotion`,
    as in the Likert tables). Tidy rows (:data:`COLUMNS`)."""
    r = responses[responses["section_type"] == "affect_likert"]
    if r.empty:
        return pd.DataFrame(columns=COLUMNS)
    cid = r["clip_id"].astype(str)
    d = pd.DataFrame({"participant": r["participant_id"].astype(str).to_numpy(), "clip": cid.to_numpy(),
                      "feature": r["question"].astype(str).to_numpy(), "value": r["value"].to_numpy(float),
                      "emotion": dominant_emotion(clips).reindex(cid).to_numpy()})
    d = d[d["emotion"].notna()]
    sampled = _sample_participants(d, max_participants, seed)
    out = []
    for feature in LIKERT_FEATURES:
        g = sampled[sampled["feature"] == feature]
        if g["clip"].nunique() < 2 or g["participant"].nunique() < 2:
            continue
        levels = [e for e in GAIT_EMOTIONS if e in set(g["emotion"])]
        ref = "neutral" if "neutral" in levels else levels[0]
        rhs = f"C(emotion, Treatment('{ref}'))" if len(levels) > 1 else "1"
        out.append(crossed_mixed_model(g, f"value ~ {rhs}", "affect_likert ~ intended emotion", feature))
    return pd.concat(out, ignore_index=True) if out else pd.DataFrame(columns=COLUMNS)


def mixed_models(responses: pd.DataFrame, clips: pd.DataFrame, max_participants: int = MAX_PARTICIPANTS,
                 seed: int = 0) -> pd.DataFrame:
    """The report's ``mixed_models`` table: :func:`theme_mixed_models` then :func:`likert_mixed_models`."""
    parts = [t for t in (theme_mixed_models(responses, clips, max_participants, seed),
                         likert_mixed_models(responses, clips, max_participants, seed)) if len(t)]
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=COLUMNS)
