"""The section-type registry (protocol/section_types/): one declaration per type, the vocabulary's old names are
views of it, and docs/section_types.md is written from it."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from protocol import section_types as st
from protocol import vocabulary as P
from protocol.section_types.__main__ import render_page

ROOT = Path(__file__).resolve().parents[1]


def test_views_follow_the_registry():
    names = st.section_type_names()
    assert tuple(P.SECTION_TYPES) == names and len(P.SECTION_TYPES) == 8
    assert P.SECTION_TYPES == names and list(P.SECTION_TYPES) == list(names)
    for spec in st.registered():
        assert P.SECTION_QUESTIONS[spec.name] == spec.question_kinds
        assert P.SECTION_MODALITY[spec.name] == spec.modality
        assert (spec.name in P.NORMING_SECTION_TYPES) == spec.norming
        assert set(P.ANSWER_QUESTIONS[spec.name]) >= set(spec.question_kinds)
        for kind in spec.question_kinds.values():
            assert P.answer_values(kind)


def test_a_registration_shows_in_every_view_and_goes():
    toy = st.SectionType(name="toy_scale", label="Toy", summary="", modality="gait",
                         questions=(st.Ask("rating", P.INTENSITY),), norming=True)
    st.register(toy)
    try:
        assert "toy_scale" in P.SECTION_TYPES and P.SECTION_QUESTIONS["toy_scale"] == {"rating": P.INTENSITY}
        assert "toy_scale" in P.NORMING_SECTION_TYPES and P.SECTION_MODALITY.get("toy_scale") == "gait"
        assert P.section_questions("toy_scale", norming=True) == {"rating": P.INTENSITY, **P.NORMING_QUESTIONS}
        with pytest.raises(ValueError, match="registered already"):
            st.register(st.SectionType(name="toy_scale", label="Other", summary="", modality=None,
                                       questions=(st.Ask("x", P.LIKERT),)))
    finally:
        st.unregister("toy_scale")
    assert "toy_scale" not in P.SECTION_TYPES and "toy_scale" not in P.SECTION_QUESTIONS


@pytest.mark.parametrize("bad, message", [
    (dict(questions=()), "at least one question"),
    (dict(questions=(st.Ask("a", P.LIKERT), st.Ask("a", P.LIKERT))), "given twice"),
    (dict(modality="face"), "modality"),
    (dict(agreement="cronbach"), "agreement"),
    (dict(name="has space"), "identifier"),
])
def test_a_bad_declaration_is_refused_by_name(bad, message):
    fields = dict(name="toy_bad", label="Bad", summary="", modality="gait", questions=(st.Ask("a", P.LIKERT),))
    with pytest.raises(ValueError, match=message):
        st.register(st.SectionType(**{**fields, **bad}))
    assert "toy_bad" not in P.SECTION_TYPES


def test_unknown_type_names_the_registered_ones():
    with pytest.raises(st.UnknownSectionTypeError, match="emotion_choice"):
        st.get_section_type("arousal_nope")


def test_option_checks_live_with_their_type():
    from protocol.pools import options_errors

    assert options_errors("gesture_emotion", {"n_options": 1}) == ["'n_options' must be an integer from 2 to 11, "
                                                                   "got 1"]
    assert options_errors("emotion_choice", {"anchors": {}})[0].startswith("unknown option 'anchors'")


def test_docs_page_is_current():
    page = (ROOT / "docs" / "section_types.md").read_text(encoding="utf-8")
    assert page == render_page(), "run: python -m protocol.section_types --out docs/section_types.md"
    for spec in st.registered():
        assert f"## `{spec.name}`" in page


def test_the_docs_command_prints_the_page():
    out = subprocess.run([sys.executable, "-m", "protocol.section_types"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    assert out.rstrip("\n") == render_page().rstrip("\n")


def test_every_type_has_its_wording_its_answer_model_and_registered_analyses():
    from analysis.answer_models import has_answer_model
    from analysis.report_tables import report_tables
    from studyapp.questions import WORDING

    tables = {t.key for t in report_tables()} | {"recognition"}
    for spec in st.registered():
        assert set(WORDING[spec.name].questions) == set(spec.wording_keys), spec.name
        assert has_answer_model(spec.name), spec.name
        assert set(spec.analyses) <= tables, (spec.name, set(spec.analyses) - tables)


def test_a_design_without_an_answer_model_is_refused_before_drawing():
    from analysis.design import DesignError, design_from_presets
    from analysis.simulate import simulate_design

    design = design_from_presets(("demo",))
    toy = st.register(st.SectionType(name="toy_nomodel", label="Toy", summary="", modality="gait",
                                     questions=(st.Ask("rating", P.INTENSITY),)))
    try:
        sec = design.sections[0]
        broken = type(design)(design.name, design.presets, design.plans,
                              (type(sec)(sec.order, sec.preset, toy.name, sec.pool, sec.n_per_participant),),
                              design.clips)
        with pytest.raises(DesignError, match="no answer model for section type.*toy_nomodel"):
            simulate_design(3, broken)
    finally:
        st.unregister(toy.name)


def test_no_branch_on_a_section_type_name_outside_the_types_own_modules():
    """A type's behaviour lives in its declaration: code elsewhere asks the registry, never compares names."""
    import re

    root = Path(__file__).resolve().parents[1]
    branch = re.compile(r"section_type\s*(==|!=)|section_type\s+(not\s+)?in\s+\(\s*['\"]")
    found = [f"{path.relative_to(root)}:{n}" for package in ("studyapp", "analysis", "generation", "protocol")
             for path in sorted((root / package).rglob("*.py")) if "section_types" not in path.parts
             for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1) if branch.search(line)]
    assert not found, f"branches on a section type's name outside protocol/section_types: {found}"
