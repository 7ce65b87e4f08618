"""The study protocol is defined once (protocol/vocabulary.py): no library keeps a copy of a vocabulary."""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

from protocol import vocabulary as P

ROOT = Path(__file__).resolve().parents[1]
LIBRARIES = ("generation", "studyapp", "analysis")

#: name -> vocabulary that must not be written out again anywhere in the libraries.
VOCABULARIES = {
    "GAIT_EMOTIONS": P.GAIT_EMOTIONS,
    "THEMES": P.THEMES,
    "GESTURE_EMOTIONS": P.GESTURE_EMOTIONS,
    "SECTION_TYPES": P.SECTION_TYPES,
    "LIKERT_FEATURES": P.LIKERT_FEATURES,
    "VAD_DIMENSIONS": P.VAD_DIMENSIONS,
    "RESPONSE_COLUMNS": P.RESPONSE_COLUMNS,
    "PARTICIPANT_COLUMNS": P.PARTICIPANT_COLUMNS,
    "GENDERS": P.GENDERS,
    "GESTURE_TASKS": P.GESTURE_TASKS,
}


def _is_scalar_row(value: ast.AST) -> bool:
    """A constant, or a tuple of numbers: the values of a lookup table such as NRC-VAD rows or opposites."""
    if isinstance(value, ast.Constant):
        return True
    return isinstance(value, ast.Tuple) and all(
        isinstance(v, ast.Constant) and isinstance(v.value, (int, float)) for v in value.elts)


def _string_collections(tree: ast.AST):
    """(line, set of strings, is a dict) for every literal tuple/list/set of strings, and the keys of every
    literal lookup table (a dict of constants or number tuples; tables of richer data keyed by a vocabulary,
    such as seed 004's features per theme, are the module's own data)."""
    for node in ast.walk(tree):
        if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            items, is_table = node.elts, False
        elif isinstance(node, ast.Dict) and all(map(_is_scalar_row, node.values)):
            items, is_table = node.keys, True
        else:
            continue
        if len(items) >= 2 and all(isinstance(i, ast.Constant) and isinstance(i.value, str) for i in items):
            yield node.lineno, {i.value for i in items}, is_table


def copies_of_vocabularies(paths) -> list[str]:
    """'file:line NAME' for each literal that spells out a protocol vocabulary (or a superset of one with
    four or more entries, such as a lexicon with an extra word). Tables keyed by a two-word vocabulary (one
    value per gender, say) are data, not copies."""
    found = []
    for path in paths:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for line, strings, is_table in _string_collections(tree):
            for name, vocab in VOCABULARIES.items():
                vocab = set(vocab)
                if is_table and len(vocab) < 3:
                    continue
                if strings == vocab or (len(vocab) >= 4 and vocab < strings):
                    found.append(f"{path.relative_to(ROOT)}:{line} {name}")
    return found


def library_files():
    for lib in LIBRARIES:
        for path in sorted((ROOT / lib).rglob("*.py")):
            if "migrations" not in path.parts:
                yield path


def test_no_library_defines_a_vocabulary_again():
    copies = copies_of_vocabularies(library_files())
    assert not copies, "define these once in protocol/vocabulary.py and import them:\n" + "\n".join(copies)


def test_the_scan_finds_a_copy(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text('EMOTIONS = ("happy", "sad", "angry", "neutral")\n'
                   'LEX = {"afraid": 1, "amused": 1, "angry": 1, "ashamed": 1, "disgusted": 1, "joyous": 1,\n'
                   '       "neutral": 1, "proud": 1, "relieved": 1, "sad": 1, "surprised": 1, "happy": 1}\n'
                   'OK = ("happy", "sad")\n')
    global ROOT
    old, ROOT = ROOT, tmp_path
    try:
        assert copies_of_vocabularies([bad]) == ["bad.py:1 GAIT_EMOTIONS", "bad.py:2 GAIT_EMOTIONS",
                                                   "bad.py:2 GESTURE_EMOTIONS"]
    finally:
        ROOT = old


def test_protocol_imports_nothing_heavy():
    code = ("import sys, protocol.vocabulary; heavy = {'numpy', 'torch', 'django', 'pandas'} & set(sys.modules); "
            "assert not heavy, heavy")
    subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True)


def test_protocol_tables_agree_with_each_other():
    assert set(P.SECTION_QUESTIONS) == set(P.SECTION_TYPES) == set(P.SECTION_MODALITY)
    assert set(P.LIKERT_LEVELS) == set(P.LIKERT_FEATURES)
    assert all(len(levels) == 5 for _, levels in P.LIKERT_LEVELS.values())
    assert set(P.OPPOSITE_THEME) == set(P.THEMES) == set(P.OPPOSITE_THEME.values())
    assert all(P.OPPOSITE_THEME[P.OPPOSITE_THEME[t]] == t for t in P.THEMES)
    assert all(0.0 <= x <= 1.0 for row in P.GESTURE_VAD.values() for x in row)
    assert list(P.GESTURE_EMOTIONS) == sorted(P.GESTURE_EMOTIONS) and len(P.GESTURE_EMOTIONS) == 11
    assert P.CLIP_COLUMNS[0] == "clip_id" and len(set(P.CLIP_COLUMNS)) == len(P.CLIP_COLUMNS)
    assert set(P.CLIP_FLOAT_COLUMNS) | set(P.CLIP_INT_COLUMNS) <= set(P.CLIP_COLUMNS)


@pytest.mark.parametrize("section", P.SECTION_TYPES)
def test_every_question_has_a_finite_answer_domain(section):
    for kind in P.SECTION_QUESTIONS[section].values():
        values = P.answer_values(kind)
        assert values and len(set(values)) == len(values)
