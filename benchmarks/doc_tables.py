"""Markdown tables of the benchmarks' JSON results, and their place in the docs.

Benchmarks write their figures as JSON (``docs/benchmarks/<area>.json``); the narrative lives in
``docs/benchmarks/<area>.md`` (``FILES`` names the areas whose JSON and doc are named otherwise, e.g. rbf_real.json
-> rbf.md). A doc marks where a rendered table goes::

    <!-- table: gait.prediction -->
    ...replaced by the table...
    <!-- /table -->

and this script replaces each marked block with the table rendered from the JSON (blocks whose data the JSON lacks
are left as they are)::

    python benchmarks/doc_tables.py gait            # docs/benchmarks/gait.json -> the marked tables of gait.md
    python benchmarks/doc_tables.py gesture         # docs/benchmarks/gesture.json -> gesture.md
    python benchmarks/doc_tables.py rbf_real        # docs/benchmarks/rbf_real.json -> rbf.md
    python benchmarks/doc_tables.py gait_real       # docs/benchmarks/gait_real.json -> gait.md
    python benchmarks/doc_tables.py gait --print    # print every table of the JSON instead
"""
from __future__ import annotations

import argparse
import json
import re
import statistics
import sys
from collections.abc import Callable
from pathlib import Path

DOCS = Path(__file__).resolve().parent.parent / "docs" / "benchmarks"
EMOTIONS = ("happy", "sad", "angry", "neutral")
BLOCK_RE = re.compile(r"(<!-- table: (?P<name>[\w.]+) -->\n)(?P<body>.*?)(<!-- /table -->)", re.S)


def table(header: list[str], rows: list[list]) -> list[str]:
    """Markdown table lines."""
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header),
            *("| " + " | ".join(str(c) for c in row) + " |" for row in rows)]


# ---- gait (benchmarks/bench_gait.py) ----------------------------------------------------------------------------
def gait_prediction(r: dict) -> list[str]:
    return table(["method", "pose err / body diag", "pose err cm", "first 10 / last 10 steps cm", "rot err deg (rad)"],
                 [[k, f"{v['pose_error_body_diag']:.3f}", f"{v['pose_error_cm']:.1f}",
                   f"{v['pose_error_first10_cm']:.1f} / {v['pose_error_last10_cm']:.1f}",
                   f"{v['rotation_error_deg']:.1f} ({v['rotation_error_rad']:.3f})"]
                  for k, v in r["prediction"].items()])


def gait_expressiveness(r: dict) -> list[str]:
    rows = []
    for k, v in r["expressiveness"].items():
        pt = v["transition_p_target"]
        rows.append([k, f"{v['own_emotion']['overall']:.2f}",
                     f"{v['other_mixture']['overall']:.2f} / {v['other_mixture_last_third']['overall']:.2f}",
                     f"{v['transition_start']['overall']:.2f} / {v['transition_end']['overall']:.2f}",
                     f"{pt['first_50_steps']:.2f} / {pt['last_50_steps']:.2f} "
                     f"({pt['constant_seed_emotion_last_50']:.2f})"])
    return table(["model", "own emotion", "other mixture (whole / last third)", "transition start / end",
                  "P(target) transition first / last 50 steps (no transition)"], rows)


def _per_class(t: dict) -> list[str]:
    return [f"{t[e]:.2f}" for e in EMOTIONS]


def gait_own_emotion(r: dict) -> list[str]:
    """Own-emotion recognition per class: test walks, the second held-out corpus, procedural seeds."""
    rows = []
    for model, v in r["expressiveness"].items():
        rows.append([model, "test walks", v["own_emotion"].get("n", ""), *_per_class(v["own_emotion"]),
                     f"{v['own_emotion']['overall']:.2f}"])
        untied = v["own_emotion_untied"]
        rows.append([model, "test walks, one dominant label", untied.get("n", ""), *_per_class(untied),
                     f"{untied['overall']:.2f}"])
    for model, v in r.get("own_emotion_heldout_corpus", {}).items():
        for part in ("all", "untied"):
            t = v[part]
            rows.append([model, f"second held-out corpus, {part}", t["n"], *_per_class(t), f"{t['overall']:.2f}"])
    for model, v in r.get("expressiveness_procedural_seeds", {}).items():
        for kind, t in v.items():
            rows.append([model, f"procedural seeds, {kind}", t.get("n", ""), *_per_class(t), f"{t['overall']:.2f}"])
    return table(["model", "seeds", "n", *EMOTIONS, "all"], rows)


