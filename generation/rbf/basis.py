"""Gaussian radial basis functions as secondary (style) features: seed 004, equations 3-5 and Fig. 4.

Etemad & Arya (IEEE THMS 2016) model the style edit of one degree of freedom (one Cartesian axis of one
joint's trajectory over an m-frame walk cycle) as a sum of at most three Gaussian RBFs::

    phi(t; mu, sigma2) = exp(-|t - mu|^2 / (2 sigma2))                  (eq. 3)
    Phi_i(t)           = sum_j alpha_j * phi(t; mu_j, sigma2_j)            (eq. 4)
    Q                  = n x 3M matrix of {alpha, mu, sigma2} per DOF      (eq. 5)

Time ``t`` is in frames of the cycle (the paper's cycle is 100 frames), ``mu`` in frames, ``sigma2`` in
frames squared, ``alpha`` in metres (or in walker heights before de-normalisation; Fig. 5 reports
amplitudes divided by the walker's height).

The four common shapes of Fig. 4 are built by :func:`shape_params`:
1. posture offset: one RBF wide enough to be flat over the cycle (a tilt);
2. one bump: one RBF (raise or lower an existing extremum once per cycle);
3. two bumps: two RBFs of the same sign (e.g. a head sway with each step);
4. opposing extrema: two RBFs of opposite sign (e.g. hip sway left on one step, right on the other).
Left/right counterparts use vertically mirrored (-alpha) versions (:func:`mirrored`).

Because our walks repeat the cycle, :func:`rbf` can evaluate the Gaussian with circular time distance
(``period=m``) so that an edit is continuous across the seam between repeated cycles; with ``period=None``
it is exactly eq. 3 on the open interval.
"""
from __future__ import annotations

import numpy as np

MAX_RBFS_PER_DOF = 3  # the paper limits M <= 3 (section III-D)
CYCLE_FRAMES = 100  # the paper's averaged neutral cycle is 100 frames long

# Widths (sigma, frames of a 100-frame cycle) used for the shapes. The paper shows the shapes (Fig. 4)
# but not their widths; these are our choices, documented in docs/rbf.md.
POSTURE_SIGMA_CYCLES = 4.0  # type 1: sigma = 4 cycles, so the offset varies < 1 % over the cycle
BUMP_SIGMA_CYCLES = 0.12  # types 2 and 4: about a quarter of the cycle above half height
DOUBLE_BUMP_SIGMA_CYCLES = 0.08  # type 3: two bumps per cycle, narrower


def rbf(t: np.ndarray, mu: float, sigma2: float, period: float | None = None) -> np.ndarray:
    """Gaussian RBF of eq. 3.

    Args:
        t: (...) frame times.
        mu: mean, frames.
        sigma2: variance, frames squared (> 0).
        period: if given, the distance |t - mu| is taken on a circle of this length (frames) so the
            function is continuous when the cycle repeats.

    Returns:
        (...) values in (0, 1].
    """
    if not sigma2 > 0:
        raise ValueError(f"RBF variance must be positive, got sigma2={sigma2}")
    d = np.asarray(t, dtype=np.float64) - mu
    if period is not None:
        d = np.abs(d) % period
        d = np.minimum(d, period - d)
    return np.exp(-(d * d) / (2.0 * sigma2))


def validate_params(params: np.ndarray, where: str = "RBF parameters") -> np.ndarray:
    """Check an (M, 3) array of (alpha, mu, sigma2) rows; return it as float64.

    Raises ValueError naming ``where`` when M > 3, the shape is wrong or a variance is not positive.
    """
    p = np.asarray(params, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"{where}: expected (M, 3) rows of (alpha, mu, sigma2), got shape {p.shape}")
    if p.shape[0] > MAX_RBFS_PER_DOF:
        raise ValueError(f"{where}: at most {MAX_RBFS_PER_DOF} RBFs per degree of freedom, got {p.shape[0]}")
    if not np.isfinite(p).all():
        raise ValueError(f"{where}: non-finite value in {p.tolist()}")
    if (p[:, 2] <= 0).any():
        raise ValueError(f"{where}: variances must be positive, got {p[:, 2].tolist()}")
    return p


