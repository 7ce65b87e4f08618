"""The simulator's known effects are found by the analyses, and null effects are not (most seeds)."""

import numpy as np
import pandas as pd
import pytest

from analysis import participants as parts_mod
from analysis import themes, vad
from analysis.io import load_study
from analysis.simulate import simulate_study
from protocol import vocabulary as P


def _load(r, c, p):
    import io

    bufs = []
    for df in (r, c, p):
        b = io.StringIO(df.to_csv(index=False))
        bufs.append(b)
    return load_study(*bufs)


def test_marked_synthetic():
    r, c, p = simulate_study(20, seed=4, completion_rate=0.8)
    assert p["participant_id"].str.startswith("sim-").all() and c["clip_id"].str.startswith("sim-").all()
    assert (p["external_id"] == "synthetic").all()
    assert set(p.loc[p["status"] == "abandoned", "completed_at"]) <= {""}
    d = _load(r, c, p)
    assert parts_mod.participant_summary(d.participants, d.responses)["synthetic"] is True


def _protocol_violations(r, c, p) -> list[str]:
    """What in a simulated study breaks the study protocol (protocol.vocabulary), checked row by row."""
    problems = []
    modality = c.set_index("clip_id")["modality"]
    for row in r.itertuples(index=False):
        kind = P.SECTION_QUESTIONS.get(row.section_type, {}).get(row.question)
        if kind is None:
            problems.append(f"question {row.question!r} is not asked in {row.section_type!r}")
            continue
        answer = str(row.answer)
        if kind in P.MULTI_SELECT_KINDS:
            labels = answer.split(";")
            order = [P.LABEL_CHOICES[kind].index(a) for a in labels if a in P.LABEL_CHOICES[kind]]
            if len(order) != len(labels) or order != sorted(set(order)):
                problems.append(f"{answer!r} is not distinct {kind} labels in protocol order")
        elif answer not in P.answer_values(kind):
            problems.append(f"{answer!r} is not a {kind} answer")
        want = P.SECTION_MODALITY[row.section_type]
        if row.clip_id not in modality.index:
            problems.append(f"unknown clip {row.clip_id!r}")
        elif want is not None and modality[row.clip_id] != want:
            problems.append(f"{row.section_type} shows {row.clip_id!r}, not a {want} clip")
    if not set(r["participant_id"]) <= set(p["participant_id"]):
        problems.append("answers of unknown participants")
    repeated = r.duplicated(["participant_id", "section_type", "clip_id", "question"])
    problems += [f"{row.participant_id} answers {row.section_type}/{row.clip_id}/{row.question} twice"
                 for row in r[repeated].itertuples(index=False)]
    return problems


def test_simulated_answers_follow_the_protocol():
    """Every answer is a question of its section with a value in the protocol's domain, about a known clip of
    the section's modality; no clip question is answered twice; every completed participant answered every
    question of every section, and the same number of answers (a balanced design); read_responses accepts it."""
    r, c, p = simulate_study(20, seed=4, completion_rate=0.8)
    assert _protocol_violations(r, c, p) == []
    done = p.loc[p["status"] == "completed", "participant_id"]
    assert len(done) >= 10
    completed = r[r["participant_id"].isin(done)]
    asked = set(zip(completed["section_type"], completed["question"]))
    for pid, answers in completed.groupby("participant_id"):
        assert set(zip(answers["section_type"], answers["question"])) == asked, pid
    assert asked == {(s, q) for s, questions in P.SECTION_QUESTIONS.items() for q in questions}
    assert completed.groupby("participant_id").size().nunique() == 1
    # the check can fail: a gesture answer outside the MPI categories, a Likert 5, a repeated answer
    bad = r.copy()
    bad.loc[bad.index[bad["section_type"] == "gesture_emotion"][0], "answer"] = "happy"
    bad.loc[bad.index[bad["section_type"] == "affect_likert"][0], "answer"] = "5"
    bad = pd.concat([bad, bad.iloc[[0]]])
    assert len(_protocol_violations(bad, c, p)) == 3
    assert len(_load(r, c, p).responses) == len(r)


def test_same_seed_same_study():
    a = simulate_study(5, seed=7)[0]
    b = simulate_study(5, seed=7)[0]
    assert a.equals(b)


