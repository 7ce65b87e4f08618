"""Emotion recognition against chance: confusion matrices, hit rates, Wagner's unbiased hit rate and Cohen's kappa.

The standard analysis of forced-choice emotion-perception studies (Wagner 1993): a confusion matrix with the
intended emotion in rows and the perceived emotion in columns, per emotion the hit rate and the unbiased hit rate
Hu, which corrects the hit rate for how often the perceived label is used at all, compared with its chance value;
and a per-participant paired t-test of Hu against chance on arcsine-transformed proportions.

    H. L. Wagner. "On measuring performance in category judgment studies of nonverbal behavior." Journal of
    Nonverbal Behavior 17(1), 3-28, 1993. doi:10.1007/BF00987006.
    J. Cohen. "A coefficient of agreement for nominal scales." Educational and Psychological Measurement 20(1),
    37-46, 1960.

Definitions (C = confusion matrix, rows intended i, columns perceived j; an answer that selects k labels adds 1/k
to each selected column, so every answer weighs 1 and N = total of C = number of answers):

- hit rate_i = C_ii / row_i
- Hu_i = C_ii^2 / (row_i * col_i)   (0 when row_i or col_i is 0)
- chance Hu_i = row_i * col_i / N^2  (the joint probability of intending i and perceiving i by independence)
- Cohen's kappa = (po - pe) / (1 - pe), po = trace / N, pe = sum_i row_i * col_i / N^2.

Unlike seed 000's 4-value Anderson-Darling test (:mod:`analysis.emotion`), these statistics keep the labels: a happy
gait perceived as neutral is a miss here, whereas the AD test only compares the two sets of four numbers.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats
from statsmodels.stats.multitest import multipletests

from protocol.vocabulary import GAIT_EMOTIONS

DOMINANT_MIN = 0.5
"""A clip's dominant intended gait emotion must be the unique largest component and at least this share."""


def dominant_intended_label(clips: pd.DataFrame, min_share: float = DOMINANT_MIN) -> pd.Series:
    """clip_id -> the dominant intended gait emotion for recognition, NaN where there is none.

    The dominant emotion is the largest of (happy, sad, angry, neutral) of the l1-normalised intended vector,
    used only when it is unique (no tie for the largest) and at least ``min_share`` (0.5); clips without an
    intended vector, with a tie, or with a largest component below 0.5 get NaN and are left out of recognition.
    (The Likert analysis's :func:`analysis.likert.dominant_emotion` is a plain argmax; this rule is stricter because
    a confusion matrix needs one correct answer per clip.)
    """
    v = clips[list(GAIT_EMOTIONS)].to_numpy(float)
    filled = np.nan_to_num(v, nan=-1.0)
    top = filled.max(axis=1)
    unique = (np.isclose(filled, top[:, None], rtol=0, atol=1e-12).sum(axis=1) == 1)
    ok = ~np.isnan(v).any(axis=1) & unique & (top >= min_share - 1e-12)
    lab = np.asarray(GAIT_EMOTIONS, dtype=object)[filled.argmax(axis=1)]
    return pd.Series(np.where(ok, lab, None), index=clips.index, dtype=object).where(ok)


def selection_weights(answers: pd.Series, labels) -> np.ndarray:
    """Answers ("happy" or multi-select "happy;neutral") -> (N, L) weights: 1/k on each of the k selected labels,
    columns in ``labels`` order. Each distinct answer is parsed once (answers may be a categorical)."""
    labels = list(labels)
    index = {lab: j for j, lab in enumerate(labels)}
    cat = pd.Categorical(answers.astype(str).to_numpy())
    table = np.zeros((len(cat.categories), len(labels)))
    for c, text in enumerate(cat.categories):
        chosen = [s.strip() for s in str(text).split(";") if s.strip()]
        unknown = [s for s in chosen if s not in index]
        if not chosen or unknown:
            raise ValueError(f"answer {text!r} selects no label or an unknown one ({unknown})")
        for s in chosen:
            table[c, index[s]] += 1.0 / len(chosen)
    return table[cat.codes] if len(cat) else np.zeros((0, len(labels)))


def confusion_matrix(intended: np.ndarray, weights: np.ndarray, labels) -> pd.DataFrame:
    """Confusion matrix from per-answer intended label indices (N,) and selection weights (N, L).

    Returns an (L, L) DataFrame: index ``intended`` labels, columns ``perceived`` labels; cell (i, j) = total
    weight that answers to clips intended as i gave to label j (1/k per selected label).
    """
    L = len(labels)
    mat = np.zeros((L, L))
    np.add.at(mat, np.asarray(intended, int), np.asarray(weights, float))
    return pd.DataFrame(mat, index=pd.Index(list(labels), name="intended"),
                        columns=pd.Index(list(labels), name="perceived"))


