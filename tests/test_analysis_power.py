"""Simulated power (analysis.power) against closed forms, and the command line."""

import numpy as np
import pandas as pd
import pytest
from statsmodels.stats.power import TTestPower

from analysis import power as P


@pytest.mark.parametrize("n,dz", [(16, 0.5), (32, 0.3)])
def test_paired_t_power_matches_closed_form(n, dz):
    sims = 4000
    t = P.power_table("paired", [n], {"dz": dz}, sims=sims, seed=1)
    exact = TTestPower().power(effect_size=dz, nobs=n, alpha=0.05, alternative="two-sided")
    se = np.sqrt(exact * (1 - exact) / sims)
    assert t["power"].iloc[0] == pytest.approx(exact, abs=4 * se)


def test_one_sample_inversion_power_matches_closed_form():
    sims = 4000
    t = P.power_table("seed004", [20], {"inversion_d": 0.6}, sims=sims, seed=2)
    got = t.loc[t["test"] == "inversion", "power"].iloc[0]
    exact = TTestPower().power(effect_size=0.6, nobs=20, alpha=0.05)
    assert got == pytest.approx(exact, abs=4 * np.sqrt(exact * (1 - exact) / sims))


def test_recognition_power_rises_with_participants_and_is_small_at_chance():
    t = P.power_table("seed000", [8, 32], {"gait_hit_rate": 0.5}, sims=300, seed=3)
    assert t["power"].iloc[0] < t["power"].iloc[1]
    null = P.power_table("seed000", [16], {"gait_hit_rate": 0.25}, sims=400, seed=4)["power"].iloc[0]
    assert null < 0.1  # at chance accuracy Wagner's test rarely rejects


def test_holm_first_by_hand():
    # p = (0.02, 0.01, 0.04): sorted 0.01, 0.02, 0.04 -> 0.03, 0.04, 0.04; first hypothesis (0.02) -> 0.04
    assert P._holm_first(np.array([[0.02, 0.01, 0.04]]))[0] == pytest.approx(0.04)


def test_unknown_effect_and_preset_raise():
    with pytest.raises(ValueError):
        P.power_table("seed000", [8], {"nope": 1})
    with pytest.raises(ValueError):
        P.power_table("nope", [8])


def test_cli_writes_table_and_figure(tmp_path, capsys):
    rc = P.main(["paired", "--participants", "8", "16", "--effect", "dz=0.8", "--sims", "200", "--out",
                 str(tmp_path)])
    assert rc == 0
    assert "| paired_t | dz=0.8 | 16 |" in capsys.readouterr().out
    assert len(pd.read_csv(tmp_path / "power.csv")) == 2
    assert (tmp_path / "power.png").read_bytes()[:4] == b"\x89PNG"
