"""Recognition against chance (analysis.recognition): hit rate, Wagner's Hu, chance Hu, Cohen's kappa."""

import numpy as np
import pandas as pd
import pytest
from scipy import stats
from statsmodels.stats.inter_rater import cohens_kappa as sm_cohens_kappa
from statsmodels.stats.multitest import multipletests

from analysis import recognition as R
from protocol.vocabulary import GAIT_EMOTIONS


def test_rates_2x2_by_hand():
    # C = [[8, 2], [4, 6]]: rows (intended) 10, 10; columns (perceived) 12, 8; N = 20.
    c = pd.DataFrame([[8.0, 2.0], [4.0, 6.0]], index=["a", "b"], columns=["a", "b"])
    r = R.recognition_rates(c).set_index("label")
    # hit rates 8/10, 6/10
    assert r["hit_rate"].tolist() == pytest.approx([0.8, 0.6])
    # Hu = C_ii^2 / (row_i col_i): 64 / (10 * 12) = 0.5333, 36 / (10 * 8) = 0.45
    assert r["unbiased_hit_rate"].tolist() == pytest.approx([64 / 120, 0.45])
    # chance = row_i col_i / N^2: 120 / 400 = 0.3, 80 / 400 = 0.2
    assert r["chance_unbiased_hit_rate"].tolist() == pytest.approx([0.3, 0.2])
    # po = 14 / 20 = 0.7; pe = (10*12 + 10*8) / 400 = 0.5; kappa = (0.7 - 0.5) / (1 - 0.5) = 0.4
    assert R.cohen_kappa(c) == pytest.approx(0.4)
    assert R.cohen_kappa(c) == pytest.approx(sm_cohens_kappa(c.to_numpy()).kappa)


def test_rates_3x3_by_hand_with_empty_row():
    # C = [[5, 1, 0], [2, 3, 1], [0, 0, 0]]: rows 6, 6, 0; columns 7, 4, 1; N = 12.
    c = np.array([[5.0, 1, 0], [2, 3, 1], [0, 0, 0]])
    r = R.recognition_rates(c)
    hit = r["hit_rate"].to_numpy()
    assert hit[:2] == pytest.approx([5 / 6, 0.5]) and np.isnan(hit[2])  # row 0: no hit rate
    # Hu: 25 / (6*7), 9 / (6*4) = 0.375, and 0 where row_i = 0
    assert r["unbiased_hit_rate"].tolist() == pytest.approx([25 / 42, 0.375, 0.0])
    # chance: 42/144, 24/144, 0/144
    assert r["chance_unbiased_hit_rate"].tolist() == pytest.approx([42 / 144, 24 / 144, 0.0])
    # po = 8/12, pe = (42 + 24 + 0)/144 = 66/144, kappa = (96 - 66) / (144 - 66) = 30/78
    assert R.cohen_kappa(c) == pytest.approx(30 / 78)
    assert R.cohen_kappa(c) == pytest.approx(sm_cohens_kappa(c).kappa)


def test_kappa_matches_statsmodels_on_random_tables():
    rng = np.random.default_rng(3)
    for _ in range(5):
        c = rng.integers(0, 20, (4, 4)).astype(float) + np.eye(4) * 10
        assert R.cohen_kappa(c) == pytest.approx(sm_cohens_kappa(c).kappa, abs=1e-12)


def test_multi_select_weights_one_over_k():
    w = R.selection_weights(pd.Series(["happy;neutral", "happy", "sad;angry;neutral"]), GAIT_EMOTIONS)
    np.testing.assert_allclose(w, [[0.5, 0, 0, 0.5], [1, 0, 0, 0], [0, 1 / 3, 1 / 3, 1 / 3]])
    # two answers to a happy clip: "happy;neutral" and "happy" -> row happy = (1.5, 0, 0, 0.5), N = 2
    conf = R.confusion_matrix(np.array([0, 0]), w[:2], GAIT_EMOTIONS)
    assert conf.loc["happy"].tolist() == pytest.approx([1.5, 0, 0, 0.5])
    assert conf.to_numpy().sum() == pytest.approx(2)
    with pytest.raises(ValueError):
        R.selection_weights(pd.Series(["joy"]), GAIT_EMOTIONS)


def _clips(rows):
    df = pd.DataFrame(rows, columns=["clip_id", *GAIT_EMOTIONS, "emotion_label"]).set_index("clip_id", drop=False)
    return df


