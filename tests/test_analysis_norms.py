"""Per-clip norms (analysis.norms): columns, the statistics against their libraries, the report folder, exclusions,
recovery of a SIMULATED norming study's truth, and clip_norms.csv read back with its errors."""

import io
import json

import numpy as np
import pandas as pd
import pytest
from scipy import stats
from statsmodels.stats.proportion import proportion_confint

from analysis.design import read_planned_clips
from analysis.emotion import gait_emotion_ad
from analysis.io import ValidationError, load_study
from analysis.norms import clip_norms, read_clip_norms
from analysis.norms_simulate import simulate_norming
from analysis.report import write_report
from protocol.vocabulary import CLIP_NORMS_COLUMNS


def _csv(df: pd.DataFrame) -> io.StringIO:
    return io.StringIO(df.to_csv(index=False))


def demo_candidates() -> pd.DataFrame:
    """The demo plan's norming candidates (SIMULATED clip rows of analysis/data/planned_clips.csv): single-emotion
    walks, gestures, positive-weight theme clips."""
    c = read_planned_clips()
    return c[(c["plan"] == "demo") & c["final_happy"].isna() & (c["theme"] != "neutral")
             & ~(c["weight"] < 0)].reset_index(drop=True)


@pytest.fixture(scope="module")
def simulated():
    sim = simulate_norming(demo_candidates(), 80, 5, seed=3)
    data = load_study(_csv(sim.responses), _csv(sim.clips), _csv(sim.participants))
    return sim, data, clip_norms(data.responses, data.clips)


def test_columns_and_rows(simulated):
    sim, data, norms = simulated
    assert list(norms.columns[:len(CLIP_NORMS_COLUMNS)]) == list(CLIP_NORMS_COLUMNS)
    shares = [c for c in norms.columns if c.startswith("share_")]
    assert shares[:4] == ["share_happy", "share_sad", "share_angry", "share_neutral"]
    assert {"share_afraid", "share_proud", "share_1", "share_7"} <= set(shares)
    assert len(norms) == len(sim.clips)   # one emotion question per candidate clip
    sums = norms[shares].sum(axis=1, min_count=1)
    assert np.allclose(sums, 1)
    gait = norms[norms["section_type"] == "emotion_choice"]
    assert gait[["share_afraid", "share_1"]].isna().all().all()
    # the cyclic design: 8 walks x 80 participants / 5 per participant = 80 ratings each
    assert set(gait["n_ratings"]) == {50}
    themes = norms[norms["section_type"] == "theme_rating"]
    assert themes["intended"].isna().all() and themes["intended_share"].isna().all()


def test_statistics_match_their_libraries(simulated):
    _, data, norms = simulated
    gait = norms[norms["section_type"] == "emotion_choice"].set_index("clip_id")
    ad = gait_emotion_ad(data.responses, data.clips).set_index("clip_id")
    assert np.allclose(gait["ad_statistic"], ad.loc[gait.index, "statistic"], equal_nan=True)
    assert np.allclose(gait["ad_p_value"], ad.loc[gait.index, "p_value"])
    for e in ("happy", "sad", "angry", "neutral"):
        assert np.allclose(gait[f"share_{e}"], ad.loc[gait.index, f"perceived_{e}"])
    # gestures: one label per answer, the plain Wilson interval
    row = norms[norms["section_type"] == "gesture_emotion"].iloc[0]
    lo, hi = proportion_confint(row["intended_share"] * row["n_ratings"], row["n_ratings"], method="wilson")
    assert (row["intended_ci_low"], row["intended_ci_high"]) == pytest.approx((lo, hi))
    # walks with two-label answers: Wilson with Kish's effective n (narrower than with n)
    row = norms.iloc[0]
    r = data.responses
    own = r[(r["clip_id"] == row["clip_id"]) & (r["question"] == "perceived")]["answer"].astype(str)
    x = np.array([(row["intended"] in a.split(";")) / len(a.split(";")) for a in own])
    n_eff = len(x) * x.mean() * (1 - x.mean()) / x.var()
    lo, hi = proportion_confint(x.mean() * n_eff, n_eff, method="wilson")
    assert (row["intended_ci_low"], row["intended_ci_high"]) == pytest.approx((lo, hi))
    plain = proportion_confint(x.mean() * len(x), len(x), method="wilson")
    assert hi - lo < plain[1] - plain[0]
    shares = [c for c in norms.columns if c.startswith("share_")]
    p = row[shares].dropna().to_numpy(float)
    assert row["entropy_bits"] == pytest.approx(stats.entropy(p, base=2))
    r = data.responses
    one = r[(r["clip_id"] == row["clip_id"]) & (r["question"] == "intensity")]
    assert row["intensity_mean"] == pytest.approx(one["value"].mean())


