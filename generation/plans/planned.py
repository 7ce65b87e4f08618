"""A plan's planned clips as clips.csv rows, before anything is rendered: the study simulator's input.

Each plan entry becomes one SYNTHETIC clip row with id ``sim-<plan>-<entry id>``: the public clips.csv columns
(``protocol.vocabulary.CLIP_COLUMNS``; intent columns as the renderer records them, :func:`schema.intent_fields`) plus
:data:`EXTRA_COLUMNS` (the plan's name, the entry id, the id of the entry's source clip and its section hints).
Its ``duration_s`` is the planned one: the entry's ``duration_s`` input, else its pair's (a generated gesture and
its source), else the plan's render duration -- a rendered clip's real length may differ a little.

The analysis reads these rows from a CSV file and never imports this package; the table it ships for the preset
plans (``analysis/data/planned_clips.csv``) is written with

    python -m generation.plans.planned $(python -m protocol.presets) --out analysis/data/planned_clips.csv
    python -m generation.plans.planned my_plan.yaml --out var/my_planned_clips.csv   # any plan (name or file)

(``python -m protocol.presets`` prints the plans the study presets draw on; the motion library does not read the
presets.)
"""
from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

from protocol.vocabulary import CLIP_COLUMNS

from .schema import ClipEntry, Plan, PlanError, intent_fields, load_plan

EXTRA_COLUMNS = ("plan", "entry_id", "source_clip_id", "sections")
"""Columns after CLIP_COLUMNS in a planned clips table (``sections``: the entry's section-type hints joined by
commas, as the study app's catalogue stores them)."""
PLANNED_COLUMNS = (*CLIP_COLUMNS, *EXTRA_COLUMNS)


def _duration(entry: ClipEntry, by_id: dict[str, ClipEntry]) -> float:
    """Planned length in seconds: the entry's duration input, else its pair's, else the plan's render duration."""
    if "duration_s" in entry.inputs:
        return float(entry.inputs["duration_s"])
    pair = by_id.get(entry.pair)
    if pair is not None and "duration_s" in pair.inputs:
        return float(pair.inputs["duration_s"])
    return float(entry.render.duration_s)


def planned_clip_rows(plan: Plan) -> list[dict]:
    """One SYNTHETIC clip row per entry of a validated plan: :data:`PLANNED_COLUMNS`, blanks ``None`` ("" for
    ``source_clip_id``)."""
    by_id = {e.id: e for e in plan.entries}
    rows = []
    for e in plan.entries:
        row = {c: None for c in CLIP_COLUMNS}
        row.update(intent_fields(e))
        row.update(clip_id=f"sim-{plan.name}-{e.id}", modality=e.modality, origin=e.origin,
                   duration_s=round(_duration(e, by_id), 3), plan=plan.name, entry_id=e.id,
                   source_clip_id=f"sim-{plan.name}-{e.pair}" if e.pair else "", sections=",".join(e.sections))
        rows.append(row)
    return rows


def write_planned_clips(plan_refs, out: str | Path) -> int:
    """Write the planned clip rows of the plans ``plan_refs`` (built-in names or files), each once, to the CSV
    ``out``; returns the number of rows. Raises PlanError for a missing or invalid plan."""
    rows = []
    for ref in dict.fromkeys(plan_refs):
        rows += planned_clip_rows(load_plan(ref))
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=PLANNED_COLUMNS, lineterminator="\n")
        writer.writeheader()
        writer.writerows({k: ("" if v is None else v) for k, v in row.items()} for row in rows)
    return len(rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m generation.plans.planned", description=__doc__.splitlines()[0])
    ap.add_argument("plans", nargs="+", help="plan names or files (the presets' plans: python -m protocol.presets)")
    ap.add_argument("--out", required=True, help="CSV file to write")
    args = ap.parse_args(argv)
    try:
        n = write_planned_clips(args.plans, args.out)
    except PlanError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"{n} planned clips -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
