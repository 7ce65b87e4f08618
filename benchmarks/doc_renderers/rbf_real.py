"""Tables of the RBF styliser on real capture (benchmarks/bench_rbf_real.py; docs/benchmarks/rbf.md)."""
from __future__ import annotations

from benchmarks.doc_renderers.common import EMOTIONS, Renderer, _opt, _run, _yes, table

RBF_REAL_CHECKED = ("speed_m_s", "cadence_steps_min", "stance_knee_deg", "pelvis_bounce_cm")


def _rbf_weights(row: dict) -> list[str]:
    """The styling weights of an observers row, as its keys spell them ('0.7', '1.0')."""
    return [k.removeprefix("expert_") for k in row if k.startswith("expert_") and not k.endswith("_emotion_p")]


def rbf_real_run(r: dict) -> list[str]:
    return _run(r)


def rbf_real_neutral_cycle(r: dict) -> list[str]:
    """The averaged neutral cycle: its sources, alignment, spread and size."""
    md = r["neutral"]["metadata"]
    per_ds: dict[str, list[int]] = {}
    for s in md["captured_sources"]:
        if s["cycles"]:
            d = per_ds.setdefault(s["dataset"], [0, 0])
            d[0] += 1
            d[1] += s["cycles"]
    return table(["averaged neutral cycle", "value"], [
        ["steady two-step cycles", f"{md['n_cycles']} from {md['n_takes']} train-split normal walks"],
        ["per dataset", ", ".join(f"{ds}: {v[1]} cycles from {v[0]} takes" for ds, v in sorted(per_ds.items()))],
        ["time warping", md["time_warping"]],
        ["cycle spread (mean per-frame standard deviation, walker heights) after contact warping / after DTW",
         f"{md['dtw_spread']['before']:.4f} / {md['dtw_spread']['after']:.4f}"],
        ["cycle", f"{md['cycle_duration_s']:.3f} s"], ["stride", f"{md['stride_m'][2]:.3f} m"],
        ["IK re-fit error (max)", f"{md['ik_error_max_m'] * 1000:.1f} mm"]])


def rbf_real_neutral_checks(r: dict) -> list[str]:
    """The averaged and the procedural base walked, against the range of the real normal walks."""
    n = r["neutral"]
    rows = []
    for name, row in n["bases"].items():
        rows.append([name, *(f"{row[k]:.2f}{'' if row['inside'][k] else ' **(outside)**'}" for k in RBF_REAL_CHECKED),
                     "/".join(f"{row['observer'][e]:.2f}" for e in EMOTIONS)])
    rr = n["real_ranges"]
    rows.append([f"real normal walks (range of {n['real_takes']})",
                 *(f"{rr[k][0]:.2f}-{rr[k][1]:.2f}" for k in RBF_REAL_CHECKED),
                 "test takes: " + "/".join(f"{n['real_test_normal_read'][e]:.2f}" for e in EMOTIONS)])
    return table(["base", "speed (m/s)", "cadence (steps/min)", "stance knee (deg)", "pelvis bounce (cm)",
                  "real observer (happy/sad/angry/neutral)"], rows)


def rbf_real_accuracy(r: dict) -> list[str]:
    return table(["classifier", "test takes", "accuracy"],
                 [[k, v["takes"], _opt(v["accuracy"])] for k, v in r["accuracy"].items()])


def rbf_real_compare(r: dict) -> list[str]:
    return table(["theme", "rows in common", "shared DOFs", "sign agree", "median ratio", "data's first five rows"],
                 [[theme, f"{c['used_overlap']} of {len(c['expert_features'])}", c["shared_dofs"],
                   _opt(c["sign_agreement"]), _opt(c["median_ratio"]),
                   ", ".join(f"{p} {a}" for p, a in c["data_features"][:5])] for theme, c in r["compare"].items()])


