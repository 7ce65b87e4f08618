"""Seed 004's styled walks read by walker-normalised style observers: the old default (calibrated) vs extended.

Measures (machine: 2-core shared CPU; about 2-3 min):
1. The walker-normalised observers (:mod:`generation.rbf.observer`, trained on the training takes of the Bandai
   Namco walks): held-out recall per scale and class (val and test takes), and held out by dataset (trained on one
   dataset's takes, reading the other's, each relative to its own dataset's normal walks).
2. Per theme and weight (-0.7, 0 (the base), 0.4, 0.7, 1.0; ten features): p(theme) and the top class of the styled
   walk read relative to the neutral walk (the plan's walk: 3 cycles at 25 fps), with the ``calibrated`` intensities
   (the default before) and the ``extended`` ones (the default after), beside the held-out real takes of the style.
3. The built-in ``seed004`` plan's 16 walks per theme (w 0.4, 0.7, 1.0, 1.3 x 1, 4, 7, 10 features): how many read
   as the theme, before and after.
4. Feature differences per group of the theme's rows (Table III and ours): real style minus normal (train and
   held-out takes) beside the generated w = 1 edit minus the base, calibrated and extended; and the stride and
   cadence levers (real ratios vs the extended walk's at w = 1, measured on the walk's own steady cycles).

    OMP_NUM_THREADS=1 python -m benchmarks.bench_rbf_extended [--corpus var/mocap/bandai-namco.npz] \
        [--json docs/benchmarks/rbf_extended.json] [--doc docs/benchmarks/rbf.md]

With ``--doc`` the tables replace the text between ``<!-- extended -->`` and ``<!-- /extended -->``.
"""
from __future__ import annotations

import argparse
import json
import time

from benchmarks.doc_tables import publish_marked
from generation.rbf import calibrate as C
from generation.rbf import observer as O
from generation.rbf.real_neutral import load_cycle, steady_cycles
from generation.rbf.stylise import neutral_walk, stylise
from generation.rbf.themes import CALIBRATED_PATH, EXTENDED_PATH, THEME_NAMES, all_features

WEIGHTS = (-0.7, 0.0, 0.4, 0.7, 1.0)  # 0: the neutral walk itself
SETS = ("calibrated", "extended")  # before, after
PLAN_WEIGHTS = (0.4, 0.7, 1.0, 1.3)
PLAN_COUNTS = (1, 4, 7, 10)
WALK = {"n_cycles": 3, "fps": 25.0}  # the seed004 plan's walks
GAIT_WALK = {"n_cycles": 6, "fps": 25.0}  # long enough for several steady cycles


def cross_dataset(clips) -> dict:
    """Energy and gender scales trained on one dataset's takes (all splits), reading the other dataset's takes
    relative to that dataset's normal walks: {scale: {"train dataset -> read dataset": {class: recall (n)}}}."""
    out = {}
    datasets = ("bandai-namco-1", "bandai-namco-2")
    for scale in ("energy", "gender"):
        out[scale] = {}
        for train_ds in datasets:
            read_ds = next(d for d in datasets if d != train_ds)
            obs = O.RbfStyleObserver.fit(clips, scale, "walker", train_splits=("train", "val", "test"),
                                         datasets=(train_ds,))
            refs = O.dataset_references(clips, ("train", "val", "test"))
            held = obs.heldout([c for c in clips if c.motion.num_frames >= 60], ("train", "val", "test"), refs,
                               (read_ds,))
            out[scale][f"{train_ds[-1]} -> {read_ds[-1]}"] = {
                k: {"recall": held["recall"][k], "takes": held["takes"][k]} for k in obs.classes}
    return out


def readings(obs, held, base, reference) -> dict:
    out = {}
    for theme in THEME_NAMES:
        scale, target = O.THEME_SCALE[theme]
        entry = {"scale": scale, "target": target, "real_heldout_takes": held[scale]["takes"][target],
                 "real_recall": held[scale]["recall"][target], "real_mean_p": held[scale]["mean_p"][target]}
        for name in SETS:
            entry[name] = {}
            for w in WEIGHTS:
                r = obs.read_theme(stylise(base, theme, w, 10, intensities=name, **WALK), theme, reference)
                entry[name][str(w)] = {"p_target": r["p_target"], "top": r["top"]}
            plan = [obs.read_theme(stylise(base, theme, w, n, intensities=name, **WALK), theme, reference)["top"]
                    for w in PLAN_WEIGHTS for n in PLAN_COUNTS]
            entry[name]["plan_read_as_theme"] = sum(t == target for t in plan)
        out[theme] = entry
    return out