def gait_trajectory(r: dict) -> list[str]:
    return table(["model", "mean m", "p95 m", "max m", "at end m", "facing vs travel deg"],
                 [[k, f"{v['mean_m']:.3f}", f"{v['p95_m']:.3f}", f"{v['max_m']:.3f}", f"{v['end_mean_m']:.3f}",
                   f"{v['facing_vs_travel_deg']:.1f}"] for k, v in r["trajectory"].items()])


def gait_long_horizon(r: dict) -> list[str]:
    return table(["steps", "root speed m/s", "pose variance cm^2", "path distance m", "root height m"],
                 [[w["steps"], f"{w['root_speed_m_s']:.2f}", f"{w['pose_variance_cm2']:.0f}",
                   f"{w['path_distance_m']:.3f}", f"{w['root_height_m']:.3f}"] for w in r["long_horizon"]["windows"]])


def gait_speed(r: dict) -> list[str]:
    keys = sorted({k for v in r["speed"].values() for k in v})
    return table(["agents", *keys], [[name, *(f"{v[k]:.2f}" if isinstance(v.get(k), float) else v.get(k, "")
                                             for k in keys)] for name, v in r["speed"].items()])


# ---- gesture (benchmarks/bench_gesture.py) ----------------------------------------------------------------------
def _by_arousal(r: dict, emotions) -> list[str]:
    """``emotions`` from the lowest to the highest arousal (``r["emotion_vad"]``; given order where it is absent)."""
    vad = r.get("emotion_vad", {})
    return sorted(emotions, key=lambda e: vad.get(e, {}).get("arousal", 0.0))


def _ratio(v: dict, m: str) -> float:
    return v[f"gen_{m}"] / v[f"corpus_{m}"]


def gesture_run(r: dict) -> list[str]:
    """Machine, date, commit, command and the evaluated weights."""
    m, sh, sp = r["meta"], r.get("shipped", {}), r.get("split", {})
    commit = (m.get("commit") or "not recorded")[:12] + (" + uncommitted changes" if m.get("uncommitted_changes")
                                                          else "")
    rows = [["machine", m["machine"]], ["date", m["date"]], ["commit", commit], ["command", f"`{m['command']}`"]]
    if m.get("seconds") is not None:
        rows.append(["duration", f"{m['seconds'] / 60:.1f} min"])
    for label, path in (m.get("comparison_weights") or {}).items():
        rows.append([f"weights '{label}'", f"`{path}`"])
    if sp:
        rows.append(["examples train / validation / test", f"{sp['train']} / {sp['val']} / {sp['test']}"])
    if sh:
        rows.append(["shipped weights", f"{sh['parameters']:,} parameters, {sh['epochs']} epochs in "
                     f"{sh['seconds'] / 60:.1f} min, the weights after epoch {sh['best_epoch'] + 1} kept"])
    if m.get("transcribed_from"):
        rows.append(["transcribed from", m["transcribed_from"]])
    return table(["run", "value"], rows)


def gesture_pose(r: dict) -> list[str]:
    """Seed 003 Table 1 layout, and the procedural ground truth's upper-body acceleration."""
    rows = [[name, f"{v['pose_error']:.4f}", f"{v['pose_error_upper']:.4f}", f"{v['rotation_error_deg']:.2f}",
             f"{v['acceleration']:.3f}", f"{v['speed_log_ratio']:.3f}"] for name, v in r["pose_error_table"].items()]
    if "gt_acceleration" in r:
        rows.append(["ground truth (procedural)", "-", "-", "-", f"{r['gt_acceleration']:.3f}", "-"])
    return table(["Method", "Mean pose error", "Upper body (8 joints)", "Rotation error (deg)",
                  "Upper-body accel. (m/s^2)", "Speed gap"], rows)


def gesture_liveliness(r: dict) -> list[str]:
    """Per emotion: corpus and generated mean / peak wrist speed (ratio) of the held-out examples, per network."""
    live = r["liveliness"]
    last = live[list(live)[-1]]["per_emotion"]
    rows = []
    for emo in _by_arousal(r, last):
        c = last[emo]
        row = [emo, f"{r['emotion_vad'][emo]['arousal']:.3f}", c["n"], f"{c['corpus_mean']:.3f}",
               f"{c['corpus_peak']:.3f}"]
        for v in (live[k]["per_emotion"][emo] for k in live):
            row += [f"{v['gen_mean']:.3f} ({v['gen_mean'] / c['corpus_mean']:.2f})",
                    f"{v['gen_peak']:.3f} ({v['gen_peak'] / c['corpus_peak']:.2f})"]
        rows.append(row)
    return table(["Emotion", "arousal", "n", "corpus mean", "corpus peak",
                  *(f"{k}: {m} (ratio)" for k in live for m in ("mean", "peak"))], rows)


