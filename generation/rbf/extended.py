"""The ``extended`` intensity set of seed 004's expert features: every row sized from real style differences.

Why: with the ``visual`` and ``calibrated`` sets, observers trained on real styled walks read nearly every styled walk
as its unstyled base (docs/benchmarks/rbf.md). The calibrated set fits all rows of a theme together with factors
capped at 6x our visual numbers, and zeroes or caps rows to offset one another; the real differences are larger
(data-driven features fitted to real themed walks are 1.0-2.0x the experts'). Here each row is sized on its own
from what real actors do, and two levers the experts' ten rows lack are added as rows of our own
(:data:`generation.rbf.themes.OURS`, ``source: ours``) plus a stride and a cadence lever.

Data (**sources**): the straight walks of the Bandai Namco Research Motion Dataset 1 and 2
(Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0), each dataset a source; and for the themes it has (happy,
sad) the BML walks of Emotion-Gait (Ma, Paterson & Pollick 2006; Bhattacharya et al. AAAI 2020; research use with
citation), :data:`BML_SOURCE`. **Training split** only: Bandai's training takes, BML's training actors (whole actors
are held out, :mod:`generation.mocap.emotion_gait_bml`). Measures as :mod:`generation.rbf.calibrate` (per body part
x axis x kind of a theme's rows, in walker heights: posture = mean offset relative to the pelvis, movement = change
of the peak-to-peak). Real difference per source (:func:`source_differences`): a Bandai dataset's themed takes minus
the same dataset's normal takes; BML the mean over actors of each actor's emotion walk minus the same actor's neutral
walk (:func:`generation.rbf.calibrate.walker_differences`). The target is the mean over the sources that hold the
theme, each source weighing the same: Bandai dataset 1 has one happy and one sad training take, BML 21 training
actors, so neither alone decides the size.

1. **Rows** (:func:`extend_theme`): for each group, the gain of its rows alone at their visual intensity on the real
   neutral base at w = 1 (after the skeleton fit), and the factor = real difference / gain, in [0,
   :data:`MAX_FACTOR`] (a decreased swing at most to no swing, :func:`_decrease_caps`); 0 where real actors move
   against the row's sign (the row is kept, at zero). Then
   :data:`REFINE_STEPS` rescalings of each group by real / reached with all rows on (rows interact: a forward neck
   carries the head); a group whose measure then moves against the real sign (a decreased swing pushed past zero
   swings the other way) is halved instead, and held at zero if it still does after the last step. Energetic's
   "Shoulders: increased swing along Y" is held at 0 (:data:`HELD_AT_ZERO`): without clavicles a shoulder bob
   moves the whole chest, a shrug artefact that made energetic walks read tired. Happy's "Hip: increased swing along
   Y" (a row of ours, the bounce) is sized on the mean over Bandai Namco and BML even in this set
   (:data:`BOTH_SOURCES`): Bandai Namco dataset 1's one happy training take bounces 4.2 % of the height more than
   its normal take, the BML actors hardly do (mean +0.2 % h over 21 training actors, 12 of 21 higher).
2. **Stride and cadence** (two levers of ours, the JSON's ``tempo`` block): the real style's stride (distance per
   cycle) and cadence (cycles per second) over the same source's normal ones (BML: the mean over actors of the
   actor's ratios), minus 1, averaged over the sources with the theme (``stride_per_weight``, ``cadence_per_weight``;
   ``per_weight`` is the speed's, kept for reference). :func:`generation.rbf.stylise.stylise` applies them with all
   ten features: the stride scaled by s(w) = max(0.5, 1 + w * stride_per_weight) (the legs' fore-aft offsets from the
   pelvis and the progression per cycle, so a planted foot stays planted;
   :func:`generation.rbf.stylise.scale_stride`) and the cycle played c(w) = max(0.5, 1 + w * cadence_per_weight)
   times faster; w = 1 gives the real stride and cadence.

:func:`extend` gives the JSON of :data:`generation.rbf.themes.EXTENDED_PATH` with the data's licence and citation,
every row's visual and extended intensity and source, per group the training and held-out real differences (with
BML: their mean over sources and per source) and the w = 1 change reached, the stride and cadence levers with their
per-source ratios, and per pooled theme the sources it was sized on with their licences and citations.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from generation.mocap.emotion_gait_bml import CITATION as BML_CITATION
from generation.mocap.emotion_gait_bml import DATASET as BML_DATASET
from generation.mocap.emotion_gait_bml import LICENCE as BML_LICENCE
from generation.mocap.emotion_gait_bml import SOURCE_URL as BML_URL

from . import calibrate as C
from .data_features import _rounded
from .real_neutral import steady_cycles
from .stylise import walker_frame_positions
from .themes import BODY_PARTS, THEME_NAMES, Feature, all_features

MAX_FACTOR = 10.0
#: (theme, Table III rank) rows held at zero, with the reason (module docstring).
HELD_AT_ZERO = {("energetic", 5): "no clavicles: a shoulder bob moves the whole chest (read as tired)"}
#: (theme, rank of ours) rows the ``extended`` set sizes on the mean over Bandai Namco and BML (each source weighing
#: the same, as the ``pooled`` set sizes every row), with the reason (module docstring).
BOTH_SOURCES = {("happy", 11): "bounce: Bandai Namco dataset 1's one happy training take bounces +4.2 % of the "
                               "height more than its normal take, the 21 BML training actors +0.2 % h (sd 0.9 % h, "
                               "12 of 21 higher): one take alone does not size it"}
REFINE_STEPS = 5
MIN_GAIN = 1e-4  # heights: a group whose rows move their own measure less than this cannot be sized (factor 0)
#: The BML walks of Emotion-Gait as a source: its name in the JSON, licence, citation and where it comes from.
BML_SOURCE = {"source": BML_DATASET, "licence": BML_LICENCE, "citation": BML_CITATION, "dataset_url": BML_URL,
              "what": "BML walks of Emotion-Gait: one walk per actor and acted emotion (happy, sad, angry, neutral); "
                      "difference = mean over actors of emotion minus the same actor's neutral walk"}
BML_NEUTRAL = ("neutral",)


def _by_rank(theme: str, factors: np.ndarray, feats: tuple[Feature, ...]) -> dict[int, float]:
    groups = C.theme_groups(theme, feats)
    out = {f.rank: f.intensity * float(factors[groups.index((f.part, f.axis, f.kind))]) for f in feats}
    for (t, rank) in HELD_AT_ZERO:
        if t == theme:
            out[rank] = 0.0
    return out


def group_gains(base: Motion, theme: str) -> np.ndarray:
    """(G,) each group's own measure change at w = 1 with only its rows on, at their visual intensities."""
    feats = all_features(theme)
    groups = C.theme_groups(theme, feats)
    gains = np.zeros(len(groups))
    for i in range(len(groups)):
        one = np.zeros(len(groups))
        one[i] = 1.0
        gains[i] = C.generated_measures(base, theme, _by_rank(theme, one, feats), 1.0, feats, True)[i]
    return gains


