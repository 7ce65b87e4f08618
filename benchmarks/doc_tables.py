"""Markdown tables of the benchmarks' JSON results, and their place in the docs.

Benchmarks write their figures as JSON (``docs/benchmarks/<area>.json``); the narrative lives in
``docs/benchmarks/<area>.md``. A doc marks where a rendered table goes::

    <!-- table: gait.prediction -->
    ...replaced by the table...
    <!-- /table -->

and this script replaces each marked block with the table rendered from the JSON (blocks whose data the JSON lacks
are left as they are)::

    python benchmarks/doc_tables.py gait            # docs/benchmarks/gait.json -> the marked tables of gait.md
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


TABLES: dict[str, dict[str, tuple[str, Callable[[dict], list[str]]]]] = {
    "gait": {"gait.prediction": ("prediction", gait_prediction),
             "gait.expressiveness": ("expressiveness", gait_expressiveness),
             "gait.own_emotion": ("expressiveness", gait_own_emotion),
             "gait.trajectory": ("trajectory", gait_trajectory),
             "gait.long_horizon": ("long_horizon", gait_long_horizon),
             "gait.speed": ("speed", gait_speed)},
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