def gesture_liveliness_summary(r: dict) -> list[str]:
    """r(peak wrist speed, arousal) and the largest ratio gap per network."""
    live = r["liveliness"]
    last = live[list(live)[-1]]
    procedural = r.get("expressiveness", {}).get("r_speed_arousal_procedural")
    return table(["Measure", "corpus", *live], [
        ["r(peak wrist speed, arousal), own attributes", f"{last['r_corpus']:.3f}",
         *(f"{v['r_gen']:.3f}" for v in live.values())],
        [f"r(peak wrist speed, arousal), each test sentence x 11 emotions ({last['n_all_emotions']})",
         "-" if procedural is None else f"{procedural:.3f} (held-out, own)",
         *(f"{v['r_all_emotions']:.3f}" for v in live.values())],
        ["largest per-emotion ratio gap (mean or peak)", "0", *(f"{v['worst_ratio_gap']:.2f}" for v in live.values())]])


def gesture_all_emotions(r: dict) -> list[str]:
    """Per emotion: generated / corpus wrist speed over every held-out example x 11 emotions, per network."""
    live = r["liveliness"]
    last = live[list(live)[-1]]["all_emotions"]["per_emotion"]
    rows = [[emo, f"{last[emo]['corpus_mean']:.3f}", f"{last[emo]['corpus_peak']:.3f}",
             *(f"{_ratio(v, 'mean'):.2f} / {_ratio(v, 'peak'):.2f}"
               for v in (live[k]["all_emotions"]["per_emotion"][emo] for k in live))]
            for emo in _by_arousal(r, last)]
    rows.append(["cells in band (of 22)", "", "", *(v["all_emotions"]["cells_in_band"] for v in live.values())])
    rows.append(["largest ratio gap", "", "", *(f"{v['all_emotions']['worst_ratio_gap']:.2f}" for v in live.values())])
    return table(["Emotion", "corpus mean", "corpus peak", *(f"{k}: mean / peak ratio" for k in live)], rows)


def gesture_arousal_sheet(r: dict) -> list[str]:
    """Wrist speeds of the clips on the arousal contact sheet."""
    return table(["Emotion", "arousal", "wrist speed mean (m/s)", "wrist speed peak (m/s)"],
                 [[t["emotion"], f"{t['arousal']:.3f}", f"{t['mean']:.2f}", f"{t['peak']:.2f}"]
                  for t in r["arousal_sheet"]])


def gesture_expressiveness(r: dict) -> list[str]:
    """Correlations and synthetic-observer accuracy, generated vs the procedural ground truth."""
    e = r["expressiveness"]
    return table(["Measure", "Generated", "Procedural ground truth (held-out)"], [
        ["Pearson r(speed, arousal)", f"{e['r_speed_arousal']:.3f} (p = {e['p_speed_arousal']:.2g})",
         f"{e['r_speed_arousal_procedural']:.3f}"],
        ["Pearson r(expansion, dominance)", f"{e['r_expansion_dominance']:.3f} (p = {e['p_expansion_dominance']:.2g})",
         f"{e['r_expansion_dominance_procedural']:.3f}"],
        *([f"Synthetic observer, high vs low {k} (balanced accuracy)", f"{e[f'observer_{k}_generated']:.3f}",
           f"{e[f'observer_{k}_procedural']:.3f}"] for k in ("arousal", "dominance"))])


def gesture_expressiveness_per_emotion(r: dict) -> list[str]:
    per, vad = r["expressiveness"]["per_emotion"], r["emotion_vad"]
    return table(["Emotion", "arousal", "dominance", "mean peak wrist speed (m/s)", "mean expansion"],
                 [[emo, f"{vad[emo]['arousal']:.3f}", f"{vad[emo]['dominance']:.3f}", f"{per[emo]['speed']:.3f}",
                   f"{per[emo]['expansion']:.3f}"] for emo in _by_arousal(r, per)])


def gesture_speed(r: dict) -> list[str]:
    """Generation speed of ``generate_gesture`` (30 fps output, one thread)."""
    s = r["speed"]
    return table(["sentences", "passes", "output frames per s (median)", "range over passes", "ms per output frame",
                  "network steps per s (10 fps)"],
                 [[s["sentences"], s["repeats"], f"{s['output_fps']:.0f}",
                   f"{s['output_fps_min']:.0f}-{s['output_fps_max']:.0f}", f"{s['ms_per_output_frame']:.2f}",
                   f"{s['network_steps_per_s']:.0f}"]])


def gesture_training_speed(r: dict) -> list[str]:
    return table(["Training preset", "parameters", "s per batch of 16 (CPU, 1 thread)", "batches per epoch",
                  "s per epoch (extrapolated)", "epochs"],
                 [[t["preset"], f"{t['parameters']:,}",
                   f"{t['seconds_per_batch']:.2f} (mean of {t['timed_batches']} timed batches)",
                   t["batches_per_epoch"], f"{t['seconds_per_epoch']:.0f}", t["epochs"]] for t in r["epoch_timing"]])


