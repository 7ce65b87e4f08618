"""Vectorised k-sample Anderson-Darling test (Scholz & Stephens 1987, midrank version A2akN).

The same statistic, normalisation and tabulated p-value interpolation as ``scipy.stats.anderson_ksamp(...,
variant="midrank")``, but computed from a (k x L) table of counts (k samples, L distinct values) instead of a
Python loop over samples, so k = 10,000 participants cost milliseconds. tests/test_analysis_stats.py checks it
against scipy on random data.

Formulas (Scholz & Stephens 1987, eq. 7 and the variance of section 3): with z_1 < ... < z_L the distinct pooled
values, l_j their multiplicities, B_j = #(pooled < z_j) + l_j / 2, and M_ij = #(sample i <= z_j) - f_ij / 2 where
f_ij = #(sample i == z_j),

    A2akN = (N - 1) / N * sum_i 1/n_i * sum_j l_j / N * (N M_ij - B_j n_i)^2 / (B_j (N - B_j) - N l_j / 4)

and the reported statistic is (A2akN - (k - 1)) / sigma_N.
"""

from __future__ import annotations

import math

import numpy as np

SIG = np.array([0.25, 0.1, 0.05, 0.025, 0.01, 0.005, 0.001])
_B0 = np.array([0.675, 1.281, 1.645, 1.96, 2.326, 2.573, 3.085])
_B1 = np.array([-0.245, 0.25, 0.678, 1.149, 1.822, 2.364, 3.615])
_B2 = np.array([-0.105, -0.305, -0.362, -0.391, -0.396, -0.345, -0.154])


def a2akn_from_counts(counts: np.ndarray) -> float:
    """Midrank A2akN from counts (k, L): counts[i, j] = occurrences of distinct value j (ascending) in sample i."""
    counts = np.asarray(counts, dtype=float)
    n = counts.sum(axis=1)  # (k,)
    lj = counts.sum(axis=0)  # (L,)
    N = lj.sum()
    Bj = np.cumsum(lj) - lj + lj / 2.0
    Mij = np.cumsum(counts, axis=1) - counts / 2.0
    inner = lj / N * (N * Mij - Bj * n[:, None]) ** 2 / (Bj * (N - Bj) - N * lj / 4.0)
    return float((inner.sum(axis=1) / n).sum() * (N - 1.0) / N)


def sigma_squared(n: np.ndarray) -> float:
    """Variance of A2akN under the null for sample sizes ``n`` (k,) (Scholz & Stephens 1987)."""
    n = np.asarray(n, dtype=float)
    k, N = len(n), float(n.sum())
    H = (1.0 / n).sum()
    hs_cs = (1.0 / np.arange(N - 1, 1, -1)).cumsum()
    h = hs_cs[-1] + 1
    g = (hs_cs / np.arange(2, N)).sum()
    a = (4 * g - 6) * (k - 1) + (10 - 6 * g) * H
    b = (2 * g - 4) * k**2 + 8 * h * k + (2 * g - 14 * h - 4) * H - 8 * h + 4 * g - 6
    c = (6 * h + 2 * g - 2) * k**2 + (4 * h - 4 * g + 6) * k + (2 * h - 6) * H + 4 * h
    d = (2 * h + 6) * k**2 - 4 * h * k
    return float((a * N**3 + b * N**2 + c * N + d) / ((N - 1.0) * (N - 2.0) * (N - 3.0)))


def p_from_statistic(stat: float, k: int) -> float:
    """scipy's p-value: quadratic fit of log(significance) on the tabulated critical values for k samples,
    capped to [0.001, 0.25]."""
    m = k - 1
    critical = _B0 + _B1 / math.sqrt(m) + _B2 / m
    if stat < critical.min():
        return float(SIG.max())
    if stat > critical.max():
        return float(SIG.min())
    pf = np.polyfit(critical, np.log(SIG), 2)
    return float(math.exp(np.polyval(pf, stat)))


def anderson_ksamp_groups(values: np.ndarray, groups: np.ndarray) -> tuple[float, float]:
    """k-sample AD test where sample membership is given per observation.

    values (N,) float; groups (N,) hashable labels (the k samples). Returns (statistic, p_value); (NaN, NaN) when
    fewer than two samples, fewer than two distinct values, N < 4, or a null variance that is not positive (e.g.
    every sample has one value, when the statistic is the same under any relabelling).
    """
    values = np.asarray(values, dtype=float)
    _, g = np.unique(np.asarray(groups), return_inverse=True)
    uv, v = np.unique(values, return_inverse=True)
    k, L = int(g.max()) + 1 if len(g) else 0, len(uv)
    if k < 2 or L < 2 or len(values) < 4:
        return math.nan, math.nan
    counts = np.bincount(g * L + v, minlength=k * L).reshape(k, L)
    if (counts.sum(axis=1) == 1).all():
        return math.nan, math.nan
    s2 = sigma_squared(counts.sum(axis=1))
    if not s2 > 0:
        return math.nan, math.nan
    stat = (a2akn_from_counts(counts) - (k - 1)) / math.sqrt(s2)
    return stat, p_from_statistic(stat, k)
