"""Agreement statistics (analysis.agreement): ICC against pingouin and Shrout & Fleiss, Fleiss' kappa."""

import numpy as np
import pandas as pd
import pingouin as pg
import pytest
from statsmodels.stats.inter_rater import fleiss_kappa as sm_fleiss_kappa

from analysis import agreement as A

# Shrout & Fleiss (1979) Table 2: 6 targets rated by 4 judges; published ICC(2,1) = .29, ICC(2,4) = .62.
SF = np.array([[9, 2, 5, 8], [6, 1, 3, 2], [8, 4, 6, 8], [7, 1, 2, 6], [10, 5, 6, 9], [6, 2, 4, 7]], float)


def _long(matrix):
    n, k = matrix.shape
    return pd.DataFrame({"target": np.repeat(np.arange(n), k), "rater": np.tile(np.arange(k), n),
                         "rating": matrix.ravel()})


def test_icc_shrout_fleiss_published_values():
    icc = A.icc_two_way(SF).set_index("statistic")
    assert icc.loc["ICC2", "value"] == pytest.approx(0.29, abs=0.005)
    assert icc.loc["ICC2k", "value"] == pytest.approx(0.62, abs=0.005)


@pytest.mark.parametrize("seed", [0, 1])
def test_icc_equals_pingouin(seed):
    rng = np.random.default_rng(seed)
    m = SF if seed == 0 else rng.normal(0, 1, (7, 1)) + rng.normal(0, 0.5, (1, 5)) + rng.normal(0, 1, (7, 5))
    ours = A.icc_two_way(m).set_index("statistic")
    ref = pg.intraclass_corr(_long(m), targets="target", raters="rater", ratings="rating").set_index("Type")
    for name, ref_name in (("ICC2", "ICC(A,1)"), ("ICC2k", "ICC(A,k)")):
        assert ours.loc[name, "value"] == pytest.approx(ref.loc[ref_name, "ICC"], abs=1e-10)
        assert ours.loc[name, "F"] == pytest.approx(ref.loc[ref_name, "F"])
        assert ours.loc[name, "p_value"] == pytest.approx(ref.loc[ref_name, "pval"])
        assert [ours.loc[name, "ci_low"], ours.loc[name, "ci_high"]] == pytest.approx(
            list(ref.loc[ref_name, "CI95"]), abs=0.006)  # pingouin rounds the interval to 2 decimals


def test_fleiss_kappa_equal_raters_matches_statsmodels_and_unequal_by_hand():
    table = np.array([[0, 0, 0, 0, 14], [0, 2, 6, 4, 2], [0, 0, 3, 5, 6], [0, 3, 9, 2, 0], [2, 2, 8, 1, 1]], float)
    assert A.fleiss_kappa(table) == pytest.approx(sm_fleiss_kappa(table))
    # unequal numbers of ratings: items [2, 0], [1, 1], [3, 0]
    # P_i = (sum n_ij^2 - n_i)/(n_i(n_i - 1)) = 1, 0, 1 -> mean 2/3; p_j = (6/7, 1/7), Pe = 37/49
    # kappa = (2/3 - 37/49) / (1 - 37/49) = -13/36
    assert A.fleiss_kappa(np.array([[2, 0], [1, 1], [3, 0]], float)) == pytest.approx(-13 / 36)
    # an item with a single rating is left out: same value
    assert A.fleiss_kappa(np.array([[2, 0], [1, 1], [3, 0], [0, 1]], float)) == pytest.approx(-13 / 36)


def _responses(section, question, rows):
    return pd.DataFrame(rows, columns=["participant_id", "clip_id", "answer", "value"]).assign(
        section_type=section, question=question)


def test_rating_icc_from_responses_drops_incomplete_raters():
    rows = [(f"p{j}", f"c{i}", str(int(SF[i, j])), SF[i, j]) for i in range(6) for j in range(4)]
    rows.append(("p9", "c0", "3", 3.0))  # a fifth participant who rated one clip only
    resp = _responses("affect_likert", "torso", rows)
    clips = pd.DataFrame({"theme": [""] * 6}, index=[f"c{i}" for i in range(6)])
    out = A.rating_icc(resp, clips)
    icc2 = out[(out["question"] == "torso") & (out["statistic"] == "ICC2")].iloc[0]
    assert icc2["value"] == pytest.approx(A.icc_two_way(SF)["value"][0])
    assert icc2["n_raters"] == 4 and icc2["n_items"] == 6 and "1 participant" in icc2["note"]


def test_choice_fleiss_kappa_from_responses():
    # 3 clips, 3 participants each; gesture choices -> table [[3,0],[2,1],[0,3]] over (angry, sad)
    rows = [("p1", "a", "angry"), ("p2", "a", "angry"), ("p3", "a", "angry"),
            ("p1", "b", "angry"), ("p2", "b", "angry"), ("p3", "b", "sad"),
            ("p1", "c", "sad"), ("p2", "c", "sad"), ("p3", "c", "sad")]
    resp = pd.DataFrame(rows, columns=["participant_id", "clip_id", "answer"]).assign(
        section_type="gesture_emotion", question="perceived")
    out = A.choice_fleiss_kappa(resp)
    assert len(out) == 1
    rec = out.iloc[0]
    assert rec["value"] == pytest.approx(sm_fleiss_kappa(np.array([[3, 0], [2, 1], [0, 3]])))
    assert rec["n_raters"] == 3 and rec["n_items"] == 3 and rec["statistic"] == "fleiss_kappa"