# ---- runs of any area: the keys at the top level of its JSON ----------------------------------------------------
def _run(r: dict, *extra: tuple[str, str]) -> list[str]:
    """Machine, date, commit, command and duration where recorded, then ``extra`` (label, value) rows and the
    source of transcribed figures (``r["meta"]["transcribed_from"]``)."""
    rows = [[key, r[key]] for key in ("machine", "date") if r.get(key)]
    if r.get("commit"):
        rows.append(["commit", r["commit"].removeprefix("commit ")])
    if r.get("command"):
        rows.append(["command", f"`{r['command']}`"])
    if r.get("seconds") is not None:
        rows.append(["duration", f"{r['seconds']:.0f} s"])
    rows += [list(row) for row in extra]
    if r.get("meta", {}).get("transcribed_from"):
        rows.append(["transcribed from", r["meta"]["transcribed_from"]])
    return table(["run", "value"], rows)


def _opt(v, fmt: str = "{:.2f}") -> str:
    return "-" if v is None else fmt.format(v)


# ---- RBF styliser, synthetic measures (benchmarks/bench_rbf_features.py; docs/benchmarks/rbf.md) ----------------
def _w(row: dict) -> str:
    return f"{row['weight']:+.1f}"


def _sign(s: int) -> str:
    return "+" if s > 0 else "-"


def _yes(holds: bool) -> str:
    return "yes" if holds else "**no**"


def rbf_features_run(r: dict) -> list[str]:
    return _run(r)


def rbf_features_neutral_base(r: dict) -> list[str]:
    """The neutral cycle the themes edit: where it comes from, its size and sources."""
    base = r["neutral_base"]
    sources = base.get("sources", base.get("captured_sources", []))
    rejected = sum(u.get("rejected_cycles", 0) for u in sources)
    return table(["neutral base", "value"], [
        ["function", f"`{r['base_function']}`"], ["cycles averaged", base["n_cycles"]],
        ["cycles rejected as glitches", rejected], ["cycle", f"{base['cycle_duration_s']:.2f} s"],
        ["stride", f"{base['stride_m'][2]:.2f} m"], ["synthetic", base["synthetic"]],
        ["sources used (cycles)", "; ".join(f"{u['name']} ({u['cycles']})" for u in sources if u["cycles"])]])


def rbf_features_summary(r: dict) -> list[str]:
    """Checks that hold, bone-length and floor extremes, speed (``r["summary"]``, from every theme and weight)."""
    s, t = r["summary"], r["timing"]
    verb = "loading" if "load_cycle" in r["base_function"] else "building"
    return table(["measure", "value"], [
        ["expected directions that hold, 18 gait affective features", f"{s['checks_held']} of {s['checks']}"],
        ["expected directions that hold, direct geometric measures", f"{s['measures_held']} of {s['measures']}"],
        ["not holding", ", ".join(s["failed"]) or "none"],
        ["largest bone-length deviation of the edited positions Y", f"{s['bone_error_before_max_m'] * 1000:.0f} mm"],
        ["largest bone-length deviation after the fit", f"{s['bone_error_after_max_m'] * 1000:.1e} mm"],
        ["lowest foot joint relative to the neutral floor: our fit / `generation.core.ik.fit_positions_to_skeleton` "
         "(direction-only)",
         f"{s['lowest_foot_m'] * 1000:+.1f} mm / {s['lowest_foot_direction_only_m'] * 1000:+.1f} mm"],
        ["stylising one 4-cycle clip at 30 fps", f"{t['stylise_clip_s'] * 1000:.0f} ms ({t['clip_frames']} frames)"],
        [f"{verb} the neutral base", f"{t['neutral_base_s']:.2f} s"]])


def rbf_features_feature_key(r: dict) -> list[str]:
    """One line: f<i> = name of each gait affective feature."""
    return ["Feature key: " + "; ".join(f"f{i} = {n}" for i, n in enumerate(r["feature_names"]))]


def rbf_features_mean_change(r: dict) -> list[str]:
    return table(["theme", "w", *(f"f{i}" for i in range(len(r["feature_names"])))],
                 [[row["theme"], _w(row), *(f"{v:+.3f}" for v in row["mean_change"])] for row in r["rows"]])


def rbf_features_feature_checks(r: dict) -> list[str]:
    return table(["theme", "w", "feature", "aggregate", "expected", "change", "holds", "why"],
                 [[row["theme"], _w(row), c["feature"], c["aggregate"], _sign(c["expected_sign"]),
                   f"{c['change']:+.4f}", _yes(c["holds"]),
                   c["reason"] if row["weight"] > 0 else "inverse of: " + c["reason"]]
                  for row in r["rows"] for c in row["checks"]])


