"""benchmarks/bench_rbf_features.py: the summary figures it writes to its JSON for the doc's summary table."""
from __future__ import annotations

from benchmarks import bench_rbf_features


def _row(theme, weight, checks, measures, before, after, foot, foot_direction_only):
    return {"theme": theme, "weight": weight, "bone_error_before_m": before, "bone_error_after_m": after,
            "lowest_foot_m": foot, "lowest_foot_direction_only_m": foot_direction_only,
            "checks": [{"feature": f, "holds": h} for f, h in checks],
            "measures": [{"measure": m, "holds": h} for m, h in measures]}


def test_summary_counts_checks_and_takes_the_extremes():
    rows = [_row("sad", 0.7, [("f4", True), ("f5", True)], [("head_height", True)], 0.026, 4e-16, -1e-6, -0.018),
            _row("tired", -0.7, [("f14", True)], [("head_height", False), ("heel_lift", True)], 0.062, 7e-16,
                 0.0012, -0.0425)]
    s = bench_rbf_features.summary({"rows": rows})
    assert (s["checks_held"], s["checks"], s["measures_held"], s["measures"]) == (3, 3, 2, 3)
    assert s["failed"] == ["tired w = -0.7: head_height"]
    assert (s["bone_error_before_max_m"], s["bone_error_after_max_m"]) == (0.062, 7e-16)
    assert (s["lowest_foot_m"], s["lowest_foot_direction_only_m"]) == (-1e-6, -0.0425)