def walk_gait(motion) -> tuple[float, float]:
    """Mean stride (heights per cycle) and duration (s) of a walk's steady cycles, cut at its own left heel strikes
    (as :func:`generation.rbf.extended.real_tempo` measures the real takes)."""
    cycles = steady_cycles(motion, 100, "bench")
    return sum(c.stride for c in cycles) / len(cycles), sum(c.duration_s for c in cycles) / len(cycles)


def generated_gait(base, theme: str, w: float = 1.0) -> dict:
    """The extended walk's stride, cadence and speed at weight ``w`` (ten features) over the neutral walk's."""
    stride0, dur0 = walk_gait(neutral_walk(base, **GAIT_WALK))
    stride, dur = walk_gait(stylise(base, theme, w, 10, **GAIT_WALK))
    return {"stride": stride / stride0, "cadence": dur0 / dur, "speed": stride / stride0 * dur0 / dur}


def features(base) -> dict:
    cal = json.loads(CALIBRATED_PATH.read_text(encoding="utf-8"))["themes"]
    ext = json.loads(EXTENDED_PATH.read_text(encoding="utf-8"))["themes"]
    out = {}
    for theme in THEME_NAMES:
        feats = all_features(theme)
        groups = C.theme_groups(theme, feats)
        c_w1 = C.generated_measures(base, theme, "calibrated", 1.0, feats)
        e_w1 = C.generated_measures(base, theme, "extended", 1.0, feats)
        rows = []
        for i, (g, gx) in enumerate(zip(groups, ext[theme]["groups"])):
            ours = all(f.source == "ours" for f in feats if (f.part, f.axis, f.kind) == g)
            rows.append({"group": f"{g[0]} {g[1]} {g[2]}" + (" (ours)" if ours else ""),
                         "real_train": gx["real_train"], "real_heldout": gx["real_heldout"],
                         "calibrated_w1": float(c_w1[i]), "extended_w1": float(e_w1[i])})
        t = ext[theme]["tempo"]
        out[theme] = {"groups": rows, "tempo": {
            "real_speed_ratio": [d["speed_ratio"] for d in t["datasets"]],
            "real_stride_ratio": [d["stride_ratio"] for d in t["datasets"]],
            "real_cadence_ratio": [d["cadence_ratio"] for d in t["datasets"]],
            "per_weight": t["per_weight"], "stride_per_weight": t["stride_per_weight"],
            "cadence_per_weight": t["cadence_per_weight"], "generated_w1": generated_gait(base, theme)}}
        assert len(cal[theme]["groups"]) <= len(rows)
    return out


def _f(x, d=2):
    return "-" if x is None else f"{x:.{d}f}"