def rbf_features_measure_checks(r: dict) -> list[str]:
    return table(["theme", "w", "measure", "expected", "change (mm)", "holds"],
                 [[row["theme"], _w(row), c["measure"], _sign(c["expected_sign"]), f"{c['change_m'] * 1000:+.1f}",
                   _yes(c["holds"])] for row in r["rows"] for c in row["measures"]])


def rbf_features_bones_floor(r: dict) -> list[str]:
    return table(["theme", "w", "before", "after (ours)", "after (ik.fit_positions_to_skeleton)", "lowest foot ours",
                  "lowest foot direction-only", "max lift by floor clamp"],
                 [[row["theme"], _w(row), f"{row['bone_error_before_m'] * 1000:.1f}",
                   f"{row['bone_error_after_m'] * 1000:.1e}", f"{row['ik_direction_only_after_m'] * 1000:.1e}",
                   f"{row['lowest_foot_m'] * 1000:+.1f}", f"{row['lowest_foot_direction_only_m'] * 1000:+.1f}",
                   f"{row['ground_lift_m'] * 1000:.1f}"] for row in r["rows"]])


def rbf_features_scaling(r: dict) -> list[str]:
    """Mean joint displacement (cm) per theme on the n x w grid of ``r["scaling_axes"]``."""
    axes = r["scaling_axes"]
    return table(["theme", "n", *(f"w {w}" for w in axes["w"])],
                 [[theme, n, *(f"{v:.2f}" for v in row)] for theme, grid in r["scaling"].items()
                  for n, row in zip(axes["n"], grid)])


# ---- RBF styliser on real capture (benchmarks/bench_rbf_real.py; docs/benchmarks/rbf.md) ------------------------
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


# ---- real-capture observer and realism (benchmarks/bench_real_observer.py; docs/benchmarks/mocap.md) ------------
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


# ---- gait network on real capture (benchmarks/bench_gait_real.py; docs/benchmarks/gait.md) ----------------------
REALISM_LABELS = {"skate_cm_s": "foot skate cm/s", "skate_ratio": "skate ratio", "toe_skim": "toe skim",
                  "stance_knee_deg": "stance knee deg", "pelvis_bounce_cm": "pelvis bounce cm", "speed_cv": "speed CV"}
REALISM_DIGITS = {"skate_cm_s": 1, "stance_knee_deg": 1, "pelvis_bounce_cm": 1}
"""Column label and decimals (default 2) of each realism measure (generation.quality.realism.MEASURES)."""
GAIT_REAL_SUBSETS = {"all": "all held-out forward locomotion", "emotion": "held-out emotion walks"}
"""Table suffix -> the prediction subset of bench_gait_real.py."""


def _sha(record: dict | None) -> str:
    """``path (sha256 <12 hex>)`` of a {path, sha256} record."""
    if not record:
        return "-"
    sha = record.get("sha256")
    return f"`{record['path']}`" + (f" (sha256 {sha[:12]}...)" if sha else "")


def gait_real_run(r: dict) -> list[str]:
    return _run(r, ("corpus", _sha(r.get("corpus"))),
                *((f"weights '{name}'", _sha(w)) for name, w in r.get("weights", {}).items()))


def _gait_real_prediction(r: dict, subset: str) -> list[str]:
    """One prediction subset: a line with its windows, takes and steps, then the error of each method."""
    t = r["prediction"][subset]
    return [f"{t['n']} windows of {t['takes']} test takes; {r['prefix']} network steps given, {r['horizon']} "
            "predicted:", "",
            *table(["method", "pose error / body diagonal", "step 1", "steps 2-5", "later steps", "cm",
                    "rotation deg"],
                   [[name, *(_opt(e[k], "{:.3f}") for k in ("pose_error_body_diag", "pose_error_body_diag_step1",
                                                            "pose_error_body_diag_steps2_5",
                                                            "pose_error_body_diag_later")),
                     _opt(e["pose_error_cm"], "{:.1f}"), _opt(e["rotation_error_deg"], "{:.1f}")]
                    for name, e in t["methods"].items()])]


def gait_real_prediction_all(r: dict) -> list[str]:
    return _gait_real_prediction(r, GAIT_REAL_SUBSETS["all"])


def gait_real_prediction_emotion(r: dict) -> list[str]:
    return _gait_real_prediction(r, GAIT_REAL_SUBSETS["emotion"])


def _n_range(ns) -> str:
    ns = [n for n in ns if n is not None]
    if not ns:
        return "-"
    return str(min(ns)) if min(ns) == max(ns) else f"{min(ns)}-{max(ns)}"