def rbf_sum(t: np.ndarray, params: np.ndarray, period: float | None = None) -> np.ndarray:
    """Secondary-feature trajectory Phi(t) of eq. 4.

    Args:
        t: (m,) frame times.
        params: (M, 3) rows (alpha, mu, sigma2), M <= 3 (M = 0 gives zeros).
        period: circular time (see :func:`rbf`).

    Returns:
        (m,) displacement in the units of alpha.
    """
    p = validate_params(params)
    t = np.asarray(t, dtype=np.float64)
    out = np.zeros_like(t)
    for alpha, mu, sigma2 in p:
        out = out + alpha * rbf(t, mu, sigma2, period)
    return out


def q_matrix(dof_params: list[np.ndarray]) -> np.ndarray:
    """Parameter matrix Q of eq. 5: (n, 3 * 3) with rows {alpha, mu, sigma2} x up to 3 RBFs per DOF.

    Missing RBFs are zero rows' worth of columns (alpha = 0), as in the paper's recorded sets.
    A zero-alpha RBF carries sigma2 = 1 so that evaluation stays defined.
    """
    Q = np.zeros((len(dof_params), 3 * MAX_RBFS_PER_DOF))
    Q[:, 2::3] = 1.0
    for i, params in enumerate(dof_params):
        p = validate_params(params, f"DOF {i}")
        Q[i, : 3 * len(p)] = p.reshape(-1)
    return Q


def params_from_q_row(row: np.ndarray) -> np.ndarray:
    """(3M,) row of Q -> (M', 3) parameters without the all-zero (unused) RBFs."""
    p = np.asarray(row, dtype=np.float64).reshape(-1, 3)
    return p[p[:, 0] != 0.0]


def evaluate_q(Q: np.ndarray, m: int = CYCLE_FRAMES, period: float | None = None) -> np.ndarray:
    """Secondary-feature set {Phi_1..Phi_n} of a Q matrix: (n, 3M) -> (m, n) displacements."""
    Q = np.asarray(Q, dtype=np.float64)
    if Q.ndim != 2 or Q.shape[1] % 3:
        raise ValueError(f"Q must be (n, 3M), got {Q.shape}")
    t = np.arange(m, dtype=np.float64)
    return np.stack([rbf_sum(t, params_from_q_row(row), period) for row in Q], axis=1)


def average_q(q_matrices: list[np.ndarray]) -> np.ndarray:
    """Consolidate several animators' Q matrices into one (section V).

    Each DOF's RBFs are first sorted by mean (unused RBFs, alpha = 0, go last), then the matrices are
    averaged element-wise. Shapes: k x (n, 3M) -> (n, 3M).
    """
    if not q_matrices:
        raise ValueError("average_q needs at least one Q matrix")
    shape = np.asarray(q_matrices[0]).shape
    sorted_q = []
    for k, Q in enumerate(q_matrices):
        Q = np.asarray(Q, dtype=np.float64)
        if Q.shape != shape:
            raise ValueError(f"Q matrix {k} has shape {Q.shape}, expected {shape}")
        out = np.zeros_like(Q)
        out[:, 2::3] = 1.0
        for i, row in enumerate(Q):
            p = row.reshape(-1, 3)
            used = p[p[:, 0] != 0.0]
            used = used[np.argsort(used[:, 1], kind="stable")]
            out[i, : used.size] = used.reshape(-1)
        sorted_q.append(out)
    return np.mean(sorted_q, axis=0)


def mirrored(params: np.ndarray) -> np.ndarray:
    """Vertically mirrored (-alpha) version of a feature, used for the other side's joint (section V-C1)."""
    p = validate_params(params).copy()
    p[:, 0] = -p[:, 0]
    return p


def scaled(params: np.ndarray, weight: float) -> np.ndarray:
    """Weighted feature: alpha -> weight * alpha; mu and sigma2 unchanged (negative weights invert only alpha)."""
    p = validate_params(params).copy()
    p[:, 0] = weight * p[:, 0]
    return p


