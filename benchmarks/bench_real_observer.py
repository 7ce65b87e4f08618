"""The real-capture gait observer on held-out real takes, the demo and seed000 plans' gait clips read by it and by the
synthetic observer, and the realism measures of real walks beside the generated ones.

    python -m benchmarks.bench_real_observer [--corpus var/mocap/bandai-namco.npz] [--plans demo seed000]
        [--json docs/benchmarks/real_observer.json] [--md docs/benchmarks/mocap.md]

1. Held-out takes: the observer (generation/quality/real_observer.py) is fitted on the corpus's training split and
   read on its test split (held out by take): the four gait emotions on dataset 1 (happy, sad, angry, normal =
   neutral), confusion matrix per take and per window; the theme pairs on both datasets.
2. Plans: every gait entry of each plan made as ``generate_clips`` makes it (no video, no figure-height projection)
   and checked by the quality gate (:func:`generation.pipeline.plan_qa.run`) once with the real-capture observer
   and once with the synthetic one (``plan_qa.run(gait_observer="synthetic")``), grouped by the intended dominant
   emotion.
3. Realism: the measures of :mod:`generation.quality.realism` per real style (all gait takes) beside the plans'
   generated clips (and the plans' real source walks, cut as rendered).

Writes the JSON, then renders it into the ``real_observer.*`` tables marked in the Markdown file
(benchmarks/doc_tables.py; the narrative there is written by hand).
Real capture: Bandai Namco Research Motion Dataset (Kobayashi et al. 2023, arXiv:2306.08861), CC BY-NC 4.0.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import re
import shlex
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from benchmarks import doc_tables
from benchmarks.bench_record import commit_label, machine_label, one_thread
from generation.mocap.real_corpus import load_real_corpus, real_corpus_path
from generation.quality import real_observer as ro
from generation.quality.observers import OBSERVERS
from generation.quality.realism import MEASURES
from generation.quality.realism_ranges import load_ranges, measure_corpus
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS


def held_out(obs: ro.RealGaitObserver, test) -> dict:
    """Emotion confusion (per take and per window) and theme-pair accuracy on held-out CorpusClips."""
    emo = [c for c in test if c.dataset == ro.EMOTION_DATASET and c.style in CAPTURE_GAIT_EMOTIONS]
    takes = np.zeros((4, 4), int)
    windows = np.zeros((4, 4), int)
    rows = []
    for c in emo:
        k = GAIT_EMOTIONS.index(CAPTURE_GAIT_EMOTIONS[c.style])
        p = obs.proba(c.motion)
        takes[k, int(p.argmax())] += 1
        for w in obs.clf.predict(ro.window_descriptors(c.motion)):
            windows[k, int(w)] += 1
        rows.append({"take": c.name, "intended": GAIT_EMOTIONS[k], "read": GAIT_EMOTIONS[int(p.argmax())],
                     "p": round(float(p.max()), 3)})
    themes = {}
    for name, (first, second) in ro.THEME_PAIRS.items():
        sel = [c for c in test if c.style in first + second]
        if not sel or name not in obs.themes:
            continue
        y = np.array([int(c.style in second) for c in sel])
        p = np.array([obs.theme_proba(c.motion, name) for c in sel])
        themes[name] = {"n": len(sel), "accuracy": round(float(((p > 0.5) == y).mean()), 3),
                        "per_dataset": {d: int(sum(c.dataset == d for c in sel)) for d in sorted({c.dataset
                                                                                                  for c in sel})},
                        "wrong": [c.name for c, yy, pp in zip(sel, y, p) if (pp > 0.5) != yy]}
    return {"n_takes": len(emo), "accuracy_takes": round(float(np.trace(takes) / max(takes.sum(), 1)), 3),
            "recall_takes": {e: round(float(takes[i, i] / max(takes[i].sum(), 1)), 3) for i, e in
                             enumerate(GAIT_EMOTIONS)},
            "confusion_takes": takes.tolist(), "accuracy_windows": round(float(np.trace(windows) / windows.sum()), 3),
            "recall_windows": {e: round(float(windows[i, i] / max(windows[i].sum(), 1)), 3) for i, e in
                               enumerate(GAIT_EMOTIONS)},
            "confusion_windows": windows.tolist(), "takes": rows, "themes": themes}


def leave_one_take_out(clips, C: float = 0.1) -> dict:
    """Emotion confusion over every dataset-1 happy/sad/angry/normal take (any split), each read by an observer
    fitted on all the others: a steadier estimate than the 8 held-out takes (20 instead of 8), at the price of
    mixing the split."""
    emo = [c for c in clips if c.dataset == ro.EMOTION_DATASET and c.style in CAPTURE_GAIT_EMOTIONS]
    desc = [ro.window_descriptors(c.motion) for c in emo]
    labels = [GAIT_EMOTIONS.index(CAPTURE_GAIT_EMOTIONS[c.style]) for c in emo]
    cm = np.zeros((4, 4), int)
    for i in range(len(emo)):
        rest = [j for j in range(len(emo)) if j != i]
        X = np.concatenate([desc[j] for j in rest])
        y = np.concatenate([np.full(len(desc[j]), labels[j]) for j in rest])
        w = np.concatenate([np.full(len(desc[j]), 1.0 / len(desc[j])) for j in rest])
        clf = ro._fit(X, y, w, C)
        p = np.zeros(4)
        p[clf.classes_.astype(int)] = clf.predict_proba(desc[i]).mean(0)
        cm[labels[i], int(p.argmax())] += 1
    return {"n_takes": len(emo), "accuracy": round(float(np.trace(cm) / cm.sum()), 3), "confusion": cm.tolist()}


#: Plan theme -> (theme pair of the real observer, index of the theme in the pair).
THEME_SIDE = {"energetic": ("energetic_vs_tired", 0), "tired": ("energetic_vs_tired", 1),
              "feminine": ("feminine_vs_masculine", 0), "masculine": ("feminine_vs_masculine", 1),
              "happy": ("happy_vs_sad", 0), "sad": ("happy_vs_sad", 1)}


def theme_rows(plan: str, obs: ro.RealGaitObserver) -> list[dict]:
    """The plan's gait theme entries (a theme of :data:`THEME_SIDE`) read by the real observer's theme pair:
    the probability of the entry's own theme (an inverted entry, weight < 0, aims at the other one)."""
    from generation.pipeline.jobs import plan_jobs
    from generation.plans.clipgen import make_motion
    from generation.plans.schema import load_plan
    from generation.render.clip import prepare

    out = []
    jobs, _ = plan_jobs(load_plan(plan))
    for job in jobs:
        entry = job.run_entry
        theme = entry.inputs.get("theme")
        if entry.modality != "gait" or theme not in THEME_SIDE:
            continue
        pair, side = THEME_SIDE[theme]
        motion, _ = prepare(make_motion(entry, requested=job.entry.generator, fallback_reason=job.fallback_reason),
                            entry.render)
        p_second = obs.theme_proba(motion, pair)
        weight = entry.inputs.get("weight")
        out.append({"entry": job.entry.id, "generator": entry.generator, "theme": theme, "weight": weight,
                    "pair": pair, "p_theme": round(p_second if side else 1.0 - p_second, 3)})
    return out


