"""Report figures (matplotlib, Agg backend), each built from one tidy analysis table.

Every ``fig_*`` function takes the DataFrame of the matching analysis and returns a matplotlib Figure (or None when
the table is empty); :func:`save_figure` writes it as PNG and SVG.
"""

from __future__ import annotations

import os
import re

import matplotlib
import matplotlib.transforms

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from protocol.vocabulary import (  # noqa: E402
    GAIT_EMOTIONS,
    IMPORTED,
    LIKERT_FEATURES,
    ORIGINS,
    THEMES,
    VAD_DIMENSIONS,
)

plt.rcParams.update({"svg.hashsalt": "analysis", "svg.fonttype": "none", "font.size": 9, "axes.titlesize": 9,
                     "figure.dpi": 100})
INTENDED_COLOR, PERCEIVED_COLOR = "#4C72B0", "#DD8452"
PAPER_EMOTION_COLORS = ("#E1A100", "#4C72B0", "#C44E52", "#8C8C8C")
"""Bar colours of seed 000's four gait emotions (happy, sad, angry, neutral), the first four of GAIT_EMOTIONS."""
EMOTION_COLORS = dict(zip(GAIT_EMOTIONS[:len(PAPER_EMOTION_COLORS)], PAPER_EMOTION_COLORS, strict=True))
"""Bar colour of each of seed 000's gait emotions; a gait emotion added after them takes each figure's default."""


def save_figure(fig, out_dir: str, name: str, dpi: int = 110) -> dict[str, str]:
    """Write ``fig`` as ``<name>.png`` and ``<name>.svg`` into out_dir, close it, return {"png": path, "svg": path}."""
    paths = {"png": os.path.join(out_dir, f"{name}.png"), "svg": os.path.join(out_dir, f"{name}.svg")}
    fig.savefig(paths["png"], dpi=dpi, metadata={"Software": None})
    fig.savefig(paths["svg"], metadata={"Date": None, "Creator": None})
    plt.close(fig)
    return paths


def _adjust(fig, top: float = 0.85, bottom: float = 0.45, left: float = 0.55, right: float = 0.15,
            hgap: float = 0.7, wgap: float = 0.3) -> None:
    """Fixed margins and gaps in inches (cheaper than tight_layout, which draws the figure once more)."""
    W, H = fig.get_size_inches()
    gs = fig.axes[0].get_gridspec()
    nrows, ncols = gs.nrows, gs.ncols
    ax_h = (H - top - bottom - hgap * (nrows - 1)) / nrows
    ax_w = (W - left - right - wgap * (ncols - 1)) / ncols
    fig.subplots_adjust(left=left / W, right=1 - right / W, bottom=bottom / H, top=1 - top / H,
                        hspace=hgap / ax_h, wspace=wgap / ax_w)


def _text_bbox(fig, renderer):
    """The tight bounding box (inches) of the text of ``fig``: each visible axes with its ticks, labels, title and
    legend (not its bars and lines, which stay inside the axes), the figure's texts and legends."""
    boxes = []
    for ax in fig.axes:
        if ax.get_visible():
            legend = ax.get_legend()
            boxes.append(ax.get_tightbbox(renderer, bbox_extra_artists=[legend] if legend else []))
    boxes += [t.get_window_extent(renderer) for t in fig.texts if t.get_visible() and t.get_text()]
    boxes += [leg.get_window_extent(renderer) for leg in fig.legends]
    title = getattr(fig, "_suptitle", None)
    if title is not None and title.get_text():
        boxes.append(title.get_window_extent(renderer))
    box = matplotlib.transforms.Bbox.union([b for b in boxes if b is not None and b.width > 0])
    return box.transformed(fig.dpi_scale_trans.inverted())


