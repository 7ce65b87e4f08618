"""Power of the planned tests by Monte-Carlo simulation, for choosing the number of participants.

    python -m analysis.power PRESET --participants 8 16 32 64 [--effect NAME=VALUE ...] [--sims N]
                             [--alpha A] [--seed S] [--out DIR]

PRESET is ``seed000`` (gait recognition), ``seed003`` (gesture recognition), ``seed004`` (theme weight effect and
inversion), ``paired`` (a plain paired t-test) or ``all``. For each planned test and number of participants, ``sims``
studies are simulated under the stated effect, the test of the report is run on each, and power = the share of
studies where it rejects at ``alpha``; ``mc_se`` = sqrt(power (1 - power) / sims) is its Monte-Carlo standard error.
Prints a Markdown table and writes ``power.csv``, ``power.png`` and ``power.svg`` into ``--out``.

Tests and their effect sizes (``--effect NAME=VALUE`` overrides the preset's value):
- ``recognition_gait`` / ``recognition_gesture``: Wagner's (1993) per-participant test of one emotion's unbiased
  hit rate against chance (arcsine, paired t, Holm across the L emotions; :mod:`analysis.recognition`). Each
  participant sees ``clips_per_label`` clips of each of L labels and answers correctly with probability
  ``hit_rate``, otherwise one of the other labels uniformly. Effects ``gait_hit_rate`` (L = 4, 2 clips per label),
  ``gesture_hit_rate`` (L = 10, 1 clip per label; the study shows a subset of clips, so this is optimistic).
- ``theme_weight``: one-way repeated-measures ANOVA of the weight factor (4 levels, ratings averaged over the
  feature-count levels) as in seed 004's Table IV; ratings = ``theme_slope`` x weight level index + participant
  intercept (SD 1) + noise (SD ``theme_noise_sd``, default 1.5), uncorrected F test.
- ``inversion``: one-sample t-test of a theme's mean inversion rating against 0; effect ``inversion_d`` (Cohen's d).
- ``paired_t``: paired t-test with standardised mean difference ``dz`` (Cohen 1988); its power has a closed form
  (statsmodels.stats.power.TTestPower), which the tests compare with the simulation.
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np
import pandas as pd
from scipy import stats

PRESETS = {
    "seed000": {"recognition_gait": {"gait_hit_rate": 0.5}},
    "seed003": {"recognition_gesture": {"gesture_hit_rate": 0.3}},
    "seed004": {"theme_weight": {"theme_slope": 0.3, "theme_noise_sd": 1.5}, "inversion": {"inversion_d": 0.5}},
    "paired": {"paired_t": {"dz": 0.5}},
}
PRESETS["all"] = {k: v for p in ("seed000", "seed003", "seed004", "paired") for k, v in PRESETS[p].items()}
"""Preset -> planned test -> its effect sizes (defaults)."""

CHUNK = 250


def _t_p(x: np.ndarray) -> np.ndarray:
    """Two-sided p of a one-sample t-test of 0 along the last axis (vectorised over the leading axes)."""
    n = x.shape[-1]
    sd = x.std(axis=-1, ddof=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = x.mean(axis=-1) / (sd / np.sqrt(n))
    p = 2 * stats.t.sf(np.abs(t), n - 1)
    return np.where(sd > 0, p, 1.0)


def _holm_first(p: np.ndarray) -> np.ndarray:
    """Holm-adjusted p-value of the first of the L hypotheses in ``p`` (..., L)."""
    L = p.shape[-1]
    order = np.argsort(p, axis=-1)
    ps = np.take_along_axis(p, order, axis=-1)
    adj = np.minimum(1, np.maximum.accumulate(ps * (L - np.arange(L)), axis=-1))
    rank_of_first = np.argmax(order == 0, axis=-1)
    return np.take_along_axis(adj, rank_of_first[..., None], axis=-1)[..., 0]


def sim_paired_t(rng, n: int, sims: int, alpha: float, dz: float) -> np.ndarray:
    """Rejections (sims,) of a two-sided paired t-test on n differences ~ N(dz, 1)."""
    return _t_p(rng.normal(dz, 1.0, (sims, n))) < alpha


def sim_inversion(rng, n: int, sims: int, alpha: float, inversion_d: float) -> np.ndarray:
    """Rejections of the one-sample t-test against 0 with Cohen's d = inversion_d (ratings ~ N(-d, 1))."""
    return _t_p(rng.normal(-inversion_d, 1.0, (sims, n))) < alpha