def dominant(vec) -> str | None:
    from generation.quality.checks import _dominant

    return _dominant(vec)


def plan_rows(plan: str, kind: str) -> list[dict]:
    """plan_qa rows of the plan's gait entries read by the ``kind`` gait observer, with ``intended_dominant`` and
    ``origin``/``theme`` from the plan."""
    from generation.pipeline import plan_qa
    from generation.plans.schema import load_plan

    rows = plan_qa.run(plan, modality="gait", figure_height=False, log=lambda *a: None, gait_observer=kind)
    entries = {e.id: e for e in load_plan(plan).entries}
    for r in rows:
        e = entries[r["entry"]]
        r["intended_dominant"] = dominant(e.inputs.get("emotion"))
        r["origin"] = e.origin
        r["theme"] = e.inputs.get("theme")
    return rows


def readings(real_rows: list[dict], synth_rows: list[dict]) -> dict:
    """Per intended emotion: clips, read as intended by each observer, their labels and median p."""
    synth = {r["entry"]: r for r in synth_rows}
    out = defaultdict(lambda: {"n": 0, "real_read": [], "real_p": [], "synthetic_read": [], "synthetic_p": [],
                               "flag_observer_real": 0, "origins": []})
    for r in real_rows:
        key = r["intended_dominant"] or ("(theme " + r["theme"] + ")" if r.get("theme") else "(none)")
        g = out[key]
        g["n"] += 1
        g["origins"].append(f"{r['origin']} {r['generator']}")
        g["real_read"].append(r["observed"])
        g["real_p"].append(r["observed_p"])
        g["flag_observer_real"] += "observer" in (r["flag"] or "").split(";")
        s = synth.get(r["entry"], {})
        g["synthetic_read"].append(s.get("observed"))
        g["synthetic_p"].append(s.get("observed_p"))
    return dict(out)


