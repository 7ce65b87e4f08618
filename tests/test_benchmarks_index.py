"""docs/benchmarks.md is the short index benchmarks/collect_docs.py writes from the area pages: current, at most
150 lines, every area page with a headline, and the index's tables as rendered in their pages."""
from __future__ import annotations

import pytest

from benchmarks import collect_docs


def test_the_index_is_current_and_short():
    text = collect_docs.INDEX.read_text()
    assert text == collect_docs.index_text(), "run python -m benchmarks.collect_docs"
    assert len(text.splitlines()) <= 150


@pytest.mark.parametrize("page", collect_docs.areas(), ids=lambda p: p.stem)
def test_every_area_page_has_a_headline_and_a_title(page):
    assert 0 < len(collect_docs.headline(page)) <= 5
    assert page.stem in collect_docs.TITLES


def test_a_missing_headline_or_table_is_named(tmp_path):
    page = tmp_path / "x.md"
    page.write_text("# X\n\nno headline\n")
    with pytest.raises(ValueError, match="x.md: no <!-- headline --> block"):
        collect_docs.headline(page)
    with pytest.raises(ValueError, match="x.md: no table gait.run"):
        collect_docs.rendered_table(page, "gait.run")
