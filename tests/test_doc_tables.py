"""benchmarks/doc_tables.py: tables rendered from benchmark JSON replace exactly their marked blocks in a doc."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))

import doc_tables  # noqa: E402

RESULTS = {
    "prediction": {"full": {"pose_error_body_diag": 0.0231, "pose_error_cm": 3.94, "pose_error_first10_cm": 1.26,
                            "pose_error_last10_cm": 6.71, "rotation_error_deg": 5.83, "rotation_error_rad": 0.1017}},
    "long_horizon": {"windows": [{"steps": "0-50", "root_speed_m_s": 1.234, "pose_variance_cm2": 196.4,
                                  "path_distance_m": 0.0171, "root_height_m": 0.8951}]},
}
DOC = """# Gait

Narrative stays.

<!-- table: gait.prediction -->
| stale | table |
<!-- /table -->

<!-- table: gait.speed -->
kept: no speed figures in these results
<!-- /table -->

<!-- table: gait.long_horizon -->
<!-- /table -->
"""


def test_marked_blocks_get_the_rendered_tables(tmp_path):
    (tmp_path / "gait.json").write_text(json.dumps(RESULTS))
    (tmp_path / "gait.md").write_text(DOC)
    done = doc_tables.update_doc("gait", tmp_path / "gait.json", tmp_path / "gait.md")
    text = (tmp_path / "gait.md").read_text()
    assert sorted(done) == ["gait.long_horizon", "gait.prediction"]
    assert "| full | 0.023 | 3.9 | 1.3 / 6.7 | 5.8 (0.102) |" in text and "stale" not in text
    assert "| 0-50 | 1.23 | 196 | 0.017 | 0.895 |" in text
    assert "kept: no speed figures in these results" in text and "Narrative stays." in text
    # rendering again changes nothing
    doc_tables.update_doc("gait", tmp_path / "gait.json", tmp_path / "gait.md")
    assert (tmp_path / "gait.md").read_text() == text


def test_the_gait_doc_marks_every_gait_table():
    text = (doc_tables.DOCS / "gait.md").read_text()
    marked = {m.group("name") for m in doc_tables.BLOCK_RE.finditer(text)}
    assert marked == set(doc_tables.TABLES["gait"])


def test_unknown_area_and_missing_results(tmp_path, capsys):
    with pytest.raises(ValueError, match="no tables for 'dance'"):
        doc_tables.render_tables("dance", {})
    assert doc_tables.main(["gait", "--results", str(tmp_path / "none.json")]) == 2
    assert "run the area's benchmark first" in capsys.readouterr().err