def fit_to_canvas(fig, pad: float = 0.05, rounds: int = 4):
    """Keep every text of ``fig`` inside its canvas: a suptitle wider than the figure widens it (the panels keep
    their size, the margins grow), then the subplot margins grow by whatever the drawn tight bounding box
    (titles, tick and axis labels, legends; inches) overshoots the canvas by, ``pad`` inches inside the edge, until
    nothing overshoots (at most ``rounds`` layouts; the text is measured, nothing is rasterised). Returns ``fig``."""
    renderer = fig.canvas.get_renderer()
    title = getattr(fig, "_suptitle", None)
    if title is not None and title.get_text():
        need = title.get_window_extent(renderer).width / fig.dpi + 2 * pad
        width, height = fig.get_size_inches()
        if need > width:
            sp = fig.subplotpars
            grow = need - width
            fig.set_size_inches(need, height)
            fig.subplots_adjust(left=(sp.left * width + grow / 2) / need,
                                right=1 - ((1 - sp.right) * width + grow / 2) / need)
    for _ in range(rounds):
        width, height = fig.get_size_inches()
        box = _text_bbox(fig, renderer)
        over = {"left": pad - box.x0, "right": box.x1 - (width - pad), "bottom": pad - box.y0,
                "top": box.y1 - (height - pad)}
        if all(v <= 0.005 for v in over.values()):
            break
        sp = fig.subplotpars
        fig.subplots_adjust(left=sp.left + max(0.0, over["left"]) / width,
                            right=sp.right - max(0.0, over["right"]) / width,
                            bottom=sp.bottom + max(0.0, over["bottom"]) / height,
                            top=sp.top - max(0.0, over["top"]) / height)
    return fig