def test_theme_effects_found_with_16_participants():
    """Seed 004 Table IV setting: 16 participants, 4 x 4 design; both main effects found for every theme."""
    d = _load(*simulate_study(16, seed=11, completion_rate=1.0))
    a = themes.theme_anova(d.responses, d.clips)
    main = a[a["effect"] != "weight * n_features"]
    assert len(main) == 12 and (main["p_gg"] < 1e-4).all()
    assert (main["df1"] == 3).all() and (main["df2"] == 45).all()
    desc = themes.theme_descriptives(d.responses, d.clips)
    lo = desc[(desc.weight == 0.4) & (desc.n_features == 1)]["mean"].mean()
    hi = desc[(desc.weight == 1.3) & (desc.n_features == 10)]["mean"].mean()
    assert hi > lo + 0.3


def test_no_theme_effect_rarely_significant():
    """With weight_effect = feature_effect = 0, main effects are significant at 0.05 in about 5% of tests."""
    rejections, tests = 0, 0
    for seed in range(12):
        d = _load(*simulate_study(16, seed=100 + seed, completion_rate=1.0, weight_effect=0.0, feature_effect=0.0))
        a = themes.theme_anova(d.responses, d.clips)
        main = a[a["effect"] != "weight * n_features"]
        rejections += int((main["p_gg"] < 0.05).sum())
        tests += len(main)
    assert tests == 144
    assert rejections / tests < 0.12


def test_inversion_found_and_null_not():
    d = _load(*simulate_study(16, seed=5, completion_rate=1.0))
    inv = themes.theme_inversion(d.responses, d.clips)
    assert (inv["mean"] < 0).all() and inv["reject"].all()
    zero = {t: 0.0 for t in inv["theme"]}
    rejected = 0
    for seed in range(8):
        d = _load(*simulate_study(16, seed=200 + seed, completion_rate=1.0, inversion_mean=zero))
        rejected += int(themes.theme_inversion(d.responses, d.clips)["reject"].sum())
    assert rejected / 48 < 0.15


def test_vad_correlation_found():
    d = _load(*simulate_study(50, seed=6))
    v = vad.vad_pearson(d.responses, d.clips)
    assert (v["r"] > 0.5).all() and (v["p_value"] < 1e-6).all() and (v["ci_low"] < v["r"]).all()


def test_no_demographic_effect_rarely_significant():
    rejected, tests = 0, 0
    for seed in range(6):
        d = _load(*simulate_study(60, seed=300 + seed))
        t = parts_mod.demographic_differences(d.responses, d.participants)
        rejected += int(t["reject"].sum())
        tests += len(t)
    assert tests >= 12
    assert rejected / tests < 0.2


@pytest.mark.parametrize("noise,expect_reject", [(0.0, False), (0.9, True)])
def test_gait_emotions_recovered_or_not(noise, expect_reject):
    """Without perception noise and multi-select, perceived vectors equal the intended ones (no rejection); with
    heavy noise the perceived vector of a fully happy gait has four non-zero components and the test rejects
    (seed 000 Table 3, Gait 2)."""
    from analysis import emotion

    d = _load(*simulate_study(80, seed=8, emotion_noise=noise, multi_select_prob=0.0))
    g = emotion.gait_emotion_ad(d.responses, d.clips).set_index("clip_id")
    happy, mixed = "sim-seed000-single_happy_loop", "sim-seed000-single_happy_neutral"   # (1,0,0,0), (.6,0,0,.4)
    pure = g[(g.filter(like="intended_") == 1).any(axis=1)]
    assert len(pure) == 8                       # seed000's pure emotions on two paths
    if noise == 0.0:
        assert not g["reject"].any()
        assert g.loc[mixed, "perceived_happy"] == pytest.approx(0.6, abs=0.15)
        assert np.isclose(g.loc[happy, "perceived_happy"], 1.0)
    else:                   # 2.111 without ties among four non-zero perceived components, whatever they are
        full = pure[(pure.filter(like="perceived_") > 0).all(axis=1)]
        assert len(full) >= 6 and full["reject"].all() and (full["statistic"] > 1.9).all()