def recognition_rates(confusion) -> pd.DataFrame:
    """Per intended label: hit rate, unbiased hit rate Hu (Wagner 1993) and Hu's chance value.

    ``confusion``: (L, L) rows intended, columns perceived (DataFrame or array). Returns one row per label:
    label, n (row total), n_perceived (column total), hit_rate = C_ii/row_i (NaN when row_i = 0),
    unbiased_hit_rate = C_ii^2/(row_i col_i) (0 when row_i or col_i is 0), chance_unbiased_hit_rate =
    row_i col_i / N^2.
    """
    c = np.asarray(confusion, float)
    labels = list(confusion.index) if isinstance(confusion, pd.DataFrame) else list(range(len(c)))
    row, col, diag, total = c.sum(axis=1), c.sum(axis=0), np.diag(c), c.sum()
    with np.errstate(invalid="ignore", divide="ignore"):
        hit = np.where(row > 0, diag / row, np.nan)
        hu = np.where((row > 0) & (col > 0), diag**2 / (row * col), 0.0)
        chance = row * col / total**2 if total > 0 else np.full(len(c), np.nan)
    return pd.DataFrame({"label": pd.Series(labels, dtype=object), "n": row, "n_perceived": col, "hit_rate": hit,
                         "unbiased_hit_rate": hu,
                         "chance_unbiased_hit_rate": chance})


def cohen_kappa(confusion) -> float:
    """Cohen's (1960) kappa of a confusion matrix (rows intended, columns perceived): (po - pe) / (1 - pe) with
    po = trace / N, pe = sum_i row_i col_i / N^2. NaN for an empty matrix or pe = 1."""
    c = np.asarray(confusion, float)
    n = c.sum()
    if n <= 0:
        return float("nan")
    po = np.trace(c) / n
    pe = float((c.sum(axis=1) * c.sum(axis=0)).sum() / n**2)
    return float((po - pe) / (1 - pe)) if pe < 1 else float("nan")