def shape_params(shape: int, alpha: float, mus: tuple[float, ...] = (), m: int = CYCLE_FRAMES) -> np.ndarray:
    """RBF parameters of the common shapes of Fig. 4.

    Args:
        shape: 1 posture offset, 2 one bump, 3 two bumps (same sign), 4 opposing extrema.
        alpha: amplitude (metres or walker heights). For type 4 the first RBF gets +alpha and the second -alpha.
        mus: the bump centres in frames: none for type 1 (centred in the cycle), one for type 2, two for 3 and 4.
        m: cycle length in frames.

    Returns:
        (M, 3) rows (alpha, mu, sigma2).
    """
    if shape == 1:
        sigma = POSTURE_SIGMA_CYCLES * m
        return np.array([[alpha, m / 2.0, sigma * sigma]])
    need = {2: 1, 3: 2, 4: 2}
    if shape not in need:
        raise ValueError(f"RBF shape must be 1, 2, 3 or 4 (Fig. 4), got {shape!r}")
    if len(mus) != need[shape]:
        raise ValueError(f"shape {shape} needs {need[shape]} centre(s), got {len(mus)}")
    if shape == 2:
        sigma = BUMP_SIGMA_CYCLES * m
        return np.array([[alpha, mus[0], sigma * sigma]])
    if shape == 3:
        sigma = DOUBLE_BUMP_SIGMA_CYCLES * m
        return np.array([[alpha, mus[0], sigma * sigma], [alpha, mus[1], sigma * sigma]])
    sigma = BUMP_SIGMA_CYCLES * m
    return np.array([[alpha, mus[0], sigma * sigma], [-alpha, mus[1], sigma * sigma]])


def _circular_peaks(x: np.ndarray) -> np.ndarray:
    """Indices of local maxima of a periodic signal (ties broken towards the first frame)."""
    prev, nxt = np.roll(x, 1), np.roll(x, -1)
    return np.flatnonzero((x > prev) & (x >= nxt))


def swing_params(trajectory: np.ndarray, shape: int, alpha: float) -> np.ndarray:
    """Place a movement feature ("increased swing", types 2-4) on one DOF of a periodic neutral cycle.

    The paper's animators put the bumps where the trajectory already has its extrema, so that an
    increased swing pushes each extremum further out (alpha > 0) and a decreased swing pulls it
    towards the mean (alpha < 0). The centres are found from the neutral trajectory:

    - type 2: one bump at the largest deviation from the mean, signed like that deviation;
    - type 3: two bumps at the two largest peaks of the dominant side (a twice-per-cycle motion);
    - type 4: +alpha at the maximum and -alpha at the minimum (a once-per-cycle oscillation).

    A DOF that is constant in the neutral cycle gets its bumps at the mid-stances (m/4, 3m/4).

    Args:
        trajectory: (m,) neutral positions of the DOF over one cycle, metres.
        shape: 2, 3 or 4.
        alpha: amplitude; its sign says increased (+) or decreased (-) swing.

    Returns:
        (M, 3) parameters in the trajectory's frame units.
    """
    x = np.asarray(trajectory, dtype=np.float64)
    if x.ndim != 1 or x.size < 8:
        raise ValueError(f"swing placement needs a (m >= 8,) trajectory, got shape {x.shape}")
    m = x.size
    d = x - x.mean()
    if np.ptp(d) < 1e-9:
        # A DOF that does not move in the neutral cycle has no extremum to push: put the bumps at the two
        # mid-stances (a quarter and three quarters of a left-to-left cycle).
        mus = {2: (0.25 * m,), 3: (0.25 * m, 0.75 * m), 4: (0.25 * m, 0.75 * m)}
        if shape not in mus:
            raise ValueError(f"swing features use shapes 2, 3 or 4, got {shape!r}")
        return shape_params(shape, alpha, mus[shape], m)
    if shape == 2:
        k = int(np.argmax(np.abs(d)))
        sign = 1.0 if d[k] >= 0 else -1.0
        return shape_params(2, sign * alpha, (float(k),), m)
    if shape == 4:
        return shape_params(4, alpha, (float(np.argmax(d)), float(np.argmin(d))), m)
    if shape == 3:
        side = 1.0 if d.max() >= -d.min() else -1.0
        s = side * d
        peaks = _circular_peaks(s)
        peaks = peaks[np.argsort(-s[peaks])]
        first = int(peaks[0])
        # second peak: the highest one at least a quarter cycle away (circularly) from the first
        far = [int(p) for p in peaks[1:] if min(abs(p - first), m - abs(p - first)) >= m // 4]
        second = far[0] if far else (first + m // 2) % m
        return shape_params(3, side * alpha, tuple(float(v) for v in sorted((first, second))), m)
    raise ValueError(f"swing features use shapes 2, 3 or 4, got {shape!r}")
