"""Markdown tables of the benchmarks' JSON results, and their place in the docs.

Benchmarks write their figures as JSON (``docs/benchmarks/<area>.json``); the narrative lives in
``docs/benchmarks/<area>.md`` (``FILES`` names the areas whose JSON and doc are named otherwise, e.g. rbf_real.json
-> rbf.md). A doc marks where a rendered table goes::

    <!-- table: gait.prediction -->
    ...replaced by the table...
    <!-- /table -->

and this script replaces each marked block with the table rendered from the JSON (blocks whose data the JSON lacks
are left as they are)::

    python -m benchmarks.doc_tables gait            # docs/benchmarks/gait.json -> the marked tables of gait.md
    python -m benchmarks.doc_tables gesture         # docs/benchmarks/gesture.json -> gesture.md
    python -m benchmarks.doc_tables rbf_real        # docs/benchmarks/rbf_real.json -> rbf.md
    python -m benchmarks.doc_tables gait_real       # docs/benchmarks/gait_real.json -> gait.md
    python -m benchmarks.doc_tables realism_by_emotion  # realism_by_emotion.json -> gait.md
    python -m benchmarks.doc_tables gait --print    # print every table of the JSON instead

The renderers live in ``doc_renderers/``, one module per area (gait, gesture, rbf_features, rbf_real,
real_observer, gait_real, upsampling, realism_by_emotion), each with its own ``TABLES``, and
``doc_renderers/common.py`` for the formatting they share; this module combines them into ``TABLES`` and keeps the
doc handling and the CLI.
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

from benchmarks.doc_renderers import (
    gait,
    gait_real,
    gesture,
    rbf_features,
    rbf_real,
    real_observer,
    realism_by_emotion,
    upsampling,
)
from benchmarks.doc_renderers.common import EMOTIONS, Renderer, table
from benchmarks.doc_renderers.gait_real import GAIT_REAL_SUBSETS

__all__ = ["BLOCK_RE", "DOCS", "EMOTIONS", "FILES", "GAIT_REAL_SUBSETS", "TABLES", "area_files", "fill_doc", "main",
           "render_tables", "table", "update_doc", "write_marked", "write_results"]

DOCS = Path(__file__).resolve().parent.parent / "docs" / "benchmarks"
BLOCK_RE = re.compile(r"(<!-- table: (?P<name>[\w.]+) -->\n)(?P<body>.*?)(<!-- /table -->)", re.S)

TABLES: dict[str, dict[str, tuple[str, Renderer]]] = {
    "gait": gait.TABLES, "gesture": gesture.TABLES, "rbf_features": rbf_features.TABLES, "rbf_real": rbf_real.TABLES,
    "real_observer": real_observer.TABLES, "gait_real": gait_real.TABLES, "upsampling": upsampling.TABLES,
    "realism_by_emotion": realism_by_emotion.TABLES}
"""area -> table name -> (the JSON key it needs, renderer)."""


FILES: dict[str, tuple[str, str]] = {"rbf_features": ("rbf_features.json", "rbf.md"),
                                     "rbf_real": ("rbf_real.json", "rbf.md"),
                                     "real_observer": ("real_observer.json", "mocap.md"),
                                     "gait_real": ("gait_real.json", "gait.md"),
                                     "upsampling": ("upsampling.json", "gait.md"),
                                     "realism_by_emotion": ("realism_by_emotion.json", "gait.md")}
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


def write_marked(doc_path: str | Path, marker: str, text: str) -> None:
    """Replace what stands between ``<!-- marker -->`` and ``<!-- /marker -->`` in the page ``doc_path`` with
    ``text`` (a section a benchmark writes whole, narrative beside it kept); SystemExit naming the page when the
    markers are missing."""
    doc_path = Path(doc_path)
    doc = doc_path.read_text(encoding="utf-8")
    pattern = re.compile(rf"(<!-- {re.escape(marker)} -->\n).*?(<!-- /{re.escape(marker)} -->)", re.S)
    if not pattern.search(doc):
        raise SystemExit(f"{doc_path}: no <!-- {marker} --> ... <!-- /{marker} --> markers")
    doc_path.write_text(pattern.sub(lambda m: m.group(1) + text + "\n" + m.group(2), doc), encoding="utf-8")


def publish_marked(results: dict, json_path: str | Path, text: str, doc_path: str | Path | None, marker: str) -> None:
    """A benchmark's end: ``results`` as JSON to ``json_path``, its rendered ``text`` printed and, with ``doc_path``,
    written between the page's ``marker`` markers (:func:`write_marked`)."""
    Path(json_path).write_text(json.dumps(results, indent=1) + "\n", encoding="utf-8")
    print(text)
    if doc_path:
        write_marked(doc_path, marker, text)


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