def _stat(values) -> dict:
    v = np.asarray([x for x in values if x is not None], dtype=float)
    if not v.size:
        return {"n": 0}
    return {"n": int(v.size), "median": round(float(np.median(v)), 3), "min": round(float(v.min()), 3),
            "max": round(float(v.max()), 3), "p5": round(float(np.percentile(v, 5)), 3),
            "p95": round(float(np.percentile(v, 95)), 3)}


def realism_table(real: list[dict], plans: dict[str, list[dict]]) -> dict:
    """{group: {measure: stats}}: real takes per (dataset, style) and pooled, then per plan generated / source."""
    out = {}
    groups = defaultdict(list)
    for r in real:
        groups[f"real {r['dataset'].removeprefix('bandai-namco-')}: {r['style']}"].append(r)
    for name in sorted(groups):
        out[name] = {m: _stat(r[m] for r in groups[name]) for m in MEASURES}
    out["real: all takes"] = {m: _stat(r[m] for r in real) for m in MEASURES}
    for plan, rows in plans.items():
        for origin in ("generated", "source"):
            sel = [r for r in rows if r["origin"] == origin]
            if sel:
                gens = ", ".join(f"{g} {n}" for g, n in sorted(_count(r["generator"] for r in sel).items()))
                key = f"{plan} {origin} ({gens})"
                out[key] = {m: _stat(r[m] for r in sel) for m in MEASURES}
                out[key]["realism_flagged"] = sum("realism" in (r["flag"] or "").split(";") for r in sel)
                out[key]["bounds_broken"] = _count(re.sub(r"[\d.]+$", "", b) for r in sel
                                                   for b in (r["realism_out"] or "").split(";") if b)
    return out


def _count(items) -> dict:
    out = defaultdict(int)
    for x in items:
        out[x] += 1
    return dict(out)


def main(argv=None) -> int:
    one_thread()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", default=None)
    ap.add_argument("--plans", nargs="*", default=["demo", "seed000"])
    ap.add_argument("--json", default=str(doc_tables.area_files("real_observer")[0]))
    ap.add_argument("--md", default=str(doc_tables.area_files("real_observer")[1]),
                    help="render the real_observer tables marked in this page")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    path = Path(args.corpus) if args.corpus else real_corpus_path(os.environ)
    obs = OBSERVERS.gait("real", path)
    if obs is None or not path.is_file():
        raise SystemExit(f"{path}: no real-capture corpus; build it with `python -m generation.mocap dataset "
                         "bandai-namco DIR --out PATH`")
    test = load_real_corpus(path, skeleton="gait", split="test")
    real = measure_corpus(load_real_corpus(path, skeleton="gait"))
    synth = OBSERVERS.gait("synthetic")
    plans_real = {p: plan_rows(p, "real") for p in args.plans}
    plans_synth = {p: plan_rows(p, "synthetic") for p in args.plans}
    ranges = load_ranges()
    res = {"date": datetime.date.today().isoformat(), "commit": commit_label(),
           "command": shlex.join(["python", "-m", "benchmarks.bench_real_observer",
                                  *(sys.argv[1:] if argv is None else argv)]),
           "machine": machine_label(),
           "corpus": path.name, "observer_source": obs.source, "train_takes": dict(obs.train_takes),
           "synthetic_source": ("logistic regression on the SYNTHETIC procedural gait corpus (var/corpus/)"
                                if synth is not None else "not available (no synthetic gait corpus in var/corpus/)"),
           "held_out": held_out(obs, test),
           "leave_one_take_out": leave_one_take_out(load_real_corpus(path, skeleton="gait",
                                                                     styles=tuple(CAPTURE_GAIT_EMOTIONS))),
           "themes_in_plans": {p: theme_rows(p, obs) for p in args.plans},
           "plans": {p: readings(plans_real[p], plans_synth[p]) for p in args.plans},
           "plan_rows": plans_real, "realism": realism_table(real, plans_real),
           "thresholds": ranges["thresholds"], "not_applied": ranges.get("not_applied", {}),
           "ranges_rule": ranges["rule"],
           "ranges_test_flagged": ranges["test_flagged_share"]}
    res["seconds"] = time.perf_counter() - t0
    Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    Path(args.json).write_text(json.dumps(res, indent=1, default=str) + "\n", encoding="utf-8")
    print(f"wrote {args.json}")
    print(f"{args.md} tables:", ", ".join(doc_tables.update_doc("real_observer", Path(args.json), Path(args.md)))
          or "none marked")
    return 0


if __name__ == "__main__":
    sys.exit(main())
