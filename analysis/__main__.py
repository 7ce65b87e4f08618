"""CLI: ``python -m analysis RESPONSES CLIPS PARTICIPANTS --out DIR [--alpha A] [--permutations N] [--no-figures]
[--no-exclusions] [--exclusion-rules JSON] [--viewing VIEWING]``.

Exit status 0 on success, 2 with a message naming file, line and column on invalid input.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

from .exclusion import rule_errors
from .io import ValidationError
from .report import write_report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m analysis",
                                 description="Analyse a perceptual study export and write the report folder.")
    ap.add_argument("responses", help="responses.csv")
    ap.add_argument("clips", help="clips.csv")
    ap.add_argument("participants", help="participants.csv")
    ap.add_argument("--out", required=True, help="output folder (created if missing)")
    ap.add_argument("--alpha", type=float, default=0.05, help="significance level (default 0.05)")
    ap.add_argument("--permutations", type=int, default=0,
                    help="also compute permutation p-values with N resamples for the 2-sample AD tests")
    ap.add_argument("--no-figures", action="store_true", help="skip the PNG/SVG figures (tables only)")
    ap.add_argument("--no-exclusions", action="store_true",
                    help="analyse every participant (skip the too-fast and straight-lining exclusion rules)")
    ap.add_argument("--exclusion-rules", metavar="JSON",
                    help="the study's exclusion thresholds: a JSON object or a .json file, e.g. "
                         "'{\"min_rt_fraction\": 0.25, \"max_straightline\": 0.9, \"min_attention_pass\": 1.0}' "
                         "(keys: see analysis.exclusion.RULES)")
    ap.add_argument("--viewing", metavar="VIEWING_CSV",
                    help="viewing.csv (optional): list answers given without a full view of the clip and enable the "
                         "viewing exclusion rules (max_unended_share, max_hidden_share, max_untrusted_share)")
    a = ap.parse_args(argv)
    for path in (a.responses, a.clips, a.participants, *([a.viewing] if a.viewing else [])):
        if not os.path.isfile(path):
            print(f"error: no such file: {path}", file=sys.stderr)
            return 2
    if not 0 < a.alpha < 1 or a.permutations < 0:
        print("error: --alpha must be in (0, 1) and --permutations >= 0", file=sys.stderr)
        return 2
    rules = None
    if a.exclusion_rules:
        text = a.exclusion_rules
        try:
            rules = json.loads(open(text, encoding="utf-8").read() if os.path.isfile(text) else text)
        except (OSError, ValueError) as exc:
            print(f"error: --exclusion-rules: not a JSON object or .json file ({exc})", file=sys.stderr)
            return 2
        errors = rule_errors(rules)
        if errors:
            print("error: --exclusion-rules: " + "; ".join(errors), file=sys.stderr)
            return 2
    try:
        report = write_report(a.responses, a.clips, a.participants, a.out, a.alpha, a.permutations,
                              figures=not a.no_figures, exclude=not a.no_exclusions,
                              exclusion_rules=rules, viewing_csv=a.viewing)
    except ValidationError as exc:
        print(f"error: invalid input\n{exc}", file=sys.stderr)
        return 2
    for line in report["meta"]["summary"]:
        print(line)
    print(f"report written to {os.path.join(a.out, 'report.html')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
