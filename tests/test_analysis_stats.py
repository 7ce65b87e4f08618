"""Every statistic of analysis/ checked against an independent route or a known answer."""

import io
import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from analysis import adtest, emotion, likert, naturalness, participants, themes, vad
from analysis.io import read_clips, read_participants, read_responses
from protocol.vocabulary import GESTURE_VAD

pytestmark = pytest.mark.filterwarnings("ignore:p-value (capped|floored):UserWarning")  # scipy's own calls here

CLIP_HEADER = ("clip_id,modality,origin,happy,sad,angry,neutral,final_happy,final_sad,final_angry,final_neutral,"
               "emotion_label,valence,arousal,dominance,theme,weight,n_features,duration_s\n")


def _clips(rows: list[str]) -> pd.DataFrame:
    return read_clips(io.StringIO(CLIP_HEADER + "\n".join(rows) + "\n"))


def _responses(rows: list[tuple], clips: pd.DataFrame) -> pd.DataFrame:
    text = "participant_id,section_type,clip_id,question,answer,response_ms\n" + "\n".join(
        ",".join(map(str, r)) + ",1000" for r in rows) + "\n"
    return read_responses(io.StringIO(text), clips)


# --- Anderson-Darling -------------------------------------------------------------------------------------------

def test_reference_ad_example():
    """REFERENCE.md section 6: intended (1,0,0,0) vs perceived (0.6,0.05,0.05,0.3): statistic 2.18, p = 0.041."""
    res = emotion.ad_2samp([1, 0, 0, 0], [0.6, 0.05, 0.05, 0.3])
    assert res["statistic"] == pytest.approx(2.18, abs=0.005)
    assert res["p_value"] == pytest.approx(0.041, abs=0.0005)
    assert res["reject"] and not res["p_capped"]


def test_gait_emotion_ad_through_answers_reproduces_reference():
    """20 single-label answers 12 happy / 1 sad / 1 angry / 6 neutral average to (0.6, 0.05, 0.05, 0.3)."""
    clips = _clips(["g1,gait,generated,1,0,0,0,,,,,,,,,,,,10"])
    rows = [(f"p{i}", "emotion_choice", "g1", "perceived", lab)
            for i, lab in enumerate(["happy"] * 12 + ["sad", "angry"] + ["neutral"] * 6)]
    t = emotion.gait_emotion_ad(_responses(rows, clips), clips)
    row = t.iloc[0]
    assert row["n"] == 20
    assert row[["perceived_happy", "perceived_sad", "perceived_angry", "perceived_neutral"]].tolist() == \
        pytest.approx([0.6, 0.05, 0.05, 0.3])
    assert row["statistic"] == pytest.approx(2.18, abs=0.005)
    assert row["p_value"] == pytest.approx(0.041, abs=0.0005)
    assert bool(row["reject"]) is True


def test_multi_select_vector_and_seed000_gait2_value():
    """'happy;neutral' -> (0.5, 0, 0, 0.5). A fully happy intended vector against a perceived vector whose four
    components are distinct and non-zero gives seed 000 Table 3's Gait 2 value 2.111 (p = 0.04)."""
    v = emotion.answer_vectors(pd.Series(["happy;neutral", "sad", "happy;sad;angry;neutral"]))
    assert v.tolist() == [[0.5, 0, 0, 0.5], [0, 1, 0, 0], [0.25, 0.25, 0.25, 0.25]]
    res = emotion.ad_2samp([1, 0, 0, 0], [0.55, 0.05, 0.1, 0.3])
    assert res["statistic"] == pytest.approx(2.111, abs=0.001)
    assert res["p_value"] == pytest.approx(0.04, abs=0.005)


def test_ad_capped_and_permutation():
    res = emotion.ad_2samp([0.7, 0, 0, 0.3], [0.5, 0.1, 0.1, 0.3], permutations=200)
    assert res["p_capped"] and res["p_display"] == "> 0.25" and not res["reject"]
    assert 0.25 < res["p_perm"] <= 1.0


