"""The layer rules of the three libraries, checked on every import statement (function-local ones included).

- generation and analysis never import studyapp or Django;
- analysis never imports generation;
- generation.core imports no other project package (it is the bottom layer);
- the top-level vocabulary (study_protocol, study_pools, study_presets) imports none of the libraries nor Django;
- the package graph (scripts/import_graph.py's packages) has no cycle.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from scripts.import_graph import TOP_MODULES, find_cycles, package_edges

FORBIDDEN = [
    ("generation", ("studyapp", "django"), "generation never imports studyapp or Django"),
    ("analysis", ("studyapp", "django", "generation"), "analysis never imports studyapp, Django or generation"),
    ("generation.core", ("generation", "analysis", "studyapp", "django", *TOP_MODULES),
     "generation.core imports nothing above it"),
    (TOP_MODULES, ("generation", "analysis", "studyapp", "django"), "the top-level vocabulary imports no library"),
]


def _under(package: str, prefixes) -> bool:
    prefixes = (prefixes,) if isinstance(prefixes, str) else prefixes
    return any(package == p or package.startswith(p + ".") for p in prefixes)


def layer_violations(edges) -> list[str]:
    """'rule: file:line imports package' for every edge that crosses a layer the wrong way."""
    found = []
    for (source, dest), uses in sorted(edges.items()):
        for sources, targets, rule in FORBIDDEN:
            if _under(source, sources) and _under(dest, targets) and dest != source:
                found += [f"{rule}: {path}:{line} imports {dest}" + (" (inside a function)" if local else "")
                          for path, line, local in uses]
    return found


@pytest.fixture(scope="module")
def edges():
    return package_edges()[0]


def test_no_import_crosses_the_layers_the_wrong_way(edges):
    assert layer_violations(edges) == []


def test_package_graph_has_no_cycle(edges):
    assert find_cycles(edges) == []


def _tree(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root


def test_the_checks_see_local_imports_and_cycles(tmp_path):
    """The rules fail on a wrong-way import hidden in a function and on a cycle made of local imports."""
    root = _tree(tmp_path, {
        "study_protocol.py": "X = 1\n",
        "analysis/__init__.py": "",
        "analysis/a.py": "def f():\n    from generation.plans import schema\n    return schema\n",
        "generation/__init__.py": "",
        "generation/core/__init__.py": "from ..render import x\n",
        "generation/render/__init__.py": "def g():\n    from generation.core import y\n",
        "generation/plans/x.py": "import django.db\n",
        "studyapp/__init__.py": "",
    })
    edges, local = package_edges(root)
    found = layer_violations(edges)
    assert any("analysis/a.py:2 imports generation.plans (inside a function)" in v for v in found)
    assert any("generation/plans/x.py:1 imports django" in v for v in found)
    assert any("generation.core imports nothing above it" in v for v in found)
    assert find_cycles(edges) == [["generation.core", "generation.render"]]
    assert {(p.name, line) for p, line, _ in local} == {("a.py", 2), ("__init__.py", 2)}