def rbf_real_top_dofs(r: dict, per_theme: int = 6) -> list[str]:
    """The first ``per_theme`` DOFs of each theme (largest amplitude of either set)."""
    rows = []
    for theme, c in r["compare"].items():
        for d in c["rows"][:per_theme]:
            sa = "-" if d["sign_agree"] is None else _yes(d["sign_agree"])
            rows.append([theme, f"{d['joint']} {d['axis']}", _opt(d["expert_peak"], "{:+.3f}"),
                         _opt(d["data_peak"], "{:+.3f}"), sa, _opt(d["peak_shift"]), _opt(d["ratio"]),
                         _opt(d["corr"])])
    return table(["theme", "DOF", "expert peak", "data peak", "sign agree", "peak shift (cycle)", "ratio", "corr"],
                 rows)


def rbf_real_observers(r: dict) -> list[str]:
    """p(intended theme) per feature set and weight; 'observer prefers' data when data win at every weight."""
    rows, weights = [], []
    for theme, row in r["observers"].items():
        weights = _rbf_weights(row)
        data_wins = [row[f"data_{w}"] > row[f"expert_{w}"] for w in weights]
        better = "data" if all(data_wins) else "expert" if not any(data_wins) else "mixed"
        rows.append([f"{theme} ({row['pair']})", f"{row['neutral']:.2f}",
                     *(f"{row[f'{f}_{w}']:.2f}" for w in weights for f in ("expert", "data")),
                     f"{row['real_test']:.2f} ({row['real_test_takes']})", better])
    return table(["theme (pair)", "neutral", *(f"{f} {w}" for w in weights for f in ("expert", "data")),
                  "real test takes", "observer prefers"], rows)


def rbf_real_ablation(r: dict) -> list[str]:
    return table(["theme", "p (all ten)", "Table III feature (rank)", "why disputed", "p without it", "sides with"],
                 [[theme, f"{ab['p_full']:.2f}", f"{d['feature']} ({d['rank']})", d["why"], f"{d['p_without']:.2f}",
                   d["sides_with"]] for theme, ab in r["ablation"].items() for d in ab["rows"]])


def rbf_real_ablation_totals(r: dict) -> list[str]:
    """How many disputed expert features the observers side on, over every theme."""
    sides = [d["sides_with"] for ab in r["ablation"].values() for d in ab["rows"]]
    return table(["sides with", "data", "expert", "neither", "all"],
                 [["disputed expert features", *(sides.count(s) for s in ("data", "expert", "neither")), len(sides)]])


def rbf_real_emotion_observer(r: dict) -> list[str]:
    """The four-emotion observer's probability of the theme's emotion (themes that are emotions)."""
    rows, weights = [], []
    for theme, row in r["observers"].items():
        if "real_test_emotion_p" not in row:
            continue
        weights = _rbf_weights(row)
        rows.append([theme, *(f"{row[f'{f}_{w}_emotion_p']:.2f}" for w in weights for f in ("expert", "data")),
                     f"{row['real_test_emotion_p']:.2f}"])
    return table(["theme", *(f"{f} {w}" for w in weights for f in ("expert", "data")), "real dataset-1 test take"],
                 rows)


TABLES: dict[str, tuple[str, Renderer]] = {
    "rbf_real.run": ("date", rbf_real_run),
    "rbf_real.neutral_cycle": ("neutral", rbf_real_neutral_cycle),
    "rbf_real.neutral_checks": ("neutral", rbf_real_neutral_checks),
    "rbf_real.accuracy": ("accuracy", rbf_real_accuracy),
    "rbf_real.compare": ("compare", rbf_real_compare),
    "rbf_real.top_dofs": ("compare", rbf_real_top_dofs),
    "rbf_real.observers": ("observers", rbf_real_observers),
    "rbf_real.ablation": ("ablation", rbf_real_ablation),
    "rbf_real.ablation_totals": ("ablation", rbf_real_ablation_totals),
    "rbf_real.emotion_observer": ("observers", rbf_real_emotion_observer),
}
"""Table name -> (the JSON key it needs, renderer)."""