def _grid(n: int, ncols: int, w: float, h: float, **kw):
    ncols = max(1, min(ncols, n))
    nrows = int(np.ceil(n / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(w * ncols, h * nrows + 0.3), squeeze=False, **kw)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    return fig, axes.ravel()


def fig_emotion_vectors(table: pd.DataFrame, title: str = "Intended vs perceived gait emotions"):
    """Seed 000 Fig. 9: per clip, intended and mean perceived (l1-normalised) emotion vectors as paired bars.
    ``table``: gait_emotion_ad or transition_ad (then one panel per clip and phase)."""
    if table.empty:
        return None
    fig, axes = _grid(len(table), 4, 2.6, 2.1, sharey=True)
    x = np.arange(len(GAIT_EMOTIONS))
    for ax, (_, row) in zip(axes, table.iterrows()):
        want = [row[f"intended_{e}"] for e in GAIT_EMOTIONS]
        got = [row[f"perceived_{e}"] for e in GAIT_EMOTIONS]
        ax.bar(x - 0.2, want, 0.4, color=INTENDED_COLOR, label="intended")
        ax.bar(x + 0.2, got, 0.4, color=PERCEIVED_COLOR, label="perceived")
        ax.set_xticks(x, [e[:3] for e in GAIT_EMOTIONS])
        ax.set_ylim(0, 1.05)
        phase = f" ({row['phase']})" if "phase" in row else ""
        verdict = "reject" if row["reject"] else "not rejected"
        ax.set_title(f"{row['clip_id']}{phase}\nA = {row['statistic']:.2f}, p {_p(row)} ({verdict})", fontsize=8)
    axes[0].legend(loc="upper right", fontsize=7, frameon=False)
    fig.suptitle(title)
    _adjust(fig)
    return fit_to_canvas(fig)


def fig_transitions(table: pd.DataFrame):
    """Seed 000 section 6.3.2: per transition clip, intended and perceived vectors of the initial (left group) and
    final (right group) emotion. ``table``: transition_ad."""
    if table.empty:
        return None
    clips = list(dict.fromkeys(table["clip_id"]))
    fig, axes = _grid(len(clips), 4, 3.0, 2.1, sharey=True)
    x = np.arange(len(GAIT_EMOTIONS))
    for ax, clip in zip(axes, clips):
        title = [clip]
        for offset, phase in ((0, "initial"), (len(GAIT_EMOTIONS) + 1, "final")):
            r = table[(table["clip_id"] == clip) & (table["phase"] == phase)]
            if r.empty:
                continue
            row = r.iloc[0]
            ax.bar(x + offset - 0.2, [row[f"intended_{e}"] for e in GAIT_EMOTIONS], 0.4, color=INTENDED_COLOR,
                   label="intended")
            ax.bar(x + offset + 0.2, [row[f"perceived_{e}"] for e in GAIT_EMOTIONS], 0.4, color=PERCEIVED_COLOR,
                   label="perceived")
            title.append(f"{phase[:3]}: p {_p(row)}{' *' if row['reject'] else ''}")
        ax.axvline(len(GAIT_EMOTIONS), color="#bbb", lw=0.8)
        ax.set_xticks(np.r_[x, x + len(GAIT_EMOTIONS) + 1], [e[:2] for e in GAIT_EMOTIONS] * 2, fontsize=7)
        ax.set_ylim(0, 1.05)
        ax.set_title("\n".join([title[0], ", ".join(title[1:])]), fontsize=8)
    h, lab = axes[0].get_legend_handles_labels()
    axes[0].legend(h[:2], lab[:2], loc="upper center", fontsize=7, frameon=False)
    fig.suptitle("Emotion transitions: initial (left) and final (right), intended vs perceived (* rejected)")
    _adjust(fig)
    return fit_to_canvas(fig)


def _p(row) -> str:
    d = row.get("p_display", "")
    return d if d.startswith(("<", ">")) else f"= {row['p_value']:.3f}"


def fig_likert(dist: pd.DataFrame):
    """Seed 000 Fig. 8: share of each Likert value 0..4, one panel per feature (rows) and emotion (columns)."""
    if dist.empty:
        return None
    emotions = [e for e in GAIT_EMOTIONS if e in set(dist["emotion"])]
    features = [f for f in LIKERT_FEATURES if f in set(dist["feature"])]
    fig, axes = plt.subplots(len(features), len(emotions), figsize=(2.2 * len(emotions), 1.6 * len(features) + 0.6),
                             squeeze=False, sharex=True, sharey=True)
    for i, f in enumerate(features):
        for j, e in enumerate(emotions):
            d = dist[(dist["emotion"] == e) & (dist["feature"] == f)].sort_values("value")
            ax = axes[i, j]
            ax.bar(d["value"], d["share"], color=EMOTION_COLORS.get(e, "#555"))
            ax.set_xticks(range(5))
            ax.set_ylim(0, 1)
            if i == 0:
                ax.set_title(e)
            if j == 0:
                ax.set_ylabel(f"{f}\nshare")
            if i == len(features) - 1:
                ax.set_xlabel("Likert value")
    fig.suptitle("Pose affective features by intended emotion (share of answers)")
    _adjust(fig, left=0.7, hgap=0.25, wgap=0.15)
    return fit_to_canvas(fig)


def fig_vad(pairs: pd.DataFrame, pearson: pd.DataFrame):
    """Seed 003 Fig. 7: intended vs perceived value per VAD dimension; each distinct pair is one bubble, its area
    proportional to the number of answers."""
    if pairs.empty:
        return None
    fig, axes = plt.subplots(1, 3, figsize=(10, 3.4))
    for ax, d in zip(axes, VAD_DIMENSIONS):
        counts = pairs.groupby([f"intended_{d}", f"perceived_{d}"]).size().reset_index(name="n")
        size = 400 * counts["n"] / counts["n"].max()
        ax.scatter(counts[f"intended_{d}"], counts[f"perceived_{d}"], s=size, alpha=0.5, color=INTENDED_COLOR,
                   edgecolor="k", linewidth=0.3)
        ax.plot([0, 1], [0, 1], color="#999", lw=0.8, ls="--")
        ax.set_xlim(-0.05, 1.05)
        ax.set_ylim(-0.05, 1.05)
        ax.set_xlabel(f"intended {d}")
        ax.set_ylabel(f"perceived {d}")
        r = pearson.set_index("dimension").get("r", pd.Series(dtype=float)).get(d, np.nan)
        ax.set_title(f"{d}: Pearson r = {r:.2f} (n = {len(pairs)})")
        ax.set_aspect("equal")
    fig.suptitle("Intended vs perceived gesture emotion in NRC-VAD space (bubble area = answers)")
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    return fit_to_canvas(fig)


ORIGIN_COLORS = {"generated": PERCEIVED_COLOR, "source": INTENDED_COLOR, IMPORTED: "#55A868"}
"""Bar colour of each clip origin in the naturalness figure (an origin not named here is grey)."""


def fig_naturalness(nat: pd.DataFrame):
    """Share of each naturalness rating 1..5 per clip origin (generated, source, imported: those in the table), one
    panel per modality; each origin's bars are labelled with its share of ratings >= 3 and its n."""
    if nat.empty:
        return None
    modalities = sorted(nat["modality"].unique())
    present = set(nat["origin"])
    origins = [o for o in ORIGINS if o in present] + sorted(present - set(ORIGINS))
    width = 0.8 / len(origins)
    fig, axes = plt.subplots(1, len(modalities), figsize=(4.2 * len(modalities), 3), squeeze=False, sharey=True)
    x = np.arange(1, 6)
    for ax, mod in zip(axes[0], modalities):
        for k, origin in enumerate(origins):
            r = nat[(nat["modality"] == mod) & (nat["origin"] == origin)]
            if r.empty:
                continue
            r = r.iloc[0]
            shares = [r[f"share_{v}"] for v in x]
            ax.bar(x + (k - (len(origins) - 1) / 2) * width, shares, width, color=ORIGIN_COLORS.get(origin, "grey"),
                   label=f"{origin} ({r['share_at_least_3']:.0%} >= 3, n = {int(r['n'])})")
        ax.set_xticks(x)
        ax.set_xlabel("naturalness rating (1 not natural .. 5 very natural)")
        ax.set_title(mod)
        ax.legend(fontsize=7, frameon=False, loc="upper left")
    axes[0, 0].set_ylabel("share of answers")
    fig.suptitle(f"Naturalness by clip origin ({', '.join(origins)})")
    fig.tight_layout()
    return fit_to_canvas(fig)


def fig_theme_ratings(desc: pd.DataFrame):
    """Seed 004 Fig. 7: normalised theme rating (0..1) against number of features, one line per weight, error
    bars = standard error, one panel per theme."""
    if desc.empty:
        return None
    themes = [t for t in THEMES if t in set(desc["theme"])] + sorted(set(desc["theme"]) - set(THEMES))
    fig, axes = _grid(len(themes), 3, 3.2, 2.6, sharey=True)
    weights = sorted(desc["weight"].unique())
    cmap = plt.get_cmap("viridis")
    for ax, theme in zip(axes, themes):
        d = desc[desc["theme"] == theme]
        for i, w in enumerate(weights):
            e = d[d["weight"] == w].sort_values("n_features")
            ax.errorbar(e["n_features"], e["mean"], yerr=e["se"], marker="o", ms=3, capsize=2, lw=1,
                        color=cmap(i / max(1, len(weights) - 1)), label=f"w = {w:g}")
        ax.set_title(theme)
        ax.set_ylim(0, 1)
        ax.set_xlabel("number of features")
        ax.set_xticks(sorted(d["n_features"].unique()))
    axes[0].set_ylabel("rating (normalised 0..1)")
    axes[0].legend(fontsize=7, frameon=False)
    fig.suptitle("Theme ratings by weight and number of features (mean ± SE)")
    _adjust(fig, hgap=0.75, wgap=0.2)
    return fit_to_canvas(fig)


def fig_inversion(inv: pd.DataFrame):
    """Seed 004 Fig. 8: mean inversion rating per theme (-7 opposite theme .. +7 original theme), error bars SE."""
    if inv.empty:
        return None
    fig, ax = plt.subplots(figsize=(5.5, 3))
    x = np.arange(len(inv))
    ax.bar(x, inv["mean"], yerr=inv["se"], capsize=3, color=INTENDED_COLOR)
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xticks(x, inv["theme"])
    ax.set_ylim(-7, 7)
    ax.set_ylabel("rating (-7 opposite .. +7 original)")
    ax.set_title("Ratings of inverted themes (w = -0.7), mean ± SE")
    fig.tight_layout()
    return fit_to_canvas(fig)


def fig_confusion(results: dict):
    """Confusion matrices of emotion recognition (Wagner 1993): one panel per question (gait, gesture), rows
    intended, columns perceived, each cell the row share (the diagonal is the hit rate), annotated; the title gives
    Cohen's kappa. ``results``: name -> :func:`analysis.recognition.recognition` dict (empty ones skipped)."""
    results = {k: v for k, v in results.items() if v and v["n_answers"] > 0}
    if not results:
        return None
    sizes = [len(v["labels"]) for v in results.values()]
    fig, axes = plt.subplots(1, len(results), figsize=(sum(0.45 * s + 1.6 for s in sizes), 0.45 * max(sizes) + 1.9),
                             squeeze=False, gridspec_kw={"width_ratios": sizes})
    for ax, (name, res) in zip(axes.ravel(), results.items()):
        c = res["confusion"].to_numpy(float)
        with np.errstate(invalid="ignore", divide="ignore"):
            share = np.where(c.sum(axis=1, keepdims=True) > 0, c / c.sum(axis=1, keepdims=True), np.nan)
        ax.imshow(share, vmin=0, vmax=1, cmap="Blues")
        labels = res["labels"]
        ax.set_xticks(range(len(labels)), labels, rotation=60, ha="right")
        ax.set_yticks(range(len(labels)), labels)
        size = 7 if len(labels) <= 5 else 5.5
        for i in range(len(labels)):
            for j in range(len(labels)):
                if np.isfinite(share[i, j]):
                    ax.text(j, i, f"{share[i, j]:.2f}".lstrip("0"), ha="center", va="center", fontsize=size,
                            color="white" if share[i, j] > 0.6 else "#222")
        ax.set_xlabel("perceived")
        ax.set_ylabel("intended")
        ax.set_title(f"{name}: kappa = {res['kappa']:.2f}, n = {res['n_answers']}", fontsize=8)
    fig.suptitle("Emotion recognition: row shares of the confusion matrix (diagonal = hit rate)")
    fig.subplots_adjust(left=0.12, right=0.98, bottom=0.28, top=0.86, wspace=0.45)
    return fit_to_canvas(fig)


def _short_id(clip_id: str) -> str:
    """A clip id short enough for a tick label: the first 8 digits of a content hash, else its last 14
    characters (named ids such as sim-demo-happy_loop say most at their end)."""
    return clip_id[:8] if re.fullmatch(r"[0-9a-f]{16}", clip_id) else clip_id[-14:]


def fig_clip_norms(norms: pd.DataFrame, modality: str, max_clips: int = 120):
    """Per-clip norms of one modality (analysis.norms): for each clip with an intended label, its perceived shares
    as a stacked bar (one colour per label) and the intended label's share with its 95 % Wilson interval (black
    point and whiskers), clips ordered by intended share (lowest first; at most ``max_clips``, the lowest kept).
    None when no clip of the modality has an intended label."""
    if norms.empty:
        return None
    t = norms[(norms["modality"] == modality) & norms["intended"].notna()]
    if t.empty:
        return None
    t = t.sort_values(["intended_share", "clip_id"], kind="stable").head(max_clips).reset_index(drop=True)
    labels = [c for c in t.columns if c.startswith("share_") and t[c].notna().any()]
    cmap = plt.get_cmap("tab20")
    colors = {c: EMOTION_COLORS.get(c[len("share_"):], cmap(i % 20)) for i, c in enumerate(labels)}
    width = min(16.0, max(7.0, 0.22 * len(t) + 2.5))
    fig, ax = plt.subplots(figsize=(width, 3.4))
    x = np.arange(len(t))
    bottom = np.zeros(len(t))
    for c in labels:
        v = t[c].fillna(0).to_numpy(float)
        ax.bar(x, v, 0.8, bottom=bottom, color=colors[c], label=c[len("share_"):], linewidth=0)
        bottom += v
    y = t["intended_share"].to_numpy(float)
    err = np.vstack([y - t["intended_ci_low"].to_numpy(float), t["intended_ci_high"].to_numpy(float) - y])
    ax.errorbar(x, y, yerr=err, fmt="o", color="black", ms=3, lw=1, capsize=2, label="intended share (95% CI)")
    ax.set_xticks(x, [f"{_short_id(cid)} {lab}" for cid, lab in zip(t["clip_id"], t["intended"])], rotation=90,
                  fontsize=6)
    ax.set_ylim(0, 1.02)
    ax.set_xlim(-0.6, len(t) - 0.4)
    ax.set_ylabel("share of answers")
    ax.set_title(f"{modality}: perceived shares per clip (bars) and the intended label's share (points),\n"
                 f"ordered by intended share; {int(t['n_ratings'].min())}..{int(t['n_ratings'].max())} "
                 "ratings per clip", fontsize=8)
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7, frameon=False)
    fig.subplots_adjust(left=0.6 / width, right=1 - 1.9 / width, bottom=0.34, top=0.86)
    return fit_to_canvas(fig)