@pytest.mark.parametrize("seed", range(6))
def test_vectorised_ksample_ad_matches_scipy(seed):
    rng = np.random.default_rng(seed)
    k = int(rng.integers(2, 40))
    sizes = rng.integers(1, 6, k)
    samples = [rng.integers(0, 5, s).astype(float) + (0.3 * (i % 3 == 0) if seed % 2 else 0)
               for i, s in enumerate(sizes)]
    values = np.concatenate(samples)
    groups = np.repeat(np.arange(k), sizes)
    stat, p = adtest.anderson_ksamp_groups(values, groups)
    ref = stats.anderson_ksamp(samples, variant="midrank")
    assert stat == pytest.approx(ref.statistic, rel=1e-9, abs=1e-12)
    assert p == pytest.approx(ref.pvalue, rel=1e-9)


def test_ksample_ad_degenerate_sizes_of_one():
    stat, p = adtest.anderson_ksamp_groups(np.array([0, 1, 2, 3, 4, 2.0]), np.arange(6))
    assert math.isnan(stat) and math.isnan(p)


# --- Likert -----------------------------------------------------------------------------------------------------

def test_likert_distribution_and_consistency():
    clips = _clips(["g1,gait,generated,0,1,0,0,,,,,,,,,,,,10", "g2,gait,generated,0.2,0.8,0,0,,,,,,,,,,,,10"])
    rows = []
    for i in range(30):
        for clip in ("g1", "g2"):
            rows.append((f"p{i}", "affect_likert", clip, "torso", i % 3))  # values 0,1,2 equally
    r = _responses(rows, clips)
    d = likert.likert_distribution(r, clips)
    torso = d[(d.emotion == "sad") & (d.feature == "torso")].set_index("value")["share"]
    assert torso.tolist() == pytest.approx([1 / 3, 1 / 3, 1 / 3, 0, 0])
    c = likert.likert_consistency_ad(r, clips)
    assert c.iloc[0]["k"] == 30 and c.iloc[0]["mean_sample_size"] == 2
    # each participant gives the same value twice: samples differ, consistency is rejected
    assert bool(c.iloc[0]["reject"]) is True
    ref = stats.anderson_ksamp([np.array([i % 3] * 2, float) for i in range(30)], variant="midrank")
    assert c.iloc[0]["statistic"] == pytest.approx(ref.statistic)
    by_clip = likert.likert_consistency_ad(r, clips, by="clip")
    assert len(by_clip) == 2 and by_clip["statistic"].isna().all()  # one value per participant: undefined
    assert (by_clip["p_display"] == "n/a (every sample has one value)").all()


# --- VAD Pearson --------------------------------------------------------------------------------------------------

def test_vad_pearson_against_hand_formula():
    labels = [lab for lab in GESTURE_VAD if lab != "neutral"]
    clips = _clips([f"c{i},gesture,generated,,,,,,,,,{lab},,,,,,,8" for i, lab in enumerate(labels)])
    rng = np.random.default_rng(0)
    rows = []
    for j in range(60):
        i = j % len(labels)
        ans = labels[i] if rng.random() < 0.6 else labels[rng.integers(len(labels))]
        rows.append((f"p{j}", "gesture_emotion", f"c{i}", "perceived", ans))
    r = _responses(rows, clips)
    t = vad.vad_pearson(r, clips).set_index("dimension")
    for d, col in zip(("valence", "arousal", "dominance"), range(3)):
        x = np.array([GESTURE_VAD[labels[j % len(labels)]][col] for j in range(60)])
        y = np.array([GESTURE_VAD[row[4]][col] for row in rows])
        xm, ym = x - x.mean(), y - y.mean()
        rr = (xm * ym).sum() / math.sqrt((xm**2).sum() * (ym**2).sum())
        tt = rr * math.sqrt(58) / math.sqrt(1 - rr**2)
        p = 2 * stats.t.sf(abs(tt), 58)
        z, se = math.atanh(rr), 1 / math.sqrt(57)
        assert t.loc[d, "r"] == pytest.approx(rr, rel=1e-9)
        assert t.loc[d, "p_value"] == pytest.approx(p, rel=1e-6)
        assert t.loc[d, "ci_low"] == pytest.approx(math.tanh(z - 1.959963984540054 * se), rel=1e-6)
        assert t.loc[d, "ci_high"] == pytest.approx(math.tanh(z + 1.959963984540054 * se), rel=1e-6)
        assert t.loc[d, "n"] == 60