def _decrease_caps(base: Motion, theme: str, feats: tuple[Feature, ...], groups: list) -> np.ndarray:
    """(G,) largest factor per group: :data:`MAX_FACTOR`, and for a decreased swing the factor whose amplitude
    equals half the smallest neutral peak-to-peak of the group's joints on that axis (relative to the pelvis): a
    swing cannot shrink below none; pushed further it swings the other way (a shoulder swing decreased past zero
    twists the chest against the step)."""
    P, _ = walker_frame_positions(base)
    joints = tuple(base.skeleton.joints)
    root, h = joints.index("root"), base.skeleton.height
    caps = np.full(len(groups), MAX_FACTOR)
    for f in feats:
        if f.kind != "swing" or f.sign > 0 or f.intensity <= 0:
            continue
        a = "XYZ".index(f.axis)
        half = min(np.ptp(P[:, joints.index(j), a] - (0 if joints.index(j) == root else P[:, root, a])) / 2
                   for j in BODY_PARTS[f.part]) / h
        g = groups.index((f.part, f.axis, f.kind))
        caps[g] = min(caps[g], half / f.intensity)
    return caps


def extend_theme(base: Motion, theme: str, target: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Factors (G,) on the visual intensities of ``theme``'s rows (Table III and ours) sized from ``target`` (G,)
    real differences in heights; returns the factors, the gains and the w = 1 measures reached with all rows."""
    feats = all_features(theme)
    groups = C.theme_groups(theme, feats)
    gains = group_gains(base, theme)
    cap = _decrease_caps(base, theme, feats, groups)
    factors = np.where((np.abs(gains) > MIN_GAIN) & (target * gains > 0),
                       np.clip(target / np.where(np.abs(gains) > MIN_GAIN, gains, 1.0), 0.0, cap), 0.0)
    reached = C.generated_measures(base, theme, _by_rank(theme, factors, feats), 1.0, feats, True)
    for _ in range(REFINE_STEPS):  # rows of one theme interact (a forward neck carries the head): rescale each group
        ok = (factors > 0) & (reached * target > 0) & (np.abs(reached) > MIN_GAIN)
        factors = np.where(ok, np.clip(factors * target / np.where(ok, reached, 1.0), 0.0, cap), factors)
        # a decreased swing pushed past zero swings the other way (the measure's sign flips): halve it
        factors = np.where((factors > 0) & (reached * target < 0), 0.5 * factors, factors)
        reached = C.generated_measures(base, theme, _by_rank(theme, factors, feats), 1.0, feats, True)
    wrong = (factors > 0) & (reached * target < 0)
    if wrong.any():  # still against the real sign after refining: held at zero
        factors = np.where(wrong, 0.0, factors)
        reached = C.generated_measures(base, theme, _by_rank(theme, factors, feats), 1.0, feats, True)
    return factors, gains, reached


def real_tempo(clips: list, theme: str, splits: tuple[str, ...] = ("train",), m: int = 100) -> dict:
    """Real walking speed, stride and cadence of ``theme``'s takes relative to the same dataset's normal takes.

    Returns {"per_weight": mean over datasets of speed ratio - 1, "stride_per_weight": of stride ratio - 1,
    "cadence_per_weight": of cadence ratio - 1, "datasets": [{dataset, speed_ratio, stride_ratio, cadence_ratio,
    takes, normal_takes}]}; per take the mean over its steady cycles of the stride (heights) and the duration
    (seconds); cadence ratio = normal duration / themed duration.
    """
    styles = C.theme_styles(theme)

    def take(c):
        cycles = steady_cycles(c.motion, m, c.name)
        if not cycles:
            return None
        return (np.mean([cy.stride for cy in cycles]), np.mean([cy.duration_s for cy in cycles]))

    rows = []
    for dataset in sorted({c.dataset for c in clips}):
        mine = [c for c in clips if c.dataset == dataset and c.split in splits and c.content == "walk"]
        themed = [v for v in (take(c) for c in mine if c.style in styles) if v is not None]
        normal = [v for v in (take(c) for c in mine if c.style == "normal") if v is not None]
        if not themed or not normal:
            continue
        (s_t, d_t), (s_n, d_n) = np.mean(themed, axis=0), np.mean(normal, axis=0)
        rows.append({"dataset": dataset, "speed_ratio": float((s_t / d_t) / (s_n / d_n)),
                     "stride_ratio": float(s_t / s_n), "cadence_ratio": float(d_n / d_t),
                     "takes": len(themed), "normal_takes": len(normal)})
    if not rows:
        raise ValueError(f"no dataset has {theme} and normal walks in splits {list(splits)}")
    return {"per_weight": float(np.mean([r["speed_ratio"] for r in rows]) - 1.0),
            "stride_per_weight": float(np.mean([r["stride_ratio"] for r in rows]) - 1.0),
            "cadence_per_weight": float(np.mean([r["cadence_ratio"] for r in rows]) - 1.0), "datasets": rows}


def bml_source(clips: list, theme: str, splits: tuple[str, ...] = ("train",), m: int = 100,
               feats: tuple[Feature, ...] | None = None, all_if_none: bool = True) -> dict | None:
    """BML's real difference for ``theme``: per actor (:func:`generation.rbf.observer.walker_of`) of ``splits`` its
    emotion walk minus its own neutral walk (:func:`generation.rbf.calibrate.walker_differences`), averaged over
    actors.

    Args:
        clips: the BML walks (:func:`generation.rbf.observer.load_bml_walks`), any split.
        splits: whose actors count; when none of them has the theme and a neutral walk and ``all_if_none``, all
            splits are used and ``splits`` in the result says so.

    Returns:
        None when the corpus has no walk of the theme; else {"dataset", "styles", "splits", "walkers": [names],
        "difference": (G,) list in walker heights, "speed_ratio", "stride_ratio", "cadence_ratio" (means over actors
        of styled / neutral), "per_walker": [{walker, difference, speed_ratio, stride_ratio, cadence_ratio}]}.
    """
    styles = tuple(s for s in C.theme_styles(theme) if any(c.style == s for c in clips))
    if not styles:
        return None
    used = tuple(splits)
    per = C.walker_differences([c for c in clips if c.split in used], theme, styles, BML_NEUTRAL, m, feats)
    if not per and all_if_none:
        used = tuple(sorted({c.split for c in clips}))
        per = C.walker_differences(clips, theme, styles, BML_NEUTRAL, m, feats)
    if not per:
        return None
    ratios = ("speed_ratio", "stride_ratio", "cadence_ratio")
    return {"dataset": BML_DATASET, "styles": list(styles), "splits": list(used),
            "walkers": [p["walker"] for p in per],
            "difference": np.mean([p["difference"] for p in per], axis=0).tolist(),
            **{k: float(np.mean([p[k] for p in per])) for k in ratios},
            "per_walker": [{"walker": p["walker"], "difference": p["difference"], **{k: p[k] for k in ratios}}
                           for p in per]}


def source_differences(clips: list, bml_clips: list | None, theme: str, splits: tuple[str, ...], m: int = 100,
                       feats: tuple[Feature, ...] | None = None) -> tuple[np.ndarray, dict[str, np.ndarray], list]:
    """(G,) target of ``theme``: the mean over sources of their real differences (walker heights), each source
    weighing the same; the Bandai datasets (:func:`generation.rbf.calibrate.real_differences`, per dataset) and,
    where ``bml_clips`` hold the theme, BML (:func:`bml_source`).

    Returns the target, {source: (G,) difference} and the per-source info (Bandai's per-dataset dicts, BML's
    :func:`bml_source` without its per-walker rows). Without a BML source the target is
    :func:`generation.rbf.calibrate.real_differences`' mean, unchanged.
    """
    bandai, info = C.real_differences(clips, theme, splits, m, feats)
    bml = bml_source(bml_clips, theme, splits, m, feats, all_if_none=tuple(splits) == ("train",)) if bml_clips else None
    per = {d["dataset"]: np.asarray(d["difference"]) for d in info}
    if bml is None:
        return bandai, per, info
    per[BML_DATASET] = np.asarray(bml["difference"])
    return np.mean(list(per.values()), axis=0), per, info + [{k: v for k, v in bml.items() if k != "per_walker"}]


def pooled_tempo(clips: list, bml: dict | None, theme: str, splits: tuple[str, ...] = ("train",),
                 m: int = 100) -> dict:
    """:func:`real_tempo` with BML as one more source where it holds the theme: ``bml`` is its :func:`bml_source`
    (ratios: means over actors of each actor's styled / neutral walk; None: Bandai alone); ``per_weight``,
    ``stride_per_weight`` and ``cadence_per_weight`` = mean over sources of the speed, stride and cadence ratio - 1,
    each source weighing the same."""
    tempo = real_tempo(clips, theme, splits, m)
    if bml is None:
        return tempo
    tempo["datasets"].append({"dataset": BML_DATASET, "speed_ratio": bml["speed_ratio"],
                              "stride_ratio": bml["stride_ratio"], "cadence_ratio": bml["cadence_ratio"],
                              "walkers": len(bml["walkers"]), "splits": bml["splits"]})
    for key, ratio in (("per_weight", "speed_ratio"), ("stride_per_weight", "stride_ratio"),
                       ("cadence_per_weight", "cadence_ratio")):
        tempo[key] = float(np.mean([r[ratio] for r in tempo["datasets"]]) - 1.0)
    return tempo


def bandai_source(dataset: str, metadata: dict) -> dict:
    """Provenance of one Bandai Namco dataset as a source: {source, licence, citation, dataset_url, what}."""
    return {"source": dataset, "licence": metadata.get("licence", "CC BY-NC 4.0"),
            "citation": metadata.get("citation", ""), "dataset_url": metadata.get("source_url", ""),
            "what": "Bandai Namco Research Motion Dataset straight walks; difference = the dataset's themed takes "
                    "minus its normal takes (no actor ids)"}


def both_sources_target(clips: list, bml_clips: list | None, theme: str, feats: tuple[Feature, ...],
                        target: np.ndarray, m: int = 100) -> tuple[np.ndarray, dict[str, float]]:
    """``target`` (G,) heights with the groups of ``theme``'s :data:`BOTH_SOURCES` rows set to the mean of their
    Bandai Namco (train) and BML (training actors) differences; also {group name: BML difference} of those groups
    (unchanged target and {} without BML walks of the theme)."""
    ranks = [rank for (t, rank) in BOTH_SOURCES if t == theme]
    if not ranks or not bml_clips:
        return target, {}
    _, per, _ = source_differences(clips, bml_clips, theme, ("train",), m, feats)
    if BML_DATASET not in per:
        return target, {}
    groups = C.theme_groups(theme, feats)
    out, used = target.copy(), {}
    for f in feats:
        if f.rank in ranks:
            g = groups.index((f.part, f.axis, f.kind))
            out[g] = float(np.mean([d[g] for d in per.values()]))
            used[f"{f.part} {f.axis} {f.kind}"] = float(per[BML_DATASET][g])
    return out, used


def extend(clips: list, base: Motion, m: int = 100, bml_clips: list | None = None, pooled: bool | None = None) -> dict:
    """The ``extended`` set of all six themes: the JSON-ready dict of :data:`generation.rbf.themes.EXTENDED_PATH`.

    ``clips``: the Bandai Namco walks (gait skeleton); ``bml_clips``: the BML walks; ``pooled`` (default: when BML
    walks are given): BML a second source of every row of the themes they hold (the ``pooled`` set); else Bandai
    alone, BML only for the :data:`BOTH_SOURCES` rows (:func:`both_sources_target`)."""
    pooled_set = bml_clips is not None if pooled is None else pooled
    first = clips[0].motion.metadata if clips else {}
    themes = {}
    for theme in THEME_NAMES:
        feats = all_features(theme)
        groups = C.theme_groups(theme, feats)
        sources = bml_clips if pooled_set else None
        train, train_per, train_info = source_differences(clips, sources, theme, ("train",), m, feats)
        heldout, held_per, held_info = source_differences(clips, sources, theme, C.HELDOUT_SPLITS, m, feats)
        both = {}
        if not pooled_set:
            train, both = both_sources_target(clips, bml_clips, theme, feats, train, m)
        pooled = BML_DATASET in train_per
        factors, gains, reached = extend_theme(base, theme, train)
        by_rank = _by_rank(theme, factors, feats)
        rows = [{"rank": f.rank, "feature": f.describe(), "source": f.source,
                 "group": groups.index((f.part, f.axis, f.kind)), "visual": f.intensity, "extended": by_rank[f.rank],
                 "factor": float(factors[groups.index((f.part, f.axis, f.kind))]),
                 **({"held_at_zero": HELD_AT_ZERO[(theme, f.rank)]} if (theme, f.rank) in HELD_AT_ZERO else {}),
                 **({"sized_on_both_sources": BOTH_SOURCES[(theme, f.rank)]} if both and (theme, f.rank) in BOTH_SOURCES
                    else {})}
                for f in feats]
        group_rows = [{"part": p, "axis": a, "kind": k, "measure": "mean offset" if k == "tilt" else "peak-to-peak",
                       "real_train": float(train[i]), "real_heldout": float(heldout[i]),
                       **({"real_train_sources": {s: float(d[i]) for s, d in train_per.items()},
                           "real_heldout_sources": {s: float(d[i]) for s, d in held_per.items()}} if pooled else {}),
                       "gain_alone": float(gains[i]),
                       "extended_w1": float(reached[i]), "expert_sign_agrees": bool(train[i] * gains[i] > 0)}
                      for i, (p, a, k) in enumerate(groups)]
        bml_train = next((d for d in train_info if d["dataset"] == BML_DATASET), None)  # source_differences' BML
        tempo = pooled_tempo(clips, bml_train, theme, ("train",), m)
        tempo["source"] = "ours"
        tempo["applied_as"] = ("with all ten features: stride scaled by max(0.5, 1 + w * stride_per_weight) (legs' "
                               "fore-aft offsets from the pelvis and progression per cycle, feet planted, pelvis "
                               "lowered where a leg cannot reach) and the cycle played max(0.5, 1 + w * "
                               "cadence_per_weight) times faster; per_weight (speed) for reference")
        themes[theme] = {"features": rows, "groups": group_rows, "tempo": tempo,
                         "sources": {"train": train_info, "heldout": held_info}}
        if both:
            themes[theme]["bml_train_differences"] = both
        if pooled:
            themes[theme]["sized_on"] = [bandai_source(s, first) if s != BML_DATASET else BML_SOURCE
                                         for s in train_per]
            themes[theme]["target"] = "mean over sources, each weighing the same"
    pooled = [t for t in themes if "sized_on" in themes[t]]
    return {"method": "generation.rbf.extended: each body part x axis x kind group of a theme's rows (Table III and "
                      "ours) sized on its own so that w = 1 moves its measure by the real style-minus-normal "
                      "difference (train split" + ("; the mean over the sources that hold the theme" if pooled else "")
                      + f"); 0 against the real sign; factor cap {MAX_FACTOR:g}; plus stride and cadence levers "
                      "(real stride and cadence ratios)",
            "units": "intensity: amplitude / walker height; measures: walker heights",
            "base": base.metadata.get("generator", "") + (" (real)" if base.metadata.get("captured_base") else ""),
            "max_factor": MAX_FACTOR, "fit_split": "train", "check_splits": list(C.HELDOUT_SPLITS),
            "data": "Bandai Namco Research Motion Dataset 1 and 2, straight walks (content walk), train split; "
                    "real-capture corpus built as docs/corpus.md says"
                    + (f"; for {' and '.join(pooled)} also the BML walks of Emotion-Gait, training actors (the "
                       "theme's sized_on lists its sources with licences and citations)" if pooled else ""),
            "licence": first.get("licence", "CC BY-NC 4.0"), "citation": first.get("citation", ""),
            "dataset_url": first.get("source_url", ""), "themes": themes}


def save_extended(data: dict, path) -> None:
    """Write :func:`extend`'s dict as JSON (floats rounded to 6 decimals)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(_rounded(data), indent=1) + "\n", encoding="utf-8")

