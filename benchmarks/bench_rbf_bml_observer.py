"""Seed 004's happy and sad walks read by a walker-normalised emotion observer trained on 30 BML actors.

The Bandai emotion scale of :mod:`generation.rbf.observer` has one training take per class; the BML walks of
Emotion-Gait (:mod:`generation.mocap.emotion_gait_bml`: 30 actors x happy, sad, angry, neutral, acted and perceived
labels; research use with citation of Ma, Paterson & Pollick 2006 and of STEP, Bhattacharya et al. AAAI 2020) give
one walk per actor and emotion, each read relative to the same actor's neutral walk.

Measures (machine: 2-core shared CPU; about a minute):
1. Held out by actor (:func:`generation.rbf.observer.heldout_by_walker`, 5 folds of 6 actors, every actor held out
   once): per class recall and mean p(own class), acted and perceived labels; the neutral walks also read relative to
   the training actors' mean neutral walk.
2. The observer trained on all 30 actors (acted labels; perceived beside) reads seed 004's happy and sad walks
   (10 features, w in -0.7, 0, 0.4, 0.7, 1.0; 3 cycles at 25 fps) relative to the neutral walk, ``extended`` and
   ``calibrated`` intensities, and the seed004 plan's 16 walks per theme (w 0.4-1.3 x 1, 4, 7, 10 features); the
   Bandai observer's readings of the same walks (docs/benchmarks/rbf_extended.json) beside. The same for the
   ``pooled`` set (happy and sad sized on Bandai and BML together), the Bandai observer's readings computed here.
3. Per actor, happy minus neutral and sad minus neutral on the theme's group measures (:func:`generation.rbf.
   calibrate.walker_differences`) and speed, stride and cadence ratios: mean and 95 % interval over actors, beside
   the Bandai training difference the extended rows were sized from and the extended w = 1 edit, and the pooled
   set's target (mean of Bandai's and BML's training actors') and w = 1 edit.

    OMP_NUM_THREADS=1 python -m benchmarks.bench_rbf_bml_observer [--corpus var/mocap/emotion-gait-bml.npz] \
        [--bandai-corpus var/mocap/bandai-namco.npz] [--json docs/benchmarks/rbf_bml_observer.json] \
        [--doc docs/benchmarks/rbf.md]

With ``--doc`` the tables replace the text between ``<!-- bml-observer -->`` and ``<!-- /bml-observer -->``.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from benchmarks.bench_rbf_extended import PLAN_COUNTS, PLAN_WEIGHTS, SETS, WALK, WEIGHTS
from benchmarks.doc_tables import publish_marked
from generation.mocap.emotion_gait_bml import CITATION
from generation.rbf import calibrate as C
from generation.rbf import observer as O
from generation.rbf.real_neutral import load_cycle
from generation.rbf.stylise import neutral_walk, stylise
from generation.rbf.themes import EXTENDED_PATH, POOLED_PATH, all_features

THEMES = ("happy", "sad")
LABELS = ("acted", "perceived")
BML_SETS = (*SETS, "pooled")
BANDAI_RESULTS = Path(__file__).resolve().parent.parent / "docs" / "benchmarks" / "rbf_extended.json"


def interval(values) -> dict:
    """{"mean", "lo", "hi", "n"}: the mean of ``values`` (n,) and its 95 % t interval (None bounds for n < 2)."""
    from scipy import stats

    x = np.asarray(values, dtype=float)
    n = len(x)
    if n < 2:
        return {"mean": float(x.mean()) if n else None, "lo": None, "hi": None, "n": n}
    half = float(stats.t.ppf(0.975, n - 1) * x.std(ddof=1) / np.sqrt(n))
    return {"mean": float(x.mean()), "lo": float(x.mean() - half), "hi": float(x.mean() + half), "n": n}


def heldout(clips) -> dict:
    """{labels: held-out-by-actor recall, mean p, takes, neutral read against other actors, folds}."""
    out = {}
    for labels in LABELS:
        h = O.heldout_by_walker(clips, labels=labels)
        out[labels] = {k: h[k] for k in ("recall", "takes", "mean_p", "neutral_other_reference", "folds")}
    return out


def readings(observers: dict, base, reference) -> dict:
    """{theme: {set: {observer labels: {weight: {p_target, top}, "plan_read_as_theme": n of 16}}}}."""
    out = {}
    for theme in THEMES:
        out[theme] = {}
        for name in BML_SETS:
            walks = {w: stylise(base, theme, w, 10, intensities=name, **WALK) for w in WEIGHTS}
            plan = [stylise(base, theme, w, n, intensities=name, **WALK) for w in PLAN_WEIGHTS for n in PLAN_COUNTS]
            out[theme][name] = {}
            for labels, obs in observers.items():
                entry = {}
                for w, motion in walks.items():
                    r = obs.read(motion, reference)
                    entry[str(w)] = {"p_target": r["p"][theme], "top": r["top"], "p": r["p"]}
                entry["plan_read_as_theme"] = sum(obs.read(m, reference)["top"] == theme for m in plan)
                out[theme][name][labels] = entry
    return out


def bandai_readings() -> dict:
    """The Bandai emotion observer's readings of the same walks, from docs/benchmarks/rbf_extended.json ({} when
    that file is missing)."""
    if not BANDAI_RESULTS.is_file():
        return {}
    res = json.loads(BANDAI_RESULTS.read_text(encoding="utf-8"))["readings"]
    return {t: {k: res[t][k] for k in (*SETS, "real_recall", "real_mean_p", "real_heldout_takes")} for t in THEMES}


def bandai_pooled(corpus: str, base, reference) -> dict:
    """{theme: {weight: {p_target, top}, "plan_read_as_theme"}}: the Bandai emotion observer (trained on the corpus's
    training takes) reading the ``pooled`` walks ({} without the corpus)."""
    if not Path(corpus).is_file():
        return {}
    obs, _ = O.train_observers(corpus)
    out = {}
    for theme in THEMES:
        entry = {}
        for w in WEIGHTS:
            r = obs.read_theme(stylise(base, theme, w, 10, intensities="pooled", **WALK), theme, reference)
            entry[str(w)] = {"p_target": r["p_target"], "top": r["top"]}
        entry["plan_read_as_theme"] = sum(
            obs.read_theme(stylise(base, theme, w, n, intensities="pooled", **WALK), theme, reference)["top"] == theme
            for w in PLAN_WEIGHTS for n in PLAN_COUNTS)
        out[theme] = entry
    return out


def differences(clips) -> dict:
    """{theme: {"groups": [{group, bml: interval, bml_actors_positive, bandai_train, extended_w1}], "tempo": {ratio:
    interval}, "bandai_tempo": [per dataset], "cycles": {how cut: clips}}}."""
    ext = json.loads(EXTENDED_PATH.read_text(encoding="utf-8"))["themes"]
    pooled = json.loads(POOLED_PATH.read_text(encoding="utf-8"))["themes"]
    out = {}
    for theme in THEMES:
        feats = all_features(theme)
        per = C.walker_differences(clips, theme, (theme,), ("neutral",), 100, feats)
        D = np.array([p["difference"] for p in per])  # (actors, G)
        rows = []
        for i, (g, gx, gp) in enumerate(zip(C.theme_groups(theme, feats), ext[theme]["groups"],
                                            pooled[theme]["groups"])):
            ours = all(f.source == "ours" for f in feats if (f.part, f.axis, f.kind) == g)
            rows.append({"group": f"{g[0]} {g[1]} {g[2]}" + (" (ours)" if ours else ""), "bml": interval(D[:, i]),
                         "bml_actors_positive": int((D[:, i] > 0).sum()), "bandai_train": gx["real_train"],
                         "extended_w1": gx["extended_w1"], "pooled_target": gp["real_train"],
                         "bml_train_actors": gp["real_train_sources"]["emotion-gait-bml"],
                         "bml_heldout_actors": gp["real_heldout_sources"]["emotion-gait-bml"],
                         "bandai_heldout": gp["real_heldout_sources"]["bandai-namco-1"],
                         "pooled_w1": gp["extended_w1"]})
        how = [h for p in per for h in p["cycles"].values()]
        out[theme] = {"groups": rows, "actors": len(per),
                      "tempo": {k: interval([p[k] for p in per]) for k in ("speed_ratio", "stride_ratio",
                                                                           "cadence_ratio")},
                      "bandai_tempo": ext[theme]["tempo"]["datasets"],
                      "pooled_tempo": pooled[theme]["tempo"], "extended_tempo": ext[theme]["tempo"],
                      "cycles": {h: how.count(h) for h in sorted(set(how))}}
    return out


def _f(x, d=2):
    return "-" if x is None else f"{x:.{d}f}"


def _ci(v, d=4, sign="+"):
    return f"{v['mean']:{sign}.{d}f} [{v['lo']:{sign}.{d}f}, {v['hi']:{sign}.{d}f}]"


def verdict(row: dict) -> str:
    """Whether the Bandai training difference agrees with the BML actors: ``sign`` when the BML interval excludes 0
    on the other side, ``size`` when it lies outside the interval on the same side, else ``agrees``."""
    b, v = row["bandai_train"], row["bml"]
    if v["lo"] > 0 > b or v["hi"] < 0 < b:
        return "sign"
    return "size" if not v["lo"] <= b <= v["hi"] else "agrees"


def render(res: dict) -> str:
    h = res["heldout"]
    lines = [f"Run {res['date']}, {res['machine']}, {res['seconds']:.0f} s; corpus `{res['corpus']}` (BML walks of "
             "Emotion-Gait, 30 actors x 4 acted emotions; research use with citation: Ma, Paterson & Pollick 2006; "
             "Bhattacharya et al., AAAI 2020); observer `generation.rbf.observer` (`normalise=\"walker\"`, each walk "
             "minus the same actor's neutral walk).", "",
             "Held out by actor (5 folds of 6 actors, every actor held out once, never trained on; each read relative "
             "to its own neutral walk). A held-out neutral walk is its own reference (its windows' spread only), so "
             "its recall is high by construction; the last column reads it relative to the training actors' mean "
             "neutral walk instead:", "",
             "| labels | class | walks | recall | mean p(own class) | neutral vs other actors' neutral |",
             "|---|---|---|---|---|---|"]
    for labels, v in h.items():
        for k in v["recall"]:
            o = v["neutral_other_reference"]
            extra = f"recall {_f(o['recall'])}, p {_f(o['mean_p'])}" if k == "neutral" else ""
            lines.append(f"| {labels} | {k} | {v['takes'][k]} | {_f(v['recall'][k])} | {_f(v['mean_p'][k])} | "
                         f"{extra} |")
    lines += ["", "p(theme) (top class) of seed 004's styled walk (10 features, 3 cycles at 25 fps, read relative to "
              "the neutral walk) by the BML observer trained on all 30 actors (acted labels; perceived below) and by "
              "the Bandai observer (one training take per class, docs/benchmarks/rbf_extended.json); last column: of "
              "the seed004 plan's 16 walks of the theme (w 0.4-1.3 x 1, 4, 7, 10 features), how many read as the "
              "theme:", "",
              "| theme | set | observer | " + " | ".join(f"w = {w}" for w in WEIGHTS) + " | plan walks |",
              "|---|---|---|" + "---|" * len(WEIGHTS) + "---|"]
    bandai = res["bandai_readings"]
    for theme, sets in res["readings"].items():
        for name in BML_SETS:
            rows = [(f"BML {labels}", e) for labels, e in sets[name].items()]
            if name == "pooled" and theme in res.get("bandai_pooled", {}):
                rows.append(("Bandai", res["bandai_pooled"][theme]))
            elif name != "pooled" and theme in bandai:
                rows.append(("Bandai", bandai[theme][name]))
            for who, e in rows:
                cells = [f"{e[str(w)]['p_target']:.2f} ({e[str(w)]['top']})" for w in WEIGHTS]
                lines.append(f"| {theme} | {name} | {who} | " + " | ".join(cells) + f" | "
                             f"{e['plan_read_as_theme']}/16 |")
    lines += ["", "Real differences per group of the theme's rows (walker heights; tilt: mean offset relative to the "
              "pelvis, swing: peak-to-peak): BML emotion minus the same actor's neutral walk, mean [95 % t interval] "
              "over actors and how many actors are positive, beside the Bandai training difference (one dataset-1 "
              "take per style minus its normal take) from which the extended rows were sized and the extended w = 1 "
              "edit; verdict: `sign` where the BML interval excludes zero on the other side of Bandai's, `size` "
              "where Bandai's value lies outside the interval on the same side:", "",
              "| theme | group | BML (per actor) | actors > 0 | Bandai train | extended w = 1 | verdict |",
              "|---|---|---|---|---|---|---|"]
    for theme, d in res["differences"].items():
        for r in d["groups"]:
            lines.append(f"| {theme} | {r['group']} | {_ci(r['bml'])} | {r['bml_actors_positive']}/{r['bml']['n']} | "
                         f"{r['bandai_train']:+.4f} | {r['extended_w1']:+.4f} | {verdict(r)} |")
    lines += ["", "The `pooled` set's targets: the mean of Bandai's training difference and the mean over BML's "
              "training actors (21), each source weighing the same; held out: Bandai's held-out takes and BML's "
              "held-out actors (9), never used to size (walker heights):", "",
              "| theme | group | Bandai train | BML train actors | pooled target | pooled w = 1 | Bandai held out | "
              "BML held-out actors |", "|---|---|---|---|---|---|---|---|"]
    for theme, d in res["differences"].items():
        for r in d["groups"]:
            lines.append(f"| {theme} | {r['group']} | {r['bandai_train']:+.4f} | {r['bml_train_actors']:+.4f} | "
                         f"{r['pooled_target']:+.4f} | {r['pooled_w1']:+.4f} | {r['bandai_heldout']:+.4f} | "
                         f"{r['bml_heldout_actors']:+.4f} |")
    lines += ["", "Tempo, emotion / the same actor's neutral walk (speed = stride / cycle duration, cadence = 1 / "
              "duration), mean [95 % interval] over actors, beside Bandai dataset 1's one take (the extended tempo "
              "is sized from its speed ratio):", "",
              "| theme | actors | speed ratio | stride ratio | cadence ratio | Bandai speed / stride / cadence |",
              "|---|---|---|---|---|---|"]
    for theme, d in res["differences"].items():
        t = d["tempo"]
        b = "; ".join(f"{x['speed_ratio']:.2f} / {x['stride_ratio']:.2f} / {x['cadence_ratio']:.2f}"
                      for x in d["bandai_tempo"])
        lines.append(f"| {theme} | {d['actors']} | {_ci(t['speed_ratio'], 2, '')} | {_ci(t['stride_ratio'], 2, '')} "
                     f"| {_ci(t['cadence_ratio'], 2, '')} | {b} |")
    lines += ["", "Pooled stride and cadence levers (speed / stride / cadence ratio per source, training split; per "
              "unit weight = their mean over sources - 1, stride / cadence, speed for reference):", "",
              "| theme | per source | extended per unit weight | pooled per unit weight |", "|---|---|---|---|"]
    keys = ("stride_per_weight", "cadence_per_weight", "per_weight")
    for theme, d in res["differences"].items():
        p = d["pooled_tempo"]
        per = "; ".join(f"{x['dataset']} {x['speed_ratio']:.2f} / {x['stride_ratio']:.2f} / {x['cadence_ratio']:.2f}"
                        for x in p["datasets"])
        ext = " / ".join(f"{d['extended_tempo'][k]:+.3f}" for k in keys)
        lines.append(f"| {theme} | {per} | {ext} | {' / '.join(f'{p[k]:+.3f}' for k in keys)} |")
    cuts = {k: sum(d["cycles"].get(k, 0) for d in res["differences"].values()) for k in ("steady", "loop", "none")}
    lines += ["", f"Cycles: {cuts['steady']} clip readings used steady cycles "
              "(`generation.rbf.real_neutral.steady_cycles`); the BML clips are about 2.5 s, and where no left-right-"
              f"left strike sequence could be cut ({cuts['loop']}) one loop period of the clip (its importer's "
              "`loop_period_frames`, the clip being one cycle repeated) stands in "
              f"(`generation.rbf.calibrate.clip_cycles`); {cuts['none']} without either. Counts over the happy, sad "
              "and neutral clips of both themes (neutral counted twice)."]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", default="var/mocap/emotion-gait-bml.npz")
    ap.add_argument("--bandai-corpus", default="var/mocap/bandai-namco.npz",
                    help="Bandai corpus for the Bandai observer's readings of the pooled set")
    ap.add_argument("--json", default="docs/benchmarks/rbf_bml_observer.json")
    ap.add_argument("--doc", default=None)
    args = ap.parse_args(argv)
    t0 = time.time()
    clips = O.load_bml_walks(args.corpus)
    observers = {labels: O.train_bml_observer(clips, labels) for labels in LABELS}
    base = load_cycle()
    reference = O.reference_descriptor(neutral_walk(base, **WALK))
    res = {"date": time.strftime("%Y-%m-%d"), "machine": "2-core shared CPU, no GPU", "corpus": args.corpus,
           "citation": CITATION, "heldout": heldout(clips), "readings": readings(observers, base, reference),
           "bandai_readings": bandai_readings(), "bandai_pooled": bandai_pooled(args.bandai_corpus, base, reference),
           "differences": differences(clips)}
    res["seconds"] = time.time() - t0
    publish_marked(res, args.json, render(res), args.doc, "bml-observer")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