def sim_recognition(rng, n: int, sims: int, alpha: float, hit_rate: float, n_labels: int,
                    clips_per_label: int) -> np.ndarray:
    """Rejections of Wagner's test for emotion 0 (Holm across n_labels emotions); see the module docstring."""
    L, m = n_labels, clips_per_label
    intended = np.repeat(np.arange(L), m)  # (L*m,)
    out = []
    for start in range(0, sims, CHUNK):
        s = min(CHUNK, sims - start)
        correct = rng.random((s, n, L * m)) < hit_rate
        other = (intended + rng.integers(1, L, (s, n, L * m))) % L  # uniform over the other labels
        chosen = np.where(correct, intended, other)
        conf = np.zeros((s, n, L, L))
        for i in range(L):  # rows: intended label i
            for j in range(m):
                conf[:, :, i, :] += np.eye(L)[chosen[:, :, i * m + j]]
        row, col, total = conf.sum(-1), conf.sum(-2), L * m
        diag = np.einsum("...ii->...i", conf)
        with np.errstate(invalid="ignore", divide="ignore"):
            hu = np.where(col > 0, diag**2 / (row * col), 0.0)
        chance = row * col / total**2
        d = np.arcsin(np.sqrt(hu)) - np.arcsin(np.sqrt(chance))  # (s, n, L)
        p = _t_p(np.moveaxis(d, 1, -1))  # (s, L)
        out.append(_holm_first(p) < alpha)
    return np.concatenate(out)


def sim_theme_weight(rng, n: int, sims: int, alpha: float, theme_slope: float, theme_noise_sd: float = 1.5,
                     levels: int = 4) -> np.ndarray:
    """Rejections of the one-way RM-ANOVA F test of a 4-level within factor (participants x levels)."""
    x = (theme_slope * np.arange(levels) + rng.normal(0, 1, (sims, n, 1))
         + rng.normal(0, theme_noise_sd, (sims, n, levels)))
    gm = x.mean(axis=(1, 2), keepdims=True)
    ss_cond = n * ((x.mean(axis=1, keepdims=True) - gm) ** 2).sum(axis=(1, 2))
    ss_subj = levels * ((x.mean(axis=2, keepdims=True) - gm) ** 2).sum(axis=(1, 2))
    ss_err = ((x - gm) ** 2).sum(axis=(1, 2)) - ss_cond - ss_subj
    df1, df2 = levels - 1, (levels - 1) * (n - 1)
    f = (ss_cond / df1) / (ss_err / df2)
    return stats.f.sf(f, df1, df2) < alpha


def _run(test: str, rng, n: int, sims: int, alpha: float, eff: dict) -> np.ndarray:
    if test == "paired_t":
        return sim_paired_t(rng, n, sims, alpha, eff["dz"])
    if test == "inversion":
        return sim_inversion(rng, n, sims, alpha, eff["inversion_d"])
    if test == "recognition_gait":
        return sim_recognition(rng, n, sims, alpha, eff["gait_hit_rate"], 4, 2)
    if test == "recognition_gesture":
        return sim_recognition(rng, n, sims, alpha, eff["gesture_hit_rate"], 10, 1)
    if test == "theme_weight":
        return sim_theme_weight(rng, n, sims, alpha, eff["theme_slope"], eff.get("theme_noise_sd", 1.5))
    raise ValueError(f"unknown test {test!r}")


