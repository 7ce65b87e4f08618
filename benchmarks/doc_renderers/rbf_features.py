"""Tables of the RBF styliser's synthetic measures (benchmarks/bench_rbf_features.py; docs/benchmarks/rbf.md)."""
from __future__ import annotations

from benchmarks.doc_renderers.common import Renderer, _run, _yes, table


def _w(row: dict) -> str:
    return f"{row['weight']:+.1f}"


def _sign(s: int) -> str:
    return "+" if s > 0 else "-"


def rbf_features_run(r: dict) -> list[str]:
    return _run(r)


def rbf_features_neutral_base(r: dict) -> list[str]:
    """The neutral cycle the themes edit: where it comes from, its size and sources."""
    base = r["neutral_base"]
    sources = base.get("sources", base.get("captured_sources", []))
    rejected = sum(u.get("rejected_cycles", 0) for u in sources)
    return table(["neutral base", "value"], [
        ["function", f"`{r['base_function']}`"], ["cycles averaged", base["n_cycles"]],
        ["cycles rejected as glitches", rejected], ["cycle", f"{base['cycle_duration_s']:.2f} s"],
        ["stride", f"{base['stride_m'][2]:.2f} m"], ["synthetic", base["synthetic"]],
        ["sources used (cycles)", "; ".join(f"{u['name']} ({u['cycles']})" for u in sources if u["cycles"])]])


def rbf_features_summary(r: dict) -> list[str]:
    """Checks that hold, bone-length and floor extremes, speed (``r["summary"]``, from every theme and weight)."""
    s, t = r["summary"], r["timing"]
    verb = "loading" if "load_cycle" in r["base_function"] else "building"
    return table(["measure", "value"], [
        ["expected directions that hold, 18 gait affective features", f"{s['checks_held']} of {s['checks']}"],
        ["expected directions that hold, direct geometric measures", f"{s['measures_held']} of {s['measures']}"],
        ["not holding", ", ".join(s["failed"]) or "none"],
        ["largest bone-length deviation of the edited positions Y", f"{s['bone_error_before_max_m'] * 1000:.0f} mm"],
        ["largest bone-length deviation after the fit", f"{s['bone_error_after_max_m'] * 1000:.1e} mm"],
        ["lowest foot joint relative to the neutral floor: our fit / `generation.core.ik.fit_positions_to_skeleton` "
         "(direction-only)",
         f"{s['lowest_foot_m'] * 1000:+.1f} mm / {s['lowest_foot_direction_only_m'] * 1000:+.1f} mm"],
        ["stylising one 4-cycle clip at 30 fps", f"{t['stylise_clip_s'] * 1000:.0f} ms ({t['clip_frames']} frames)"],
        [f"{verb} the neutral base", f"{t['neutral_base_s']:.2f} s"]])


def rbf_features_feature_key(r: dict) -> list[str]:
    """One line: f<i> = name of each gait affective feature."""
    return ["Feature key: " + "; ".join(f"f{i} = {n}" for i, n in enumerate(r["feature_names"]))]


def rbf_features_mean_change(r: dict) -> list[str]:
    return table(["theme", "w", *(f"f{i}" for i in range(len(r["feature_names"])))],
                 [[row["theme"], _w(row), *(f"{v:+.3f}" for v in row["mean_change"])] for row in r["rows"]])


def rbf_features_feature_checks(r: dict) -> list[str]:
    return table(["theme", "w", "feature", "aggregate", "expected", "change", "holds", "why"],
                 [[row["theme"], _w(row), c["feature"], c["aggregate"], _sign(c["expected_sign"]),
                   f"{c['change']:+.4f}", _yes(c["holds"]),
                   c["reason"] if row["weight"] > 0 else "inverse of: " + c["reason"]]
                  for row in r["rows"] for c in row["checks"]])


def rbf_features_measure_checks(r: dict) -> list[str]:
    return table(["theme", "w", "measure", "expected", "change (mm)", "holds"],
                 [[row["theme"], _w(row), c["measure"], _sign(c["expected_sign"]), f"{c['change_m'] * 1000:+.1f}",
                   _yes(c["holds"])] for row in r["rows"] for c in row["measures"]])


def rbf_features_bones_floor(r: dict) -> list[str]:
    return table(["theme", "w", "before", "after (ours)", "after (ik.fit_positions_to_skeleton)", "lowest foot ours",
                  "lowest foot direction-only", "max lift by floor clamp"],
                 [[row["theme"], _w(row), f"{row['bone_error_before_m'] * 1000:.1f}",
                   f"{row['bone_error_after_m'] * 1000:.1e}", f"{row['ik_direction_only_after_m'] * 1000:.1e}",
                   f"{row['lowest_foot_m'] * 1000:+.1f}", f"{row['lowest_foot_direction_only_m'] * 1000:+.1f}",
                   f"{row['ground_lift_m'] * 1000:.1f}"] for row in r["rows"]])


def rbf_features_scaling(r: dict) -> list[str]:
    """Mean joint displacement (cm) per theme on the n x w grid of ``r["scaling_axes"]``."""
    axes = r["scaling_axes"]
    return table(["theme", "n", *(f"w {w}" for w in axes["w"])],
                 [[theme, n, *(f"{v:.2f}" for v in row)] for theme, grid in r["scaling"].items()
                  for n, row in zip(axes["n"], grid)])


TABLES: dict[str, tuple[str, Renderer]] = {
    "rbf_features.run": ("date", rbf_features_run),
    "rbf_features.neutral_base": ("neutral_base", rbf_features_neutral_base),
    "rbf_features.summary": ("summary", rbf_features_summary),
    "rbf_features.feature_key": ("feature_names", rbf_features_feature_key),
    "rbf_features.mean_change": ("rows", rbf_features_mean_change),
    "rbf_features.feature_checks": ("rows", rbf_features_feature_checks),
    "rbf_features.measure_checks": ("rows", rbf_features_measure_checks),
    "rbf_features.bones_floor": ("rows", rbf_features_bones_floor),
    "rbf_features.scaling": ("scaling", rbf_features_scaling),
}
"""Table name -> (the JSON key it needs, renderer)."""
