"""Crossed random-effects models (analysis.mixed): recovery of known variance components and fixed effects."""

import numpy as np
import pandas as pd
import pytest

from analysis import mixed as M


def test_crossed_model_recovers_variance_components():
    # 60 participants x 20 clips, every participant rates every clip: y = 2 + 0.8 x + u_p + w_c + e with
    # var(u) = 1.0, var(w) = 0.5, var(e) = 1.0. Standard errors of the REML variance estimates are about
    # 1.0 * sqrt(2/59) = 0.18 (participant) and 0.5 * sqrt(2/19) = 0.16 (clip); residual about 0.04.
    rng = np.random.default_rng(7)
    n_p, n_c = 60, 20
    p = np.repeat(np.arange(n_p), n_c)
    c = np.tile(np.arange(n_c), n_p)
    x = np.linspace(-1, 1, n_c)[c]  # a clip-level predictor, like weight
    y = 2 + 0.8 * x + rng.normal(0, 1.0, n_p)[p] + rng.normal(0, np.sqrt(0.5), n_c)[c] + rng.normal(0, 1, len(p))
    d = pd.DataFrame({"participant": [f"p{i}" for i in p], "clip": [f"c{j}" for j in c], "y": y, "x": x})
    out = M.crossed_mixed_model(d, "y ~ x", "test").set_index("term")
    assert out.loc["participant", "estimate"] == pytest.approx(1.0, abs=0.5)
    assert out.loc["clip", "estimate"] == pytest.approx(0.5, abs=0.4)
    assert out.loc["residual", "estimate"] == pytest.approx(1.0, abs=0.12)
    assert out.loc["x", "estimate"] == pytest.approx(0.8, abs=0.6)
    assert out.loc["x", "ci_low"] < 0.8 < out.loc["x", "ci_high"]
    assert out["converged"].all() and (out["n_participants"] == n_p).all() and (out["n_clips"] == n_c).all()


def test_term_names_are_readable():
    assert M._term_name("C(emotion, Treatment('neutral'))[T.happy]") == "emotion[happy]"
    assert M._term_name("weight_c:n_features_c") == "weight_c:n_features_c"
