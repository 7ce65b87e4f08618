"""Collect the per-area benchmark write-ups in docs/benchmarks/*.md into docs/benchmarks.md.

Each benchmark script writes (or its author pastes) its figures into docs/benchmarks/<area>.md; this
script puts them into the one page researchers read, in a fixed order, with a table of contents.
Usage: python -m benchmarks.collect_docs
"""
from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ORDER = ["core_features", "corpus", "rbf", "gait", "gesture", "device", "motion_quality", "render", "mocap",
         "mocap_training", "study", "flow", "flow_postgres", "analysis"]
TITLES = {
    "core_features": "Motion core: features, IK, BVH, captured walks",
    "corpus": "Procedural motion and the synthetic corpus",
    "rbf": "RBF style features (seed 004)",
    "gait": "Emotive gait network (seed 000)",
    "gesture": "Text2Gestures network (seed 003)",
    "device": "Training and generation devices, paper-size configurations",
    "motion_quality": "Motion quality: planted feet, quality gate",
    "render": "Rendering, plans and catalogue",
    "mocap": "Motion-capture import",
    "mocap_training": "Training on imported capture",
    "study": "Study web app under load",
    "flow": "Participant flow: queries per answer, concurrent starts",
    "flow_postgres": "Participant flow on PostgreSQL",
    "analysis": "Analysis and reports",
}


def main() -> None:
    parts = sorted((ROOT / "docs" / "benchmarks").glob("*.md"), key=lambda p: (
        ORDER.index(p.stem) if p.stem in ORDER else len(ORDER), p.stem))
    lines = [
        "# Benchmarks",
        "",
        "Speed and quality figures, measured with the scripts in `benchmarks/` on the project's 2-core CI VM",
        "(no GPU, 24 GiB) on 2026-11-27. During most runs other jobs shared the two cores, so absolute times are",
        "pessimistic; ratios were measured within one run. Each section is kept in `docs/benchmarks/<area>.md` and",
        "collected here by `python -m benchmarks.collect_docs`.",
        "",
    ]
    lines += [f"- [{TITLES.get(p.stem, p.stem)}](#{p.stem.replace('_', '-')})" for p in parts]
    for part in parts:
        body = part.read_text().strip().splitlines()
        if body and body[0].startswith("# "):
            body = body[1:]
        body = [("#" + line) if line.startswith("#") else line for line in body]
        lines += ["", f'<a id="{part.stem.replace("_", "-")}"></a>', "", f"## {TITLES.get(part.stem, part.stem)}",
                  "", *body]
    (ROOT / "docs" / "benchmarks.md").write_text("\n".join(lines).rstrip() + "\n")
    print(f"wrote docs/benchmarks.md from {len(parts)} sections")


if __name__ == "__main__":
    main()
