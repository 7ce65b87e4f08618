"""After the quality gate: which section of a preset is short of the clips it asks for, and why."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from analysis.coverage import planned_rows
from generation.plans.planned import planned_clip_rows
from generation.plans.schema import load_plan
from protocol import coverage
from protocol.coverage import matches
from protocol.pools import blocking_checks
from protocol.presets import PRESET_PLANS


def section_coverage(preset, flags):
    return coverage.section_coverage(preset, planned_clip_rows(load_plan(PRESET_PLANS[preset])), flags)


def coverage_lines(preset, flags):
    return coverage.coverage_lines(preset, planned_clip_rows(load_plan(PRESET_PLANS[preset])), flags)


def test_pool_filters_on_planned_rows():
    row = {"modality": "gait", "origin": "generated", "final_happy": None, "theme": None, "plan": "demo",
           "sections": "emotion_choice,naturalness", "happy": 1.0}
    assert matches(row, {"modality": "gait", "transition": False, "rbf": False})
    assert not matches(row, {"transition": True})
    assert matches(row, {"sections__contains": "naturalness", "happy__gte": 0.5})
    assert not matches(row, {"origin": ["source"]})
    advisory = {"keep_advisory": True}
    assert blocking_checks("realism", {}) == ["realism"] and blocking_checks("", {}) == []
    assert blocking_checks("observer;realism", advisory) == ["observer"] and blocking_checks("realism", advisory) == []
    assert blocking_checks("observer;realism", {**advisory, "observer_advisory": True}) == []
    assert blocking_checks("observer;realism", {"observer_advisory": True}) == ["realism"]
    assert blocking_checks("penetration;observer", {"observer_advisory": True}) == ["penetration"]
    assert blocking_checks("penetration;observer", {"include_flagged": True}) == []


def test_demo_sections_full_when_nothing_is_flagged_and_short_when_the_gate_takes_clips():
    full = section_coverage("demo", {})
    assert not any(s["short"] for s in full)
    walks = full[0]
    assert walks["section_type"] == "emotion_choice" and walks["asks"] == 2 and walks["usable"] >= 2
    entries = [e for e in ("happy_loop", "sad_loop", "angry_hairpin", "happy_neutral_mix")]
    flags = dict.fromkeys(entries, "penetration")
    flags["happy_loop"] = "realism"                         # advisory: stays in the pool
    cov = section_coverage("demo", flags)
    assert cov[0]["short"] and cov[0]["usable"] == 1
    assert ("sad_loop", ["penetration"]) in cov[0]["left_out"]
    lines = coverage_lines("demo", flags)
    assert lines[0].startswith("section 1 (emotion_choice)") and "SHORT" in lines[0] and "sad_loop: penetration" \
        in lines[0]
    assert "shows the clips of section 1 again" in lines[2]


def test_norming_candidates_keep_observer_flags_and_a_pool_smaller_than_m_is_not_short():
    """People judge a norming study's candidates: an observer flag keeps none out, and when fewer than M
    candidates are usable each participant rates them all."""
    flags = {"happy_neutral_mix": "observer", "sad_loop": "penetration"}
    walks = section_coverage("norming", flags)[0]
    assert walks["asks"] == 8 and walks["in_pool"] == 8
    assert walks["left_out"] == [("sad_loop", ["penetration"])]
    assert walks["usable"] == 7 and not walks["short"]
    assert "norming: each participant rates 7 of the 7 candidates" in walks["why"]
    gestures = section_coverage("norming", {})[1]
    assert gestures["asks"] == 8 and gestures["in_pool"] < 8 and not gestures["short"]
    broken = section_coverage("norming", {"happy_loop": "jerk", "sad_loop": "jerk", "angry_hairpin": "jerk",
                                          "happy_neutral_mix": "jerk", "source_walk_happy": "jerk",
                                          "source_walk_sad": "jerk", "source_walk_angry": "jerk",
                                          "source_walk_normal": "jerk"})[0]
    assert broken["usable"] == 0 and broken["short"]


@pytest.mark.parametrize("preset", ["demo", "norming"])
def test_the_shipped_planned_table_gives_the_same_coverage_as_the_plan(preset):
    flags = {"sad_loop": "penetration", "happy_neutral_mix": "observer"}
    from_table = coverage.section_coverage(preset, planned_rows(PRESET_PLANS[preset]), flags)
    assert from_table == section_coverage(preset, flags)


def test_the_coverage_command_reads_plan_qa_flags(tmp_path):
    qa = tmp_path / "qa.json"
    qa.write_text(json.dumps([{"entry": e, "flag": "penetration"} for e in ("happy_loop", "sad_loop", "angry_hairpin",
                                                                             "happy_neutral_mix")]))
    out = subprocess.run([sys.executable, "-m", "analysis.coverage", "--plan", "demo", "--flags", str(qa)],
                         capture_output=True, text=True, check=True).stdout
    assert "plan demo, preset demo: section 1 (emotion_choice)" in out and "SHORT" in out
    bad = subprocess.run([sys.executable, "-m", "analysis.coverage", "--plan", "nope"], capture_output=True, text=True)
    assert bad.returncode == 2 and "plan 'nope' has no rows" in bad.stderr
