"""Seed 004 Gaussian RBF model (eqs. 3-5, Fig. 4 shapes) and the Table III theme data."""
from __future__ import annotations

import numpy as np
import pytest

from generation.rbf import basis as R
from generation.rbf.themes import AXES, BODY_PARTS, TABLE_III, THEME_NAMES, THEMES, Feature, theme_features


# ---- equations 3-5 ------------------------------------------------------------------------------------
def test_rbf_is_the_gaussian_of_eq3():
    t = np.array([50.0, 60.0, 40.0, 80.0])
    np.testing.assert_allclose(R.rbf(t, 50.0, 100.0), np.exp(-np.array([0, 100, 100, 900]) / 200.0))


def test_rbf_sum_is_weighted_sum_of_eq4():
    t = np.arange(100.0)
    params = np.array([[0.3, 20.0, 64.0], [-0.1, 70.0, 25.0]])
    expected = 0.3 * np.exp(-(t - 20) ** 2 / 128.0) - 0.1 * np.exp(-(t - 70) ** 2 / 50.0)
    np.testing.assert_allclose(R.rbf_sum(t, params), expected)
    assert np.all(R.rbf_sum(t, np.zeros((0, 3))) == 0)


def test_circular_rbf_is_continuous_across_the_cycle_seam():
    m = 100
    for mu in (0.0, 5.0, 95.0):
        f = R.rbf_sum(np.array([0.0, float(m), -1.0, m - 1.0]), np.array([[1.0, mu, 150.0]]), period=m)
        assert f[0] == pytest.approx(f[1])
        assert f[2] == pytest.approx(f[3])
    # open-interval version of eq. 3 is not periodic
    assert R.rbf(np.array(0.0), 95.0, 150.0) != pytest.approx(R.rbf(np.array(100.0), 95.0, 150.0))