def participant_hu_tests(participant: np.ndarray, intended: np.ndarray, weights: np.ndarray, labels,
                         alpha: float = 0.05) -> pd.DataFrame:
    """Wagner's (1993) test of recognition above chance: per participant and intended label, Hu and chance Hu from
    that participant's own confusion matrix; both arcsine-transformed (arcsin(sqrt(x))); per label a paired t-test
    of Hu against chance across participants (scipy.stats.ttest_rel, two-sided); Holm correction across labels
    (statsmodels.stats.multitest.multipletests, method 'holm').

    ``participant`` (N,) ids, ``intended`` (N,) label indices, ``weights`` (N, L) selection weights. A participant
    enters a label's test only if they saw at least one clip intended as that label (row_i > 0); otherwise their Hu
    and chance are both 0 by definition and carry no information. Fewer than 2 participants, or no variation in
    the differences, gives NaN t and p.

    Returns one row per label: label, n_participants, mean_hu, mean_chance (untransformed means), mean_diff_asin
    (mean of arcsin-sqrt Hu minus chance), t, df, p_value, p_holm, reject (p_holm < alpha).
    """
    labels = list(labels)
    L = len(labels)
    codes, uniq = pd.factorize(pd.Series(participant).astype(str), sort=True)
    P = len(uniq)
    mats = np.zeros((P, L, L))
    if len(codes):
        np.add.at(mats, (codes, np.asarray(intended, int)), np.asarray(weights, float))
    row, col = mats.sum(axis=2), mats.sum(axis=1)
    diag = np.einsum("pii->pi", mats)
    total = mats.sum(axis=(1, 2))[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        hu = np.where((row > 0) & (col > 0), diag**2 / (row * col), 0.0)
        chance = np.where(total > 0, row * col / total**2, 0.0)
    rows = []
    for i, lab in enumerate(labels):
        seen = row[:, i] > 0
        a, b = np.arcsin(np.sqrt(hu[seen, i])), np.arcsin(np.sqrt(chance[seen, i]))
        t = p = np.nan
        if seen.sum() >= 2 and np.ptp(a - b) > 0:
            res = stats.ttest_rel(a, b)
            t, p = float(res.statistic), float(res.pvalue)
        rows.append({"label": lab, "n_participants": int(seen.sum()),
                     "mean_hu": float(hu[seen, i].mean()) if seen.any() else np.nan,
                     "mean_chance": float(chance[seen, i].mean()) if seen.any() else np.nan,
                     "mean_diff_asin": float((a - b).mean()) if seen.any() else np.nan,
                     "t": t, "df": int(seen.sum()) - 1 if seen.sum() >= 2 else np.nan, "p_value": p})
    out = pd.DataFrame(rows, columns=["label", "n_participants", "mean_hu", "mean_chance", "mean_diff_asin", "t",
                                      "df", "p_value"])
    out["p_holm"] = np.nan
    ok = out["p_value"].notna().to_numpy()
    if ok.any():
        out.loc[ok, "p_holm"] = multipletests(out.loc[ok, "p_value"].to_numpy(float), alpha=alpha, method="holm")[1]
    out["reject"] = (out["p_holm"] < alpha).to_numpy()
    return out


def _answers(responses: pd.DataFrame, section: str) -> pd.DataFrame:
    return responses[(responses["section_type"] == section) & (responses["question"] == "perceived")]


def recognition(participant, intended_labels, answers, labels, alpha: float = 0.05) -> dict:
    """The whole recognition analysis of one forced-choice question.

    ``participant``, ``intended_labels`` (strings), ``answers`` (strings, ';' for multi-select): one entry per
    answer; ``labels``: the label order of the matrix. Returns a dict: labels, confusion (DataFrame, rows intended),
    rates (:func:`recognition_rates`), kappa, n_answers, participant_tests (:func:`participant_hu_tests`).
    """
    labels = list(labels)
    index = {lab: i for i, lab in enumerate(labels)}
    intended = np.array([index[x] for x in np.asarray(intended_labels, dtype=object)], dtype=int)
    weights = selection_weights(pd.Series(np.asarray(answers, dtype=object)), labels)
    conf = confusion_matrix(intended, weights, labels)
    return {"labels": labels, "confusion": conf, "rates": recognition_rates(conf), "kappa": cohen_kappa(conf),
            "n_answers": int(len(intended)),
            "participant_tests": participant_hu_tests(np.asarray(participant), intended, weights, labels, alpha)}


def gait_recognition(responses: pd.DataFrame, clips: pd.DataFrame, alpha: float = 0.05) -> dict:
    """Recognition of single gait emotions (section ``emotion_choice``, multi-select, 1/k per selected label).

    Intended label: :func:`dominant_intended_label` (unique largest component >= 0.5); answers to clips without
    one are left out (``n_excluded``). Labels in GAIT_EMOTIONS order. Returns :func:`recognition`'s dict plus
    n_excluded.
    """
    r = _answers(responses, "emotion_choice")
    dom = dominant_intended_label(clips).reindex(r["clip_id"].astype(str)).to_numpy()
    keep = pd.notna(dom)
    out = recognition(r["participant_id"].astype(str).to_numpy()[keep], dom[keep],
                      r["answer"].astype(str).to_numpy()[keep], GAIT_EMOTIONS, alpha)
    out["n_excluded"] = int((~keep).sum())
    return out


def gesture_recognition(responses: pd.DataFrame, clips: pd.DataFrame, alpha: float = 0.05) -> dict:
    """Recognition of gesture emotion categories (section ``gesture_emotion``, one choice per answer).

    Intended label: the clip's ``emotion_label``; answers to clips without one are left out (``n_excluded``).
    Labels: sorted alphabetically over all intended and chosen labels. Returns :func:`recognition`'s dict plus
    n_excluded.
    """
    r = _answers(responses, "gesture_emotion")
    lab = clips["emotion_label"].reindex(r["clip_id"].astype(str)).to_numpy(dtype=object)
    keep = np.array([isinstance(x, str) and x != "" for x in lab], dtype=bool)
    answers = r["answer"].astype(str).to_numpy()[keep]
    chosen = {s.strip() for a in pd.unique(answers) for s in str(a).split(";") if s.strip()}
    labels = sorted(set(lab[keep]) | chosen)
    out = recognition(r["participant_id"].astype(str).to_numpy()[keep], lab[keep], answers, labels, alpha)
    out["n_excluded"] = int((~keep).sum())
    return out


def recognition_table(result: dict) -> pd.DataFrame:
    """Tidy per-label table of one :func:`recognition` result: rates joined with the participant tests."""
    return result["rates"].merge(result["participant_tests"], on="label", how="left")


def recognition_json(result: dict) -> dict:
    """The report.json object of one recognition result (DESIGN.md ``recognition.<question>``)."""
    rates = result["rates"].set_index("label")
    return {"labels": result["labels"], "confusion": result["confusion"].to_numpy().tolist(),
            "hit_rate": rates["hit_rate"].to_dict(), "unbiased_hit_rate": rates["unbiased_hit_rate"].to_dict(),
            "chance_unbiased_hit_rate": rates["chance_unbiased_hit_rate"].to_dict(), "kappa": result["kappa"],
            "n_answers": result["n_answers"], "n_excluded": result.get("n_excluded", 0),
            "participant_tests": result["participant_tests"].to_dict("records")}
