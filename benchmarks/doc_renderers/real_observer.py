"""Tables of the real-capture observer and realism (benchmarks/bench_real_observer.py; docs/benchmarks/mocap.md)."""
from __future__ import annotations

import statistics

from benchmarks.doc_renderers.common import EMOTIONS, Renderer, _run, table


def real_observer_run(r: dict) -> list[str]:
    return _run(r, ("corpus", r["corpus"]), ("real-capture observer", r["observer_source"]),
                ("synthetic observer", r["synthetic_source"]))


def real_observer_emotion_accuracy(r: dict) -> list[str]:
    """Four-emotion accuracy on the held-out takes and with leave one take out."""
    h, lo = r["held_out"], r["leave_one_take_out"]
    return table(["emotion classifier", "training takes", "takes read", "accuracy per take", "per 2 s window"], [
        ["held out (test split)", sum(r["train_takes"].values()), h["n_takes"], f"{h['accuracy_takes']:.2f}",
         f"{h['accuracy_windows']:.2f}"],
        ["leave one take out (train and test split)", lo["n_takes"] - 1, lo["n_takes"], f"{lo['accuracy']:.2f}", "-"]])


def _confusion(cm: list[list[int]]) -> list[str]:
    """Rows: intended emotion, columns: the observer's top label, and the recall of each row."""
    return table(["intended \\ read", *EMOTIONS, "recall"],
                 [[e, *cm[i], f"{cm[i][i] / sum(cm[i]):.2f}" if sum(cm[i]) else "-"] for i, e in enumerate(EMOTIONS)])


def real_observer_confusion_takes(r: dict) -> list[str]:
    return _confusion(r["held_out"]["confusion_takes"])


def real_observer_confusion_windows(r: dict) -> list[str]:
    return _confusion(r["held_out"]["confusion_windows"])


def real_observer_confusion_loto(r: dict) -> list[str]:
    return _confusion(r["leave_one_take_out"]["confusion"])


def real_observer_themes(r: dict) -> list[str]:
    return table(["pair", "held-out takes", "accuracy", "takes per dataset", "wrong"],
                 [[name.replace("_", " "), t["n"], f"{t['accuracy']:.2f}",
                   ", ".join(f"{k}: {v}" for k, v in t["per_dataset"].items()), ", ".join(t["wrong"]) or "-"]
                  for name, t in r["held_out"]["themes"].items()])


def real_observer_plan_themes(r: dict) -> list[str]:
    return table(["plan", "entry", "generator", "theme", "weight", "pair", "p(theme)"],
                 [[plan, t["entry"], t["generator"], t["theme"], t["weight"], t["pair"].replace("_", " "),
                   f"{t['p_theme']:.2f}"] for plan, rows in r["themes_in_plans"].items() for t in rows])


def _counts(items) -> dict:
    out: dict = {}
    for x in items:
        out[x] = out.get(x, 0) + 1
    return out


def _readings(labels: list, ps: list) -> str:
    """'label count, ...' most frequent first, and the median top probability in brackets."""
    if not any(labels):
        return "no reading"
    counts = _counts(lab or "none" for lab in labels)
    ps = [p for p in ps if p is not None]
    med = statistics.median(ps) if ps else float("nan")
    return ", ".join(f"{k} {v}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1])) + f" ({med:.2f})"


def real_observer_plans(r: dict) -> list[str]:
    """Per plan and intended dominant emotion: the clips' readings by the real-capture and the synthetic observer."""
    rows = []
    for plan, groups in r["plans"].items():
        for key, g in sorted(groups.items()):
            origins = ", ".join(f"{o} {n}" for o, n in sorted(_counts(g["origins"]).items()))
            rows.append([plan, key, g["n"], origins, _readings(g["real_read"], g["real_p"]),
                         _readings(g["synthetic_read"], g["synthetic_p"]), g["flag_observer_real"]])
    return table(["plan", "intended", "clips", "origin and generator used", "real-capture: read (median p)",
                  "synthetic: read (median p)", "observer flags (real)"], rows)


def real_observer_thresholds(r: dict) -> list[str]:
    """The quality gate's realism bounds and how many held-out real takes break them."""
    rows = [[k, f"{v:g}" + (" (not applied)" if k in r["not_applied"] else "")] for k, v in r["thresholds"].items()]
    return table(["realism bound (`generation/quality/realism_ranges.json`)", "value"],
                 [["rule", r["ranges_rule"]], *rows,
                  ["held-out real takes outside the bounds", f"{r['ranges_test_flagged']:.0%}"]])


def _stat(s: dict) -> str:
    """Median (5th-95th percentile), or (min-max) under 5 values."""
    if not s or not s.get("n"):
        return "-"
    lo, hi = ("min", "max") if s["n"] < 5 else ("p5", "p95")
    return f"{s['median']:.3g} ({s[lo]:.3g}-{s[hi]:.3g})"


def real_observer_realism(r: dict) -> list[str]:
    """Realism measures per group; plan groups add their realism flags and the bounds broken."""
    groups = r["realism"]
    measures = [m for m in next(iter(groups.values())) if m not in ("realism_flagged", "bounds_broken")]
    rows = []
    for name, row in groups.items():
        flags = row.get("realism_flagged", "")
        if row.get("bounds_broken"):
            flags = f"{flags} (" + ", ".join(f"{k} {v}" for k, v in sorted(row["bounds_broken"].items())) + ")"
        rows.append([name, *(_stat(row[m]) for m in measures), flags])
    return table(["group", *measures, "realism flags (bounds broken: clips)"], rows)


TABLES: dict[str, tuple[str, Renderer]] = {
    "real_observer.run": ("date", real_observer_run),
    "real_observer.emotion_accuracy": ("held_out", real_observer_emotion_accuracy),
    "real_observer.confusion_takes": ("held_out", real_observer_confusion_takes),
    "real_observer.confusion_windows": ("held_out", real_observer_confusion_windows),
    "real_observer.themes": ("held_out", real_observer_themes),
    "real_observer.confusion_loto": ("leave_one_take_out", real_observer_confusion_loto),
    "real_observer.plan_themes": ("themes_in_plans", real_observer_plan_themes),
    "real_observer.plans": ("plans", real_observer_plans),
    "real_observer.thresholds": ("thresholds", real_observer_thresholds),
    "real_observer.realism": ("realism", real_observer_realism),
}
"""Table name -> (the JSON key it needs, renderer)."""