def gait_real_emotion(r: dict) -> list[str]:
    """Per set of generated walks (weights, seeds), per asked emotion: the share read as asked / read as neutral
    (neutral: read as asked only)."""
    rows = []
    for name, rec in r["recognition"].items():
        per = rec["per_class"]
        cells = [_opt(per[e]["own"]) if e == "neutral" else f"{_opt(per[e]['own'])} / {_opt(per[e]['as_neutral'])}"
                 for e in EMOTIONS]
        rows.append([name, _n_range(per[e].get("n") for e in EMOTIONS), *cells])
    return table(["walks", "n per emotion", *(f"{e}: as asked / as neutral" if e != "neutral" else e
                                              for e in EMOTIONS)], rows)


def _measure(m: str, v) -> str:
    return _opt(v, f"{{:.{REALISM_DIGITS.get(m, 2)}f}}")


def gait_real_realism(r: dict) -> list[str]:
    """Per emotion: the real takes' min-max of each realism measure, then per set of generated walks the median and
    (in brackets) the share of walks inside the quality gate's widened range."""
    real = r["real_realism"]
    measures = [m for m in next(iter(real.values())) if m != "takes"]
    rows = []
    for e in EMOTIONS:
        if e in real:
            rows.append([e, "real takes (min-max)", _opt(real[e].get("takes"), "{}"),
                         *("-" if not real[e].get(m) else f"{_measure(m, real[e][m]['min'])}-"
                           f"{_measure(m, real[e][m]['max'])}" for m in measures)])
        for name, per in r["realism"].items():
            if e not in per:
                continue
            v, cells = per[e], []
            for m in measures:
                g, inside = v["measures"].get(m), v["inside_share"].get(m)
                cells.append(_measure(m, g and g["median"]) + ("" if inside is None else f" ({inside:.2f})"))
            rows.append([e, name, _opt(v.get("n"), "{}"), *cells])
    return table(["emotion", "walks", "n", *(REALISM_LABELS.get(m, m) for m in measures)], rows)


def gait_real_plan_reading(r: dict) -> list[str]:
    """The real takes (read whole), then per weights the seed000 plan's clips read for what each asks (transitions
    by their first and last window): per asked emotion (as asked / as neutral) and per kind of clip (share read as
    asked)."""
    rows = []
    for name, rec in {**r.get("real_take_reading", {}), **r["plan_reading"]}.items():
        per, kinds = rec["per_class"], rec.get("by_kind", {})
        rows.append([name, *(_opt(per[e]["own"]) if e == "neutral" else
                             f"{_opt(per[e]['own'])} / {_opt(per[e]['as_neutral'])} (n {per[e]['n']})"
                             for e in EMOTIONS),
                     *(f"{_opt(kinds[k]['read_as_asked'])} (n {kinds[k]['n']})" if k in kinds else "-"
                       for k in ("pure", "mixture", "transition"))])
    return table(["walks", *(f"{e}: as asked / as neutral" if e != "neutral" else e for e in EMOTIONS),
                  "pure clips", "mixtures", "transition ends"], rows)


def gait_real_plan_parts(r: dict) -> list[str]:
    """Each part of the plan's clips read by the real-capture observer (the first weights of ``plan_reading``)."""
    name, rec = next(iter(r["plan_reading"].items()))
    rows = [[p["clip"], p["part"], p["asked"] or "tie: " + "/".join(p["components"]), p["read"],
             " ".join(f"{v:.2f}" for v in p["p"])] for p in rec["parts"]]
    return table(["clip", "part", "asked", f"read ({name})", "p " + " ".join(EMOTIONS)], rows)


# ---- upsampling the networks' output (benchmarks/bench_upsampling.py; docs/benchmarks/gait.md) ------------------
UPSAMPLING = ("slerp", "spline")


def upsampling_run(r: dict) -> list[str]:
    ms = r.get("call_ms")
    extra = [("one call, 10 s walk at 7.5 Hz to 30 fps", " / ".join(f"{m} {ms[m]:.1f} ms" for m in UPSAMPLING))
             ] if ms else []
    return _run(r, *extra)


def upsampling_gestures(r: dict) -> list[str]:
    """Per gesture emotion: jerk and peak hand speed, slerp -> spline."""
    rows = [[emotion, f"{v['slerp']['jerk']:.0f} -> {v['spline']['jerk']:.0f}",
             f"{v['slerp']['peak_hand_speed']:.2f} -> {v['spline']['peak_hand_speed']:.2f}"]
            for emotion, v in r["gestures"].items()]
    return table(["emotion", "jerk m/s^3, slerp -> spline", "peak hand speed m/s"], rows)