# --- themes -------------------------------------------------------------------------------------------------------

def _theme_study(n_subj=16, seed=0, effect=1.0, drop_one=False):
    weights, counts = (0.4, 0.7, 1.0, 1.3), (1, 4, 7, 10)
    clip_rows = [f"t-{w}-{n},gait,generated,,,,,,,,,,,,,happy,{w},{n},10" for w in weights for n in counts]
    clips = _clips(clip_rows)
    rng = np.random.default_rng(seed)
    rows = []
    for s in range(n_subj):
        base = rng.normal(0, 0.7)
        for wi, w in enumerate(weights):
            for ni, n in enumerate(counts):
                if drop_one and s == 0 and wi == 0 and ni == 0:
                    continue
                v = int(np.clip(np.rint(3 + base + effect * (wi + ni) / 2 + rng.normal(0, 1)), 1, 7))
                rows.append((f"s{s}", "theme_rating", f"t-{w}-{n}", "rating", v))
    return _responses(rows, clips), clips


def test_theme_anova_matches_statsmodels_anovarm():
    from statsmodels.stats.anova import AnovaRM

    r, clips = _theme_study()
    a = themes.theme_anova(r, clips).set_index("effect")
    cells = themes.theme_cells(r, clips)
    sm = AnovaRM(cells, "rating", "participant_id", within=["weight", "n_features"]).fit().anova_table
    for ours, theirs in (("weight", "weight"), ("n_features", "n_features"), ("weight * n_features",
                                                                              "weight:n_features")):
        assert a.loc[ours, "F"] == pytest.approx(sm.loc[theirs, "F Value"], rel=1e-9)
        assert a.loc[ours, "df1"] == sm.loc[theirs, "Num DF"]
        assert a.loc[ours, "df2"] == sm.loc[theirs, "Den DF"]
        assert a.loc[ours, "p_value"] == pytest.approx(sm.loc[theirs, "Pr > F"], rel=1e-6, abs=1e-300)
        assert a.loc[ours, "p_gg"] >= a.loc[ours, "p_value"] - 1e-15
    assert (a["df1"].tolist(), a["df2"].tolist()) == ([3, 3, 9], [45, 45, 135])  # seed 004 Table IV


def test_theme_anova_partial_eta_squared_by_hand():
    r, clips = _theme_study(seed=3)
    a = themes.theme_anova(r, clips).set_index("effect")
    c = themes.theme_cells(r, clips)
    y = c.pivot_table(index="participant_id", columns=["weight", "n_features"], values="rating").to_numpy()
    y = y.reshape(len(y), 4, 4)
    gm = y.mean()
    s_m, w_m = y.mean(axis=(1, 2)), y.mean(axis=(0, 2))
    sw_m = y.mean(axis=2)
    ss_w = 16 * 4 * ((w_m - gm) ** 2).sum()
    ss_err = 4 * ((sw_m - s_m[:, None] - w_m[None, :] + gm) ** 2).sum()
    assert a.loc["weight", "eta2_partial"] == pytest.approx(ss_w / (ss_w + ss_err), rel=1e-9)
    assert a.loc["weight", "F"] == pytest.approx((ss_w / 3) / (ss_err / 45), rel=1e-9)


def test_theme_anova_drops_incomplete_participants():
    r, clips = _theme_study(drop_one=True)
    a = themes.theme_anova(r, clips)
    assert (a["n_dropped"] == 1).all() and (a["n_subjects"] == 15).all()
    assert "dropped" in a["note"].iloc[0]
    assert a.loc[a.effect == "weight", "df2"].item() == 42


def test_theme_inversion_t_by_hand():
    clips = _clips(["inv-sad,gait,generated,,,,,,,,,,,,,sad,-0.7,10,10"])
    vals = [-3, -2, -4, 0, -1, -5, -2, 1]
    r = _responses([(f"p{i}", "theme_inversion", "inv-sad", "rating", v) for i, v in enumerate(vals)], clips)
    row = themes.theme_inversion(r, clips).iloc[0]
    v = np.array(vals, float)
    se = v.std(ddof=1) / math.sqrt(len(v))
    assert row["mean"] == pytest.approx(v.mean())
    assert row["se"] == pytest.approx(se)
    assert row["t"] == pytest.approx(v.mean() / se)
    assert row["p_value"] == pytest.approx(2 * stats.t.sf(abs(v.mean() / se), len(v) - 1))
    assert row["n"] == 8 and bool(row["reject"]) is True


