"""After the quality gate: which section of a preset is short of the clips it asks for, and why."""
from __future__ import annotations

from generation.pipeline.section_coverage import blocking, coverage_lines, matches, section_coverage


def test_pool_filters_on_planned_rows():
    row = {"modality": "gait", "origin": "generated", "final_happy": None, "theme": None, "plan": "demo",
           "sections": "emotion_choice,naturalness", "happy": 1.0}
    assert matches(row, {"modality": "gait", "transition": False, "rbf": False})
    assert not matches(row, {"transition": True})
    assert matches(row, {"sections__contains": "naturalness", "happy__gte": 0.5})
    assert not matches(row, {"origin": ["source"]})
    assert blocking("observer;realism") == ["observer"] and blocking("realism") == [] and blocking("") == []


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
