"""Markdown tables of the benchmarks' JSON results, and their place in the docs.

Benchmarks write their figures as JSON (``docs/benchmarks/<area>.json``); the narrative lives in
``docs/benchmarks/<area>.md``. A doc marks where a rendered table goes::

    <!-- table: gait.prediction -->
    ...replaced by the table...
    <!-- /table -->

and this script replaces each marked block with the table rendered from the JSON (blocks whose data the JSON lacks
are left as they are)::

    python benchmarks/doc_tables.py gait            # docs/benchmarks/gait.json -> the marked tables of gait.md
    python benchmarks/doc_tables.py gesture         # docs/benchmarks/gesture.json -> gesture.md
    python benchmarks/doc_tables.py gait --print    # print every table of the JSON instead
"""
from __future__ import annotations

import argparse
import json
import re
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
}
"""area -> table name -> (the JSON key it needs, renderer)."""


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
    results_path = results_path or DOCS / f"{area}.json"
    doc_path = doc_path or DOCS / f"{area}.md"
    tables = render_tables(area, json.loads(results_path.read_text()))
    text, done = fill_doc(doc_path.read_text(), tables)
    doc_path.write_text(text)
    return done


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("area", choices=sorted(TABLES))
    ap.add_argument("--results", type=Path, help="JSON results (default docs/benchmarks/<area>.json)")
    ap.add_argument("--doc", type=Path, help="Markdown doc (default docs/benchmarks/<area>.md)")
    ap.add_argument("--print", action="store_true", help="print the tables instead of writing the doc")
    args = ap.parse_args(argv)
    results_path = args.results or DOCS / f"{args.area}.json"
    if not results_path.is_file():
        print(f"error: no results file {results_path} (run the area's benchmark first)", file=sys.stderr)
        return 2
    if args.print:
        for name, lines in render_tables(args.area, json.loads(results_path.read_text())).items():
            print(f"\n{name}\n" + "\n".join(lines))
        return 0
    done = update_doc(args.area, results_path, args.doc)
    print(f"{args.doc or DOCS / (args.area + '.md')}: {len(done)} table(s) written "
          f"({', '.join(done) or 'none marked'})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