def test_dominant_label_rule_ties_and_below_half_excluded():
    clips = _clips([
        ("pure", 1, 0, 0, 0, ""),
        ("mix", 0.7, 0, 0, 0.3, ""),
        ("half", 0.5, 0.2, 0.2, 0.1, ""),     # exactly 0.5 and unique: happy
        ("tie", 0.5, 0.5, 0, 0, ""),          # tie for the largest: excluded
        ("low", 0.4, 0.3, 0.3, 0, ""),        # largest below 0.5: excluded
        ("none", np.nan, np.nan, np.nan, np.nan, "proud"),  # no intended vector
    ])
    dom = R.dominant_intended_label(clips)
    assert dom["pure"] == "happy" and dom["mix"] == "happy" and dom["half"] == "happy"
    assert dom[["tie", "low", "none"]].isna().all()


def test_gait_recognition_end_to_end_small():
    clips = _clips([("h", 1, 0, 0, 0, ""), ("s", 0, 1, 0, 0, ""), ("tie", 0.5, 0.5, 0, 0, "")])
    resp = pd.DataFrame({
        "participant_id": ["p1", "p1", "p1", "p2", "p2", "p2"],
        "section_type": "emotion_choice", "question": "perceived",
        "clip_id": ["h", "s", "tie", "h", "s", "tie"],
        "answer": ["happy;neutral", "sad", "happy", "happy", "happy", "sad"],
    })
    g = R.gait_recognition(resp, clips)
    assert g["n_answers"] == 4 and g["n_excluded"] == 2 and g["labels"] == list(GAIT_EMOTIONS)
    c = g["confusion"]
    # happy row: p1 0.5 happy + 0.5 neutral, p2 1 happy; sad row: p1 sad, p2 happy
    assert c.loc["happy"].tolist() == pytest.approx([1.5, 0, 0, 0.5])
    assert c.loc["sad"].tolist() == pytest.approx([1, 1, 0, 0])
    rates = g["rates"].set_index("label")
    # happy: row 2, col 2.5, Hu = 1.5^2 / (2 * 2.5) = 0.45, chance = 2 * 2.5 / 16 = 0.3125
    assert rates.loc["happy", "unbiased_hit_rate"] == pytest.approx(0.45)
    assert rates.loc["happy", "chance_unbiased_hit_rate"] == pytest.approx(0.3125)
    assert rates.loc["happy", "hit_rate"] == pytest.approx(0.75)
    js = R.recognition_json(g)
    assert set(js) >= {"labels", "confusion", "hit_rate", "unbiased_hit_rate", "chance_unbiased_hit_rate", "kappa",
                       "n_answers"}
    assert js["confusion"][0] == pytest.approx([1.5, 0, 0, 0.5])


def test_gesture_labels_sorted_over_intended_and_chosen():
    clips = _clips([("g1", np.nan, np.nan, np.nan, np.nan, "proud"),
                    ("g2", np.nan, np.nan, np.nan, np.nan, "afraid")])
    resp = pd.DataFrame({"participant_id": ["p1", "p1", "p2", "p2"], "section_type": "gesture_emotion",
                         "question": "perceived", "clip_id": ["g1", "g2", "g1", "g2"],
                         "answer": ["proud", "surprised", "joyous", "afraid"]})
    g = R.gesture_recognition(resp, clips)
    assert g["labels"] == ["afraid", "joyous", "proud", "surprised"]
    assert g["confusion"].loc["proud", "proud"] == 1 and g["confusion"].loc["afraid", "surprised"] == 1


def test_participant_tests_are_paired_t_on_arcsine_with_holm():
    rng = np.random.default_rng(0)
    labels = ["a", "b", "c"]
    part, intended, answers = [], [], []
    for p in range(12):
        for i in range(3):
            for _ in range(4):
                part.append(f"p{p}")
                intended.append(i)
                answers.append(i if rng.random() < 0.6 else int(rng.integers(0, 3)))
    w = np.eye(3)[answers]
    res = R.participant_hu_tests(np.array(part), np.array(intended), w, labels)
    # recompute one participant's Hu and chance by hand for label "a"
    hu, ch = [], []
    for p in range(12):
        m = np.zeros((3, 3))
        for q, i, j in zip(part, intended, answers):
            if q == f"p{p}":
                m[i, j] += 1
        row, col, n = m.sum(1), m.sum(0), m.sum()
        hu.append(m[0, 0] ** 2 / (row[0] * col[0]) if col[0] else 0.0)
        ch.append(row[0] * col[0] / n**2)
    expect = stats.ttest_rel(np.arcsin(np.sqrt(hu)), np.arcsin(np.sqrt(ch)))
    a = res.set_index("label").loc["a"]
    assert a["t"] == pytest.approx(expect.statistic) and a["p_value"] == pytest.approx(expect.pvalue)
    assert a["mean_hu"] == pytest.approx(np.mean(hu)) and a["n_participants"] == 12 and a["df"] == 11
    assert res["p_holm"].tolist() == pytest.approx(multipletests(res["p_value"], method="holm")[1].tolist())
    assert res["reject"].all()