@pytest.mark.parametrize("bad, message", [
    (np.ones((4, 3)), "at most 3"),
    (np.array([[1.0, 10.0, 0.0]]), "variances must be positive"),
    (np.ones((2, 2)), "expected (M, 3)"),
    (np.array([[np.nan, 1.0, 1.0]]), "non-finite"),
])
def test_bad_parameters_are_rejected_with_a_reason(bad, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        R.rbf_sum(np.arange(10.0), bad)


def test_q_matrix_round_trip_eq5():
    dofs = [np.array([[0.1, 10.0, 4.0]]), np.zeros((0, 3)), np.array([[0.2, 5.0, 9.0], [-0.2, 55.0, 9.0]])]
    Q = R.q_matrix(dofs)
    assert Q.shape == (3, 9)
    traj = R.evaluate_q(Q, m=100)
    assert traj.shape == (100, 3)
    t = np.arange(100.0)
    for i, p in enumerate(dofs):
        np.testing.assert_allclose(traj[:, i], R.rbf_sum(t, p))


def test_average_q_sorts_rbfs_by_mean_before_averaging():
    a = R.q_matrix([np.array([[0.2, 10.0, 4.0], [-0.4, 60.0, 9.0]])])
    b = R.q_matrix([np.array([[-0.2, 70.0, 9.0], [0.4, 20.0, 4.0]])])  # same kind of edit, other order
    avg = R.average_q([a, b])
    np.testing.assert_allclose(R.params_from_q_row(avg[0]), [[0.3, 15.0, 4.0], [-0.3, 65.0, 9.0]])
    with pytest.raises(ValueError, match="shape"):
        R.average_q([a, np.zeros((2, 9))])


# ---- Fig. 4 shapes --------------------------------------------------------------------------------------
def test_type1_posture_offset_is_flat():
    f = R.rbf_sum(np.arange(100.0), R.shape_params(1, 0.05), period=100)
    assert f.min() > 0.99 * 0.05 and f.max() <= 0.05 + 1e-12


def test_type2_one_bump():
    f = R.rbf_sum(np.arange(100.0), R.shape_params(2, 0.05, (30.0,)), period=100)
    assert int(np.argmax(f)) == 30 and f.max() == pytest.approx(0.05)
    assert f[80] < 0.01 * 0.05


def test_type3_two_bumps_same_sign():
    f = R.rbf_sum(np.arange(100.0), R.shape_params(3, 0.05, (25.0, 75.0)), period=100)
    peaks = [i for i in range(100) if f[i] > f[i - 1] and f[i] >= f[(i + 1) % 100]]
    assert peaks == [25, 75] and f.min() >= 0


def test_type4_opposing_extrema_and_mirror():
    params = R.shape_params(4, 0.05, (25.0, 75.0))
    f = R.rbf_sum(np.arange(100.0), params, period=100)
    assert int(np.argmax(f)) == 25 and int(np.argmin(f)) == 75
    assert f.max() == pytest.approx(-f.min(), rel=1e-6)
    g = R.rbf_sum(np.arange(100.0), R.mirrored(params), period=100)
    np.testing.assert_allclose(g, -f)
    np.testing.assert_array_equal(R.mirrored(params)[:, 1:], params[:, 1:])  # only alpha changes


def test_shape_needs_the_right_number_of_centres():
    with pytest.raises(ValueError, match="needs 2"):
        R.shape_params(4, 1.0, (10.0,))
    with pytest.raises(ValueError, match="1, 2, 3 or 4"):
        R.shape_params(5, 1.0)


def test_scaled_inverts_only_alpha():
    p = R.shape_params(4, 0.05, (25.0, 75.0))
    q = R.scaled(p, -0.7)
    np.testing.assert_allclose(q[:, 0], -0.7 * p[:, 0])
    np.testing.assert_array_equal(q[:, 1:], p[:, 1:])


# ---- placing movement features on a neutral trajectory -----------------------------------------------
def test_swing_type4_sits_on_the_extrema_and_increases_the_swing():
    t = np.arange(100.0)
    x = 0.2 * np.sin(2 * np.pi * (t - 10) / 100)  # max at 35, min at 85
    p = R.swing_params(x, 4, 0.03)
    np.testing.assert_allclose(p[:, :2], [[0.03, 35.0], [-0.03, 85.0]])
    y = x + R.rbf_sum(t, p, period=100)
    assert np.ptp(y) > np.ptp(x) + 0.05
    y_dec = x + R.rbf_sum(t, R.swing_params(x, 4, -0.03), period=100)
    assert np.ptp(y_dec) < np.ptp(x) - 0.05


def test_swing_type3_finds_two_peaks_per_cycle():
    t = np.arange(100.0)
    x = 0.03 * np.cos(4 * np.pi * (t - 20) / 100)  # peaks at 20 and 70
    p = R.swing_params(x, 3, 0.01)
    np.testing.assert_allclose(p[:, 1], [20.0, 70.0])
    assert np.all(p[:, 0] == 0.01)


def test_swing_type2_follows_the_sign_of_the_largest_deviation():
    t = np.arange(100.0)
    x = -0.1 * np.exp(-((t - 60) ** 2) / 50.0)  # a dip at 60
    p = R.swing_params(x, 2, 0.02)
    assert p[0, 1] == 60.0 and p[0, 0] == pytest.approx(-0.02)  # increased swing deepens the dip


# ---- Table III as data -----------------------------------------------------------------------------
def test_six_themes_with_ten_features_in_table_order():
    assert set(THEMES) == set(THEME_NAMES)
    for theme in THEME_NAMES:
        feats = THEMES[theme]
        assert [f.rank for f in feats] == list(range(1, 11))
        assert tuple(f.describe() for f in feats) == TABLE_III[theme]


def test_first_n_features():
    for n in (1, 4, 7, 10):
        assert theme_features("sad", n, "visual") == THEMES["sad"][:n]
        assert [f.rank for f in theme_features("sad", n, "calibrated")] == [f.rank for f in THEMES["sad"][:n]]
        # the default (extended) set adds our own rows only to the full set: the first-n study stays Table III's
        ours = [f.rank for f in theme_features("sad", n)]
        assert ours == [f.rank for f in THEMES["sad"][:n]] + ([11, 12, 13] if n == 10 else [])
    assert [f.source for f in theme_features("sad")] == ["table_iii"] * 10 + ["ours"] * 3
    with pytest.raises(ValueError, match="n_features"):
        theme_features("sad", 11)
    with pytest.raises(ValueError, match="unknown theme"):
        theme_features("angry", 4)


def test_posture_features_are_shape1_and_movement_shapes_2_to_4():
    for feats in THEMES.values():
        for f in feats:
            assert (f.shape == 1) == (f.kind == "tilt")
            assert f.part in BODY_PARTS and f.axis in AXES and 0 < f.intensity < 0.1


def test_sad_and_tired_are_mostly_posture_the_others_mostly_movement():
    # Table II: sad 75.5 % and tired 87.1 % posture; happy, energetic, feminine, masculine mostly movement.
    posture = {t: sum(f.kind == "tilt" for f in THEMES[t]) for t in THEMES}
    assert posture["sad"] >= 7 and posture["tired"] >= 7
    for t in ("happy", "energetic", "masculine"):
        assert posture[t] <= 4


def test_strongest_features_as_in_fig5():
    # wrist swing along Z (happy), ankle swing along Z (tired), ankle swing along Y (masculine) are strongest
    def strongest(theme):
        return max(THEMES[theme], key=lambda f: f.intensity).describe()

    assert strongest("happy") == "Wrists: increased swing along Z"
    assert strongest("tired") == "Ankles: decreased swing along Z"
    assert strongest("masculine") == "Ankles: increased swing along Y"
    top = sorted((f.intensity for fs in THEMES.values() for f in fs), reverse=True)[:3]
    assert top == [0.07, 0.07, 0.07]


def test_side_signs_follow_the_table_and_our_axes():
    # feminine: "Ankles: tilted, R along +X, L along -X" = towards the midline (left = +x in our frame)
    ankles = THEMES["feminine"][1]
    assert dict(ankles.joint_signs()) == {"left_heel": -1, "right_heel": +1}
    knees = THEMES["masculine"][1]
    assert dict(knees.joint_signs()) == {"left_knee": +1, "right_knee": -1}


def test_feature_validation_names_the_feature():
    with pytest.raises(ValueError, match="feature 3 \\(ears\\)"):
        Feature(3, "ears", "X", "tilt", 1, 1, 0.01)
    with pytest.raises(ValueError, match="shape 1"):
        Feature(1, "head", "Y", "tilt", 1, 2, 0.01)
    with pytest.raises(ValueError, match="axis"):
        Feature(1, "head", "W", "tilt", 1, 1, 0.01)


def test_swing_on_a_still_dof_uses_the_mid_stances():
    p = R.swing_params(np.zeros(100), 4, 0.02)
    np.testing.assert_allclose(p[:, :2], [[0.02, 25.0], [-0.02, 75.0]])
    assert R.swing_params(np.ones(100), 3, 0.02)[:, 1].tolist() == [25.0, 75.0]