def test_recovers_the_simulated_truth(simulated):
    sim, _, norms = simulated
    m = norms.merge(sim.truth, on=["clip_id", "section_type", "question"], suffixes=("", "_true"))
    errors = [(m[c] - m[f"{c}_true"]).abs() for c in norms.columns if c.startswith("share_") and f"{c}_true" in m]
    mae = float(pd.concat(errors).dropna().mean())
    assert mae < 0.05


def test_report_folder_has_norms_and_excludes(tmp_path):
    sim = simulate_norming(demo_candidates(), 40, 5, seed=4)
    parts = sim.participants.copy()
    parts["attention_passed"], parts["attention_total"] = 1, 1
    parts.loc[0, "attention_passed"] = 0          # fails the attention check: excluded
    paths = {}
    for name, df in (("responses", sim.responses), ("clips", sim.clips), ("participants", parts)):
        paths[name] = tmp_path / f"{name}.csv"
        df.to_csv(paths[name], index=False)
    out = tmp_path / "report"
    report = write_report(paths["responses"], paths["clips"], paths["participants"], out)
    on_disk = pd.read_csv(out / "clip_norms.csv")
    assert list(on_disk.columns[:len(CLIP_NORMS_COLUMNS)]) == list(CLIP_NORMS_COLUMNS)
    assert len(report["clip_norms"]) == len(on_disk)
    assert json.loads((out / "report.json").read_text())["clip_norms"][0]["clip_id"] == on_disk["clip_id"][0]
    kept = sim.responses[sim.responses["participant_id"] != parts.loc[0, "participant_id"]]
    first = on_disk.iloc[0]
    assert first["n_ratings"] == ((kept["clip_id"] == first["clip_id"]) & (kept["question"] == first["question"])
                                  & (kept["section_type"] == first["section_type"])).sum()
    for modality in ("gait", "gesture"):
        assert (out / f"fig_clip_norms_{modality}.png").read_bytes()[:4] == b"\x89PNG"
    read_clip_norms(out / "clip_norms.csv", known_clips=sim.clips["clip_id"])


def _norms_csv(tmp_path, simulated, edit) -> str:
    _, _, norms = simulated
    df = norms.copy()
    df = edit(df) if edit else df
    path = tmp_path / "clip_norms.csv"
    df.to_csv(path, index=False)
    return path


def _problems(path, known=None) -> list[str]:
    with pytest.raises(ValidationError) as err:
        read_clip_norms(path, known_clips=known)
    return [str(p) for p in err.value.problems]


def test_read_back_errors_name_file_line_column(tmp_path, simulated):
    ok = read_clip_norms(_norms_csv(tmp_path, simulated, None))
    assert len(ok) == len(simulated[2])
    problems = _problems(_norms_csv(tmp_path, simulated, lambda d: d.drop(columns="entropy_bits")))
    assert problems == [problems[0]] and "clip_norms.csv header, column 'entropy_bits'" in problems[0]
    problems = _problems(_norms_csv(tmp_path, simulated, None), known=["sim-demo-happy_loop"])
    assert problems[0] == ("clip_norms.csv line 2, column 'clip_id': unknown clip 'sim-demo-angry_hairpin' (not in "
                           "the catalogue)")
    assert not any("line 3," in p for p in problems)         # sim-demo-happy_loop is known

    def skew(d):
        d.loc[1, "share_sad"] = d.loc[1, "share_sad"] + 0.1
        return d
    problems = _problems(_norms_csv(tmp_path, simulated, skew))
    assert len(problems) == 1 and problems[0].startswith(
        "clip_norms.csv line 3, columns 'share_happy', 'share_sad', 'share_angry', 'share_neutral': shares of "
        "emotion_choice/perceived sum to 1.1, not 1 (")

    def bad_number(d):
        d["n_ratings"] = d["n_ratings"].astype(object)
        d.loc[0, "n_ratings"] = "many"
        return d
    assert _problems(_norms_csv(tmp_path, simulated, bad_number)) == [
        "clip_norms.csv line 2, column 'n_ratings': 'many' is not a number"]