def power_table(preset: str, participants, effects: dict | None = None, sims: int = 1000, alpha: float = 0.05,
                seed: int = 0) -> pd.DataFrame:
    """Simulated power of each planned test of ``preset`` for each number of participants.

    ``effects``: NAME -> value overriding the preset's effect sizes (unknown names raise ValueError). Returns one
    row per test and number of participants: preset, test, effects (text), participants, power, mc_se, sims.
    """
    if preset not in PRESETS:
        raise ValueError(f"unknown preset {preset!r} (one of {', '.join(PRESETS)})")
    effects = dict(effects or {})
    known = {name for spec in PRESETS[preset].values() for name in spec}
    unknown = set(effects) - known
    if unknown:
        raise ValueError(f"unknown effect(s) {', '.join(sorted(unknown))} for preset {preset} "
                         f"(known: {', '.join(sorted(known))})")
    rng = np.random.default_rng(seed)
    rows = []
    for test, spec in PRESETS[preset].items():
        eff = {k: float(effects.get(k, v)) for k, v in spec.items()}
        for n in participants:
            if n < 2:
                raise ValueError("participants must be >= 2")
            power = float(_run(test, rng, int(n), sims, alpha, eff).mean())
            rows.append({"preset": preset, "test": test, "effects": ", ".join(f"{k}={v:g}" for k, v in eff.items()),
                         "participants": int(n), "power": power, "mc_se": float(np.sqrt(power * (1 - power) / sims)),
                         "sims": sims})
    return pd.DataFrame(rows)


def save_power_figure(table: pd.DataFrame, out: str, alpha: float = 0.05) -> dict:
    """power.png and power.svg in ``out`` (paths by format): power against participants, one line per test, the
    conventional 0.8 dashed."""
    from .figures import plt, save_figure  # heavy: matplotlib, only when a figure is drawn

    fig, ax = plt.subplots(figsize=(5.5, 3.4))
    for test, g in table.groupby("test", sort=False):
        ax.errorbar(g["participants"], g["power"], yerr=1.96 * g["mc_se"], marker="o", capsize=2,
                    label=f"{test} ({g['effects'].iloc[0]})")
    ax.axhline(0.8, color="#888", ls="--", lw=0.8)
    ax.set_xscale("log", base=2)
    ax.set_xticks(sorted(table["participants"].unique()), [str(v) for v in sorted(table["participants"].unique())])
    ax.set_ylim(0, 1.02)
    ax.set_xlabel("participants")
    ax.set_ylabel(f"power (alpha = {alpha})")
    ax.legend(fontsize=7, frameon=False, loc="lower right")
    fig.subplots_adjust(left=0.12, right=0.98, bottom=0.15, top=0.95)
    return save_figure(fig, out, "power")


def _parse_effect(text: str) -> tuple[str, float]:
    name, sep, value = text.partition("=")
    try:
        if not sep:
            raise ValueError
        return name.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--effect wants NAME=VALUE, not {text!r}") from None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m analysis.power", description=__doc__.split("\n")[0])
    ap.add_argument("preset", choices=list(PRESETS))
    ap.add_argument("--participants", type=int, nargs="+", default=[8, 16, 32, 64])
    ap.add_argument("--effect", type=_parse_effect, action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--sims", type=int, default=1000, help="simulated studies per cell (default 1000)")
    ap.add_argument("--alpha", type=float, default=0.05)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=".", help="folder for power.csv, power.png, power.svg (default .)")
    a = ap.parse_args(argv)
    if a.sims < 1 or not 0 < a.alpha < 1 or min(a.participants) < 2:
        print("error: --sims >= 1, 0 < --alpha < 1, --participants >= 2", file=sys.stderr)
        return 2
    try:
        table = power_table(a.preset, a.participants, dict(a.effect), a.sims, a.alpha, a.seed)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print("| test | effects | participants | power | MC s.e. |")
    print("|---|---|---|---|---|")
    for _, r in table.iterrows():
        print(f"| {r['test']} | {r['effects']} | {r['participants']} | {r['power']:.3f} | {r['mc_se']:.3f} |")
    os.makedirs(a.out, exist_ok=True)
    table.to_csv(os.path.join(a.out, "power.csv"), index=False)
    paths = save_power_figure(table, a.out, a.alpha)
    print(f"wrote {os.path.join(a.out, 'power.csv')}, {paths['png']}, {paths['svg']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
