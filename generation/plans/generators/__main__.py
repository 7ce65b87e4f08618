"""Write the generator table of ``docs/generators.md`` from the registry.

    python -m generation.plans.generators            # print the page
    python -m generation.plans.generators --out docs/generators.md
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from generation.plans.schema import COMMON_FIELDS

from . import registered
from .registry import GeneratorSpec


def _field_line(spec: GeneratorSpec) -> str:
    parts = []
    for f in dataclasses.fields(spec.inputs):
        if f.name not in spec.fields:
            continue
        default = "" if f.default is dataclasses.MISSING else f" = {f.default!r}"
        parts.append(f"`{f.name}` ({f.type}{default})")
    extra = sorted(spec.fields - {f.name for f in dataclasses.fields(spec.inputs)})
    parts += [f"`{name}`" for name in extra]
    return "; ".join(parts)


def render_page() -> str:
    """The Markdown page: one section per registered generator."""

    common = ", ".join(f"`{name}`" for name in sorted(COMMON_FIELDS))
    lines = ["# Generators", "",
             "Written by `python -m generation.plans.generators --out docs/generators.md` from the generator "
             "registry (`generation/plans/generators/`); a test checks that it is current. A plan entry names one "
             f"with `generator:`; every entry also takes {common} (generation/plans/schema.py).", "",
             "| generator | modality | origins | fallbacks | weights | summary |", "|---|---|---|---|---|---|"]
    for spec in registered():
        weights = spec.weights(None).name if spec.weights else ""
        lines.append(f"| `{spec.name}` | {spec.modality or 'entry (gait or gesture)'} | {', '.join(spec.origins)} | "
                     f"{', '.join(spec.fallbacks)} | {weights} | {spec.summary} |")
    lines.append("")
    for spec in registered():
        doc = " ".join((spec.inputs.__doc__ or "").split())
        lines += [f"## `{spec.name}`", "", f"Module `{spec.module}`. {doc}", "", f"Fields: {_field_line(spec)}.", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m generation.plans.generators", description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None, help="file to write (default: print)")
    args = ap.parse_args(argv)
    page = render_page()
    if args.out:
        Path(args.out).write_text(page, encoding="utf-8")
        print(f"{len(registered())} generators -> {args.out}")
    else:
        print(page)
    return 0


if __name__ == "__main__":
    sys.exit(main())
