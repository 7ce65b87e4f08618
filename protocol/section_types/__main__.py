"""Write ``docs/section_types.md`` from the section-type registry.

    python -m protocol.section_types                              # print the page
    python -m protocol.section_types --out docs/section_types.md
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from protocol.pools import COMMON_OPTIONS
from protocol.vocabulary import INTEGER_RANGES, NORMING_QUESTIONS, answer_values

from . import page_types, registered
from .registry import SectionType


def _domain(kind: str) -> str:
    """An integer scale as ``lo..hi``, a label set spelled out."""
    if kind in INTEGER_RANGES:
        return "{}..{}".format(*INTEGER_RANGES[kind])
    return ", ".join(answer_values(kind))


def _questions(spec: SectionType) -> str:
    return "; ".join(f"`{a.key}` ({a.kind}: {_domain(a.kind)})" for a in spec.questions)


def _clip_need(spec: SectionType) -> str:
    if spec.clip_need is None:
        return "a clip id"
    return " or ".join("+".join(group) for group in spec.clip_need.any_of) + f" ({spec.clip_need.text})"


def render_page() -> str:
    """The Markdown page: a table of every registered section type, then one section each."""
    norming = ", ".join(f"`{k}` ({kind})" for k, kind in NORMING_QUESTIONS.items())
    lines = ["# Section types", "",
             "Written by `python -m protocol.section_types --out docs/section_types.md` from the section-type "
             "registry (`protocol/section_types/`); a test checks that it is current. A study section names one "
             "with `section_type`; every section also takes the options "
             f"{', '.join(f'`{k}`' for k in COMMON_OPTIONS)} (protocol/pools.py), and a norming type asks "
             f"{norming} after its own questions when `options.norming` is set.", "",
             "A new section type is three registrations: its declaration (a module here), its participant wording "
             "(`studyapp.questions.register_wording`) and its analysis (an answer model, "
             "`analysis.answer_models.register_answer_model`, and, for a table of its own, "
             "`analysis.report_tables.register_table`).", "",
             "| section type | modality | questions | options | norming | analyses |", "|---|---|---|---|---|---|"]
    for spec in registered():
        lines.append(f"| `{spec.name}` | {spec.modality or 'any'} | {', '.join(spec.wording_keys)} | "
                     f"{', '.join(spec.option_keys)} | {'yes' if spec.norming else ''} | {', '.join(spec.analyses)} |")
    lines.append("")
    for spec in registered():
        lines += [f"## `{spec.name}`: {spec.label}", "", f"Module `{spec.module}`. {spec.summary}", "",
                  f"- Questions: {_questions(spec)}."]
        if spec.options:
            lines.append("- Options: " + "; ".join(f"`{o.key}` ({o.doc})" for o in spec.options) + ".")
        extras = [x for x in (f"sub-pools {', '.join(spec.sub_pools)}" if spec.sub_pools else "",
                              "choices drawn per participant and clip" if spec.drawn_choices else "") if x]
        if extras:
            lines.append(f"- Assignment: {'; '.join(extras)}.")
        lines += [f"- Clips need: {_clip_need(spec)}.",
                  f"- Simulated answers: {spec.simulator or 'none'}."]
        agreement = {"icc": "ICC of ratings", "kappa": "Fleiss' kappa of choices"}.get(spec.agreement, "none")
        by = f" (one rater set per `{spec.agreement_by}`)" if spec.agreement_by else ""
        lines.append(f"- Agreement: {agreement}{by}; demographic comparison: "
                     f"{f'`{spec.demographics}`' if spec.demographics else 'none'}.")
        lines += [f"- Feeds: {', '.join(f'`{a}`' for a in spec.analyses) or 'nothing'}; figures: "
                  f"{', '.join(f'`{f}`' for f in spec.figures) or 'none'}.", ""]
    return "\n".join(lines + _page_lines())


def _page_lines() -> list[str]:
    """The page types (instruction and break pages): no clips, no questions; left out of the table above."""
    lines = ["## Pages between sections", "",
             "A page type is a section without clips or questions that a participant reads and continues from "
             "(docs/study.md, \"Instruction and break pages\"). It takes no pool and none of the options of every "
             "section; under counterbalancing it travels with the section after it; pages.csv records when each "
             "participant saw it and continued.", ""]
    for spec in page_types():
        options = "; ".join(f"`{o.key}` ({o.doc})" for o in spec.options) or "none"
        lines += [f"- `{spec.name}`: {spec.label}. Module `{spec.module}`. {spec.summary} Options: {options}."]
    return lines + [""]


def main(argv=None) -> int:
    """Print the page, or write it to ``--out``; returns the exit status."""
    ap = argparse.ArgumentParser(prog="python -m protocol.section_types", description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None, help="file to write (default: print)")
    args = ap.parse_args(argv)
    page = render_page()
    if args.out:
        Path(args.out).write_text(page, encoding="utf-8")
        print(f"{len(registered())} section types -> {args.out}")
    else:
        print(page)
    return 0


if __name__ == "__main__":
    sys.exit(main())