def test_neutral_validation_shares():
    clips = _clips(["n,gait,source,0,0,0,1,,,,,,,,,,,,10"])
    answers = ["neutral"] * 12 + ["happy", "sad", "tired", "masculine"]
    r = _responses([(f"p{i}", "neutral_validation", "n", "perceived", a) for i, a in enumerate(answers)], clips)
    t = themes.neutral_validation(r).set_index("choice")
    assert t.loc["neutral", "share"] == pytest.approx(0.75)  # seed 004 Table I pattern
    assert t.loc["energetic", "share"] == 0 and t["share"].sum() == pytest.approx(1)


# --- naturalness and demographics ---------------------------------------------------------------------------------

def test_naturalness_shares_and_chi_square_by_hand():
    clips = _clips(["gen,gait,generated,1,0,0,0,,,,,,,,,,,,10", "src,gait,source,1,0,0,0,,,,,,,,,,,,10"])
    gen = [5] * 22 + [4] * 43 + [3] * 24 + [2] * 7 + [1] * 4  # seed 000 6.3.4 shares
    src = [5] * 58 + [4] * 35 + [3] * 7
    rows = [(f"a{i}", "naturalness", "gen", "naturalness", v) for i, v in enumerate(gen)]
    rows += [(f"b{i}", "naturalness", "src", "naturalness", v) for i, v in enumerate(src)]
    r = _responses(rows, clips)
    n = naturalness.naturalness(r, clips).set_index("origin")
    assert n.loc["generated", "share_at_least_3"] == pytest.approx(0.89)
    assert n.loc["source", "share_at_least_3"] == pytest.approx(1.0)
    assert n.loc["generated", "count_2"] == 7
    t = naturalness.naturalness_test(r, clips).iloc[0]
    # 2x2 table [[89, 11], [100, 0]]: expected 5.5 in the "< 3" column -> Yates chi-square by hand
    obs = np.array([[89, 11], [100, 0]], float)
    exp = obs.sum(1, keepdims=True) * obs.sum(0, keepdims=True) / obs.sum()
    chi = (((np.abs(obs - exp) - 0.5) ** 2) / exp).sum()
    assert t["share_test"] == "chi2_yates"
    assert t["share_stat"] == pytest.approx(chi)
    assert t["share_p"] == pytest.approx(stats.chi2.sf(chi, 1))
    u = stats.mannwhitneyu(gen, src).statistic
    assert t["mwu_U"] == pytest.approx(u) and t["rank_biserial"] < 0 and bool(t["reject_mwu"])


def test_demographic_chi_square_by_hand():
    clips = _clips(["g,gait,generated,1,0,0,0,,,,,,,,,,,,10"])
    pcsv = "participant_id,gender,age_group,started_at,completed_at,status,external_id\n" + "".join(
        f"p{i},{'male' if i < 20 else 'female'},18-24,,,completed,\n" for i in range(40))
    parts = read_participants(io.StringIO(pcsv))
    answers = ["happy"] * 15 + ["sad"] * 5 + ["happy"] * 8 + ["happy;sad"] * 12
    r = _responses([(f"p{i}", "emotion_choice", "g", "perceived", a) for i, a in enumerate(answers)], clips)
    t = participants.demographic_differences(r, parts).set_index("factor")
    obs = np.array([[20, 12], [15, 5]], float)  # rows female, male; columns happy, sad selections
    exp = obs.sum(1, keepdims=True) * obs.sum(0, keepdims=True) / obs.sum()
    chi = ((obs - exp) ** 2 / exp).sum()
    assert t.loc["gender", "chi2"] == pytest.approx(chi)
    assert t.loc["gender", "dof"] == 1 and t.loc["gender", "n"] == 52
    assert "age_group" not in t.index  # a single age group: nothing to compare
