"""Write docs/benchmarks.md, the index of the per-area benchmark write-ups in docs/benchmarks/*.md.

Each area's page keeps its figures (the tables of the JSON-writing benchmarks are rendered from their JSON by
``benchmarks.doc_tables``; the narrative is written by hand) and opens with a short headline between
``<!-- headline -->`` and ``<!-- /headline -->``. The index lists every area in a fixed order with its headline, a
link to its page and, for a few areas, one of its generated tables copied as rendered there (``INDEX_TABLES``), so
the index's figures are those of the pages. tests/test_benchmarks_index.py keeps the index current.
Usage: python -m benchmarks.collect_docs
"""
from __future__ import annotations

import re
from pathlib import Path

from benchmarks.doc_tables import BLOCK_RE

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs" / "benchmarks"
INDEX = ROOT / "docs" / "benchmarks.md"
ORDER = ["core_features", "corpus", "rbf", "gait", "gesture", "device", "motion_quality", "render", "mocap",
         "mocap_training", "import", "study", "flow", "flow_postgres", "analysis", "norms"]
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
    "import": "Importing researchers' own videos and motion files",
    "study": "Study web app under load",
    "flow": "Participant flow: queries per answer, concurrent starts",
    "flow_postgres": "Participant flow on PostgreSQL",
    "analysis": "Analysis and reports",
    "norms": "Per-clip norms and norming studies",
}
#: Generated tables shown in the index, by area: (table name, the line that introduces it).
INDEX_TABLES = {
    "gait": [("gait_real.emotion", "How the real-capture observer reads generated walks:")],
    "rbf": [("rbf_features.summary", "Summary:")],
    "gesture": [("gesture.liveliness_summary", "Liveliness:")],
}
HEADLINE_RE = re.compile(r"<!-- headline -->\n(?P<body>.*?)<!-- /headline -->", re.S)


def areas() -> list[Path]:
    """The area pages, in ORDER (others after, by name)."""
    return sorted(DOCS.glob("*.md"), key=lambda p: (ORDER.index(p.stem) if p.stem in ORDER else len(ORDER), p.stem))


def headline(page: Path) -> list[str]:
    """The lines of a page's headline block; ValueError when it has none."""
    m = HEADLINE_RE.search(page.read_text())
    if m is None:
        raise ValueError(f"{page}: no <!-- headline --> block")
    return m["body"].strip().splitlines()


def rendered_table(page: Path, name: str) -> list[str]:
    """The lines of the generated table ``name`` as rendered in ``page``; ValueError when it is not there."""
    for m in BLOCK_RE.finditer(page.read_text()):
        if m["name"] == name:
            return m["body"].strip().splitlines()
    raise ValueError(f"{page}: no table {name}")


def index_text() -> str:
    """The text of docs/benchmarks.md."""
    lines = [
        "# Benchmarks",
        "",
        "Speed and quality figures, measured with the modules in `benchmarks/` (`python -m benchmarks.<name>`) on",
        "the project's 2-core CI VM (no GPU), mostly shared with other jobs, so absolute times are pessimistic;",
        "ratios were measured within one run. Each area has its own page in `docs/benchmarks/` with the set-up,",
        "every table and the reading; this index gives each page's headline. Written by",
        "`python -m benchmarks.collect_docs` from the pages' headline blocks and generated tables.",
    ]
    for page in areas():
        lines += ["", f"## [{TITLES.get(page.stem, page.stem)}](benchmarks/{page.name})", "", *headline(page)]
        for name, intro in INDEX_TABLES.get(page.stem, []):
            lines += ["", intro, "", *rendered_table(page, name)]
    return "\n".join(lines) + "\n"


def main() -> None:
    INDEX.write_text(index_text())
    print(f"wrote {INDEX.relative_to(ROOT)} from {len(areas())} pages")


if __name__ == "__main__":
    main()