def render(res: dict) -> str:
    lines = [f"Run {res['date']}, {res['machine']}, {res['seconds']:.0f} s; corpus `{res['corpus']}`; observers "
             "`generation.rbf.observer` (`normalise=\"walker\"`).", "",
             "Held-out recall (val and test takes, whole takes held out; each read relative to its dataset's "
             "training normal walks):", "", "| scale | class | held-out takes | recall | mean p(own class) |",
             "|---|---|---|---|---|"]
    for scale, h in res["observers"].items():
        for k in h["recall"]:
            lines.append(f"| {scale} | {k} | {h['takes'][k]} | {_f(h['recall'][k])} | {_f(h['mean_p'][k])} |")
    lines += ["", "Held out by dataset (another recording with its own actors; the corpus has no actor ids): trained "
              "on all takes of one dataset, reading every take of at least 2 s of the other:", "",
              "| scale | trained -> read | class | takes | recall |",
              "|---|---|---|---|---|"]
    for scale, runs in res["cross_dataset"].items():
        for run, classes in runs.items():
            for k, v in classes.items():
                lines.append(f"| {scale} | {run} | {k} | {v['takes']} | {_f(v['recall'])} |")
    lines += ["", "p(theme) (top class) of the styled walk (10 features, 3 cycles at 25 fps, read relative to the "
              "neutral walk), before (`calibrated`, the old default) and after (`extended`); the held-out real takes "
              "of the style beside (recall, mean p); last column: of the seed004 plan's 16 walks of the theme "
              "(w 0.4-1.3 x 1, 4, 7, 10 features), how many read as the theme:", "",
              "| theme | set | " + " | ".join(f"w = {w}" for w in WEIGHTS) + " | held-out real takes | plan walks |",
              "|---|---|" + "---|" * len(WEIGHTS) + "---|---|"]
    for theme, e in res["readings"].items():
        for name in SETS:
            cells = [f"{e[name][str(w)]['p_target']:.2f} ({e[name][str(w)]['top']})" for w in WEIGHTS]
            real = f"recall {_f(e['real_recall'])}, p {_f(e['real_mean_p'])} (n = {e['real_heldout_takes']})"
            lines.append(f"| {theme} | {name} | " + " | ".join(cells) + f" | {real} | "
                         f"{e[name]['plan_read_as_theme']}/16 |")
    lines += ["", "Feature differences per group of the theme's rows (walker heights; tilt: mean offset relative to "
              "the pelvis, swing: peak-to-peak change): real style minus normal beside the generated w = 1 edit minus "
              "the base:", "", "| theme | group | real (train) | real (held out) | calibrated w = 1 | extended w = 1 |",
              "|---|---|---|---|---|---|"]
    for theme, entry in res["features"].items():
        for r in entry["groups"]:
            lines.append(f"| {theme} | {r['group']} | {r['real_train']:+.4f} | {r['real_heldout']:+.4f} | "
                         f"{r['calibrated_w1']:+.4f} | {r['extended_w1']:+.4f} |")
    lines += ["", "Stride and cadence (levers of ours; real style / the same dataset's normal walks, train takes, per "
              "dataset; the extended walk's stride is scaled by max(0.5, 1 + w x stride) and its cadence by "
              "max(0.5, 1 + w x cadence), per unit weight the mean real ratio - 1); the extended walk at w = 1 "
              "measured on its own steady cycles (6 cycles, contacts detected on the walk) over the neutral walk's:",
              "", "| theme | real stride ratio | real cadence ratio | real speed ratio | stride / cadence per unit "
              "weight | w = 1 stride | w = 1 cadence | w = 1 speed |", "|---|---|---|---|---|---|---|---|"]
    for theme, entry in res["features"].items():
        t, g = entry["tempo"], entry["tempo"]["generated_w1"]
        lines.append(f"| {theme} | {', '.join(f'{x:.2f}' for x in t['real_stride_ratio'])} | "
                     f"{', '.join(f'{x:.2f}' for x in t['real_cadence_ratio'])} | "
                     f"{', '.join(f'{x:.2f}' for x in t['real_speed_ratio'])} | "
                     f"{t['stride_per_weight']:+.3f} / {t['cadence_per_weight']:+.3f} | {g['stride']:.2f} | "
                     f"{g['cadence']:.2f} | {g['speed']:.2f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", default="var/mocap/bandai-namco.npz")
    ap.add_argument("--json", default="docs/benchmarks/rbf_extended.json")
    ap.add_argument("--doc", default=None)
    args = ap.parse_args(argv)
    t0 = time.time()
    obs, clips = O.train_observers(args.corpus)
    base = load_cycle()
    held = obs.heldout(clips)
    reference = O.reference_descriptor(neutral_walk(base, **WALK))
    res = {"date": time.strftime("%Y-%m-%d"), "machine": "2-core shared CPU, no GPU", "corpus": args.corpus,
           "observers": {s: {k: h[k] for k in ("recall", "takes", "mean_p")} for s, h in held.items()},
           "cross_dataset": cross_dataset(clips), "readings": readings(obs, held, base, reference),
           "features": features(base)}
    res["seconds"] = time.time() - t0
    publish_marked(res, args.json, render(res), args.doc, "extended")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
