"""Style-theme ratings of RBF-styled walks (seed 004 sections V-A, V-D, V-E; Table I, Table IV, Figs. 7-8).

- ``neutral_validation``: 7-way forced choice (neutral + six themes) on the neutral input walk (Table I).
- ``theme_rating``: rating 1..7 of how much of the clip's theme is present; clips carry theme, weight w and
  number of features n_features (seed 004: w in 0.4, 0.7, 1.0, 1.3 and n in 1, 4, 7, 10). For figures the
  ratings are normalised to 0..1 as (rating - 1) / 6 (the ANOVA is unchanged by this linear map).
- ``theme_inversion``: rating -7..7 of clips made with a negative weight (-7 maximum opposite theme, 0 neutral,
  +7 maximum original theme).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pingouin as pg
from scipy import stats

from protocol.vocabulary import NEUTRAL_CHOICES, THEMES

ANOVA_COLUMNS = ["theme", "effect", "F", "df1", "df2", "p_value", "p_gg", "eta2_partial", "epsilon", "n_subjects",
                 "n_dropped", "note"]


def _theme_rows(responses: pd.DataFrame, clips: pd.DataFrame, section: str) -> pd.DataFrame:
    r = responses[responses["section_type"] == section]
    c = clips.reindex(r["clip_id"])
    return pd.DataFrame({"participant_id": r["participant_id"].to_numpy(), "theme": c["theme"].to_numpy(),
                         "weight": c["weight"].to_numpy(float), "n_features": c["n_features"].to_numpy(float),
                         "value": r["value"].to_numpy(float)})


def _theme_order(themes) -> list[str]:
    present = set(themes)
    return [t for t in THEMES if t in present] + sorted(present - set(THEMES))


def theme_cells(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    """Per participant, theme, weight and n_features: the mean rating (a participant who rated a cell more than
    once contributes the mean of those ratings). Columns participant_id, theme, weight, n_features, rating."""
    d = _theme_rows(responses, clips, "theme_rating")
    return (d.groupby(["participant_id", "theme", "weight", "n_features"], sort=True)["value"].mean()
            .rename("rating").reset_index())


def theme_anova(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    """Two-way repeated-measures ANOVA, weight x number of features, per theme (seed 004 Table IV).

    pingouin.rm_anova(dv=rating, within=[weight, n_features], subject=participant_id, correction=True,
    effsize="np2"): F, df, uncorrected p, Greenhouse-Geisser corrected p (``p_gg``; epsilon in ``epsilon``) and
    partial eta squared SS_effect / (SS_effect + SS_error). The design of a theme is every (weight, n_features)
    cell seen in its clips; participants missing any cell of a theme are dropped from that theme's ANOVA
    (``n_dropped``, and a note), since RM-ANOVA needs complete data. A factor with one level leaves a one-way
    ANOVA on the other factor.

    Returns theme, effect (weight | n_features | weight * n_features), F, df1, df2, p_value, p_gg, eta2_partial,
    epsilon, n_subjects, n_dropped, note.
    """
    cells = theme_cells(responses, clips)
    rows = []
    for theme in _theme_order(cells["theme"].unique()):
        t = cells[cells["theme"] == theme]
        n_cells = t.groupby(["weight", "n_features"]).ngroups
        per_subject = t.groupby("participant_id").size()
        complete = per_subject.index[per_subject == n_cells]
        n_dropped = int(len(per_subject) - len(complete))
        t = t[t["participant_id"].isin(complete)]
        factors = [f for f in ("weight", "n_features") if t[f].nunique() >= 2]
        note = f"{n_dropped} participant(s) with missing cells dropped" if n_dropped else ""
        if len(complete) < 2 or not factors:
            rows.append({"theme": theme, "effect": "", "F": np.nan, "df1": np.nan, "df2": np.nan, "p_value": np.nan,
                         "p_gg": np.nan, "eta2_partial": np.nan, "epsilon": np.nan, "n_subjects": len(complete),
                         "n_dropped": n_dropped,
                         "note": "; ".join(filter(None, [note, "not enough complete participants or levels"]))})
            continue
        if len(factors) == 1:
            note = "; ".join(filter(None, [note, "one-way ANOVA (the other factor has one level)"]))
        a = pg.rm_anova(t, dv="rating", within=factors if len(factors) == 2 else factors[0],
                        subject="participant_id", detailed=True, effsize="np2", correction=True)
        if len(factors) == 1:  # one-way table: effect row + Error row with "DF"
            df2 = int(a.loc[1, "DF"])
            a = a.iloc[[0]].rename(columns={"DF": "ddof1"}).assign(ddof2=df2)
        for _, row in a.iterrows():
            p_gg = row.get("p_GG_corr", np.nan)
            eps = row.get("eps", np.nan)
            if pd.isna(p_gg):  # pingouin leaves it out when a factor has 2 levels (epsilon = 1)
                p_gg, eps = row["p_unc"], 1.0
            rows.append({"theme": theme, "effect": str(row["Source"]), "F": float(row["F"]),
                         "df1": int(row["ddof1"]), "df2": int(row["ddof2"]), "p_value": float(row["p_unc"]),
                         "p_gg": float(p_gg), "eta2_partial": float(row["np2"]), "epsilon": float(eps),
                         "n_subjects": len(complete), "n_dropped": n_dropped, "note": note})
    return pd.DataFrame(rows, columns=ANOVA_COLUMNS)


def theme_descriptives(responses: pd.DataFrame, clips: pd.DataFrame) -> pd.DataFrame:
    """Mean and standard error (SD / sqrt(n), SD with ddof 1) of the normalised rating (rating - 1) / 6 per theme,
    weight and n_features, over participants' cell means (seed 004 Fig. 7). Columns theme, weight, n_features,
    mean, se, n."""
    cells = theme_cells(responses, clips)
    cells["norm"] = (cells["rating"] - 1.0) / 6.0
    g = cells.groupby(["theme", "weight", "n_features"])["norm"]
    out = pd.DataFrame({"mean": g.mean(), "se": g.std(ddof=1) / np.sqrt(g.count()), "n": g.count()}).reset_index()
    return out


def theme_inversion(responses: pd.DataFrame, clips: pd.DataFrame, alpha: float = 0.05) -> pd.DataFrame:
    """Inversion ratings per theme (seed 004 section V-E, Fig. 8): mean, standard error SD/sqrt(n) and a
    two-sided one-sample t-test against 0 (scipy.stats.ttest_1samp), t = mean / se with n - 1 df.

    Observations are participants: a participant who rated several inverted clips of one theme contributes their
    mean. Returns theme, mean, se, n, t, p_value, reject (p < alpha; a negative mean with reject = True means the
    opposite theme was perceived).
    """
    d = _theme_rows(responses, clips, "theme_inversion")
    per = d.groupby(["theme", "participant_id"])["value"].mean().reset_index()
    rows = []
    for theme in _theme_order(per["theme"].unique()):
        v = per.loc[per["theme"] == theme, "value"].to_numpy(float)
        n = len(v)
        mean = float(v.mean())
        se = float(v.std(ddof=1) / np.sqrt(n)) if n > 1 else np.nan
        if n > 1 and se > 0:
            res = stats.ttest_1samp(v, 0.0)
            t, p = float(res.statistic), float(res.pvalue)
        else:
            t, p = np.nan, np.nan
        rows.append({"theme": theme, "mean": mean, "se": se, "n": n, "t": t, "p_value": p,
                     "reject": bool(p < alpha) if not np.isnan(p) else False})
    return pd.DataFrame(rows, columns=["theme", "mean", "se", "n", "t", "p_value", "reject"])


def neutral_validation(responses: pd.DataFrame) -> pd.DataFrame:
    """Share of each of the seven choices (neutral + six themes) in section ``neutral_validation`` (seed 004
    Table I). Every choice appears (share 0 if never chosen). Columns choice, share, n (all answers), count."""
    r = responses.loc[responses["section_type"] == "neutral_validation", "answer"]
    counts = r.value_counts().reindex(list(NEUTRAL_CHOICES), fill_value=0)
    n = int(counts.sum())
    return pd.DataFrame({"choice": list(NEUTRAL_CHOICES), "share": counts.to_numpy() / n if n else np.nan,
                         "n": n, "count": counts.to_numpy()})