def upsampling_real(r: dict) -> list[str]:
    """Per real take: its capture's jerk, then per method the position error and jerk after the round trip."""
    rows = []
    for emotion, row in r["real_round_trip"].items():
        rows.append([emotion, f"{row['take']} ({row['seconds']:.1f} s)", f"{row['capture']['jerk']:.0f}",
                     *(f"{row[m]['position_error_cm']:.2f}" for m in UPSAMPLING),
                     *(f"{row[m]['jerk']:.0f}" for m in UPSAMPLING)])
    return table(["emotion", "real take", "jerk of the capture", *(f"error cm, {m}" for m in UPSAMPLING),
                  *(f"jerk, {m}" for m in UPSAMPLING)], rows)


def upsampling_generated(r: dict) -> list[str]:
    """Per emotion and path: jerk, toe skim and skate of the generated walk, slerp -> spline."""
    rows = []
    for emotion, per_path in r["generated"].items():
        for path, row in per_path.items():
            rows.append([emotion, path, *(f"{_opt(row['slerp'][k], fmt)} -> {_opt(row['spline'][k], fmt)}"
                                          for k, fmt in (("jerk", "{:.0f}"), ("toe_skim", "{:.2f}"),
                                                         ("skate_cm_s", "{:.0f}")))])
    return table(["emotion", "path", "jerk m/s^3, slerp -> spline", "toe skim", "skate cm/s"], rows)


TABLES: dict[str, dict[str, tuple[str, Callable[[dict], list[str]]]]] = {
    "gait": {"gait.prediction": ("prediction", gait_prediction),
             "gait.expressiveness": ("expressiveness", gait_expressiveness),
             "gait.own_emotion": ("expressiveness", gait_own_emotion),
             "gait.trajectory": ("trajectory", gait_trajectory),
             "gait.long_horizon": ("long_horizon", gait_long_horizon),
             "gait.speed": ("speed", gait_speed)},
    "gesture": {"gesture.run": ("meta", gesture_run),
                "gesture.pose": ("pose_error_table", gesture_pose),
                "gesture.liveliness": ("liveliness", gesture_liveliness),
                "gesture.liveliness_summary": ("liveliness", gesture_liveliness_summary),
                "gesture.all_emotions": ("liveliness", gesture_all_emotions),
                "gesture.arousal_sheet": ("arousal_sheet", gesture_arousal_sheet),
                "gesture.expressiveness": ("expressiveness", gesture_expressiveness),
                "gesture.expressiveness_per_emotion": ("expressiveness", gesture_expressiveness_per_emotion),
                "gesture.speed": ("speed", gesture_speed),
                "gesture.training_speed": ("epoch_timing", gesture_training_speed)},
    "rbf_features": {"rbf_features.run": ("date", rbf_features_run),
                     "rbf_features.neutral_base": ("neutral_base", rbf_features_neutral_base),
                     "rbf_features.summary": ("summary", rbf_features_summary),
                     "rbf_features.feature_key": ("feature_names", rbf_features_feature_key),
                     "rbf_features.mean_change": ("rows", rbf_features_mean_change),
                     "rbf_features.feature_checks": ("rows", rbf_features_feature_checks),
                     "rbf_features.measure_checks": ("rows", rbf_features_measure_checks),
                     "rbf_features.bones_floor": ("rows", rbf_features_bones_floor),
                     "rbf_features.scaling": ("scaling", rbf_features_scaling)},
    "rbf_real": {"rbf_real.run": ("date", rbf_real_run),
                 "rbf_real.neutral_cycle": ("neutral", rbf_real_neutral_cycle),
                 "rbf_real.neutral_checks": ("neutral", rbf_real_neutral_checks),
                 "rbf_real.accuracy": ("accuracy", rbf_real_accuracy),
                 "rbf_real.compare": ("compare", rbf_real_compare),
                 "rbf_real.top_dofs": ("compare", rbf_real_top_dofs),
                 "rbf_real.observers": ("observers", rbf_real_observers),
                 "rbf_real.ablation": ("ablation", rbf_real_ablation),
                 "rbf_real.ablation_totals": ("ablation", rbf_real_ablation_totals),
                 "rbf_real.emotion_observer": ("observers", rbf_real_emotion_observer)},
    "real_observer": {"real_observer.run": ("date", real_observer_run),
                      "real_observer.emotion_accuracy": ("held_out", real_observer_emotion_accuracy),
                      "real_observer.confusion_takes": ("held_out", real_observer_confusion_takes),
                      "real_observer.confusion_windows": ("held_out", real_observer_confusion_windows),
                      "real_observer.themes": ("held_out", real_observer_themes),
                      "real_observer.confusion_loto": ("leave_one_take_out", real_observer_confusion_loto),
                      "real_observer.plan_themes": ("themes_in_plans", real_observer_plan_themes),
                      "real_observer.plans": ("plans", real_observer_plans),
                      "real_observer.thresholds": ("thresholds", real_observer_thresholds),
                      "real_observer.realism": ("realism", real_observer_realism)},
    "gait_real": {"gait_real.run": ("date", gait_real_run),
                  "gait_real.prediction_all": ("prediction", gait_real_prediction_all),
                  "gait_real.prediction_emotion": ("prediction", gait_real_prediction_emotion),
                  "gait_real.emotion": ("recognition", gait_real_emotion),
                  "gait_real.realism": ("realism", gait_real_realism),
                  "gait_real.plan_reading": ("plan_reading", gait_real_plan_reading),
                  "gait_real.plan_parts": ("plan_reading", gait_real_plan_parts)},
    "upsampling": {"upsampling.run": ("date", upsampling_run),
                   "upsampling.real": ("real_round_trip", upsampling_real),
                   "upsampling.generated": ("generated", upsampling_generated),
                   "upsampling.gestures": ("gestures", upsampling_gestures)},
}
"""area -> table name -> (the JSON key it needs, renderer)."""


