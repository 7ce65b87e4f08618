"""Which section of a preset is short of clips after a plan's quality gate, from the planned clips table.

The study side of ``python -m generation.pipeline.plan_qa``: its ``--json`` rows give each entry's quality flag; the
planned clips table (default the shipped ``analysis/data/planned_clips.csv``, or one written by
``python -m generation.plans.planned PLAN --out CSV``) gives the plan's rows; :mod:`protocol.coverage` compares them
with each preset section's pool and clip count.

    python -m generation.pipeline.plan_qa --plan demo --json /tmp/demo_qa.json
    python -m analysis.coverage --plan demo --flags /tmp/demo_qa.json [--clips CSV]
"""
from __future__ import annotations

import argparse
import json
import math
import sys

from protocol.coverage import coverage_lines, presets_of_plan

from .design import PLANNED_CLIPS, DesignError, read_planned_clips


def planned_rows(plan: str, clips=PLANNED_CLIPS) -> list[dict]:
    """The plan's rows of a planned clips table as dicts (blank cells None), what ``protocol.coverage`` reads.
    DesignError when the table has no row of the plan."""
    table = read_planned_clips(clips)
    table = table[table["plan"] == plan]
    if table.empty:
        raise DesignError(f"planned clips {clips}: plan {plan!r} has no rows (write them with python -m "
                          f"generation.plans.planned {plan} --out CSV)")
    return [{k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in row.items()}
            for row in table.to_dict("records")]


def flags_of(qa_rows: list[dict]) -> dict[str, str]:
    """entry id -> quality flag from plan_qa's ``--json`` rows (``entry``, ``flag``)."""
    return {str(r["entry"]): r.get("flag") or "" for r in qa_rows}


def main(argv=None) -> int:
    """Print the coverage lines of every preset drawing on ``--plan``; 2 on bad input."""
    ap = argparse.ArgumentParser(prog="python -m analysis.coverage", description=__doc__.splitlines()[0])
    ap.add_argument("--plan", required=True)
    ap.add_argument("--flags", default=None, help="plan_qa --json output (default: every entry passed)")
    ap.add_argument("--clips", default=str(PLANNED_CLIPS), help="planned clips table (CSV)")
    args = ap.parse_args(argv)
    try:
        rows = planned_rows(args.plan, args.clips)
        flags = {}
        if args.flags:
            with open(args.flags, encoding="utf-8") as f:
                flags = flags_of(json.load(f))
    except (DesignError, OSError, ValueError, KeyError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    presets = presets_of_plan(args.plan)
    if not presets:
        print(f"plan {args.plan}: no preset draws on it")
    for preset in presets:
        for line in coverage_lines(preset, rows, flags, args.plan):
            print(f"plan {args.plan}, preset {preset}: {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
