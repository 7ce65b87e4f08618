"""Planned clips: generation writes a plan's clip rows as a CSV, the analysis designs a study from that file alone."""
from __future__ import annotations

import subprocess
import sys

import pandas as pd
import pytest

from analysis.design import PLANNED_CLIPS, DesignError, design_from_presets, read_planned_clips
from generation.plans.planned import planned_clip_rows, write_planned_clips
from generation.plans.schema import load_plan
from protocol.presets import PRESET_PLANS


def test_shipped_table_is_the_current_plans(tmp_path):
    """analysis/data/planned_clips.csv must follow the plans; rewrite it with
    python -m generation.plans.planned $(python -m protocol.presets) --out analysis/data/planned_clips.csv"""
    write_planned_clips(sorted(set(PRESET_PLANS.values())), tmp_path / "now.csv")
    assert (tmp_path / "now.csv").read_text() == PLANNED_CLIPS.read_text()


def test_rows_carry_intent_duration_and_pairs():
    plan = load_plan("seed003")
    rows = {r["entry_id"]: r for r in planned_clip_rows(plan)}
    paired = next(e for e in plan.entries if e.pair)
    row = rows[paired.id]
    assert row["source_clip_id"] == f"sim-seed003-{paired.pair}" and row["clip_id"] == f"sim-seed003-{paired.id}"
    assert row["modality"] == paired.modality and row["duration_s"] > 0
    assert row["emotion_label"] == paired.inputs.get("emotion_label")


def test_any_plan_file_through_the_csv(tmp_path):
    out = tmp_path / "planned.csv"
    n = write_planned_clips(["demo"], out)
    assert n == len(load_plan("demo").entries)
    renamed = pd.read_csv(out, dtype=str, keep_default_na=False)
    renamed["plan"] = "mine"
    renamed.to_csv(out, index=False)
    design = design_from_presets(("demo",), plans={"demo": "mine"}, clips=out)
    assert set(design.clips["plan"]) == {"mine"} and len(design.clips) == n
    with pytest.raises(DesignError, match="plan 'nope' has no rows.*generation.plans.planned nope"):
        design_from_presets(("demo",), plans={"demo": "nope"})
    (tmp_path / "bad.csv").write_text("clip_id,plan\nx,demo\n")
    with pytest.raises(DesignError, match="missing columns"):
        design_from_presets(("demo",), clips=tmp_path / "bad.csv")


def test_cli_writes_the_table(tmp_path):
    out = tmp_path / "t.csv"
    res = subprocess.run([sys.executable, "-m", "generation.plans.planned", "demo", "--out", str(out)],
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert read_planned_clips(out)["clip_id"].tolist() == read_planned_clips(PLANNED_CLIPS).query(
        "plan == 'demo'")["clip_id"].tolist()
    res = subprocess.run([sys.executable, "-m", "generation.plans.planned", "no_such_plan", "--out", str(out)],
                         capture_output=True, text=True)
    assert res.returncode == 2 and "no_such_plan" in res.stderr