FILES: dict[str, tuple[str, str]] = {"rbf_features": ("rbf_features.json", "rbf.md"),
                                     "rbf_real": ("rbf_real.json", "rbf.md"),
                                     "real_observer": ("real_observer.json", "mocap.md"),
                                     "gait_real": ("gait_real.json", "gait.md"),
                                     "upsampling": ("upsampling.json", "gait.md")}
"""area -> (its JSON, its doc) in docs/benchmarks/, where they are not <area>.json and <area>.md."""


def area_files(area: str) -> tuple[Path, Path]:
    """(JSON results, Markdown doc) of ``area``."""
    results, doc = FILES.get(area, (f"{area}.json", f"{area}.md"))
    return DOCS / results, DOCS / doc


def render_tables(area: str, results: dict) -> dict[str, list[str]]:
    """Table name -> Markdown lines, for every table of ``area`` whose data ``results`` holds."""
    if area not in TABLES:
        raise ValueError(f"no tables for {area!r}; areas: {', '.join(TABLES)}")
    return {name: fn(results) for name, (key, fn) in TABLES[area].items() if key in results}


def fill_doc(text: str, tables: dict[str, list[str]]) -> tuple[str, list[str]]:
    """``text`` with every marked block whose table is in ``tables`` replaced; returns (text, names replaced)."""
    done = []

    def replace(m: re.Match) -> str:
        name = m.group("name")
        if name not in tables:
            return m.group(0)
        done.append(name)
        return m.group(1) + "\n".join(tables[name]) + "\n" + m.group(4)

    return BLOCK_RE.sub(replace, text), done


def update_doc(area: str, results_path: Path | None = None, doc_path: Path | None = None) -> list[str]:
    """Render ``area``'s tables from its JSON into the marked blocks of its doc; returns the tables written."""
    results_path = results_path or area_files(area)[0]
    doc_path = doc_path or area_files(area)[1]
    tables = render_tables(area, json.loads(results_path.read_text()))
    text, done = fill_doc(doc_path.read_text(), tables)
    doc_path.write_text(text)
    return done


def write_results(area: str, out: Path, results: dict, seconds: float, default=float) -> None:
    """Write a benchmark's ``results`` as JSON to ``out``; when ``out`` is the area's own JSON file, also render the
    area's tables into its doc (a run written elsewhere, e.g. a candidate's, leaves the docs alone)."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(results, indent=1, default=default) + "\n")
    print(f"\nwrote {out} in {seconds:.0f} s")
    if out.resolve() == area_files(area)[0].resolve():
        print(f"{area_files(area)[1].name} tables:", ", ".join(update_doc(area)) or "none marked")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("area", choices=sorted(TABLES))
    ap.add_argument("--results", type=Path, help="JSON results (default docs/benchmarks/<area>.json or FILES)")
    ap.add_argument("--doc", type=Path, help="Markdown doc (default docs/benchmarks/<area>.md or FILES)")
    ap.add_argument("--print", action="store_true", help="print the tables instead of writing the doc")
    args = ap.parse_args(argv)
    results_path = args.results or area_files(args.area)[0]
    if not results_path.is_file():
        print(f"error: no results file {results_path} (run the area's benchmark first)", file=sys.stderr)
        return 2
    if args.print:
        for name, lines in render_tables(args.area, json.loads(results_path.read_text())).items():
            print(f"\n{name}\n" + "\n".join(lines))
        return 0
    done = update_doc(args.area, results_path, args.doc)
    print(f"{args.doc or area_files(args.area)[1]}: {len(done)} table(s) written "
          f"({', '.join(done) or 'none marked'})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
