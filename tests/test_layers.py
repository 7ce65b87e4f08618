"""The layer rules of the three libraries, checked on every import statement (function-local ones included).

- generation and analysis never import studyapp or Django;
- analysis never imports generation;
- generation.core imports no other project package (it is the bottom layer);
- the protocol package (the ground floor: vocabulary, pools, presets, norming) imports none of the libraries nor Django;
- inside generation, a package imports only the packages below it in LAYERS (core < formats < procedural < render
  < gesture < mocap < gait < rbf < quality < plans < pipeline < imports, the order of the design notes), and
  every package of generation has its place in that order;
- the package graph (scripts/import_graph.py's packages) has no cycle;
- a function-local import of a project module says on its line why it is local (a heavy import such as torch or
  matplotlib, or an optional library), and there are at most LOCAL_IMPORT_BUDGET of them.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from scripts.import_graph import GROUND, ROOT, find_cycles, imports_of, module_name, package_edges, package_of

#: The packages of generation, bottom first: each may import only those before it.
LAYERS = ("core", "formats", "procedural", "render", "gesture", "mocap", "gait", "rbf", "quality", "plans",
          "pipeline", "imports")
LOCAL_IMPORT_BUDGET = 11      # 10, and studyapp.apps.ready connecting the signal receivers (Django's way)

FORBIDDEN = [
    ("generation", ("studyapp", "django"), "generation never imports studyapp or Django"),
    ("analysis", ("studyapp", "django", "generation"), "analysis never imports studyapp, Django or generation"),
    ("generation.core", ("generation", "analysis", "studyapp", "django", GROUND),
     "generation.core imports nothing above it"),
    (GROUND, ("generation", "analysis", "studyapp", "django"), "the protocol imports no library"),
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
    return found + layer_order_violations(edges)


def _layer(package: str) -> int | None:
    parts = package.split(".")
    return LAYERS.index(parts[1]) if parts[0] == "generation" and len(parts) > 1 and parts[1] in LAYERS else None


def layer_order_violations(edges) -> list[str]:
    """'file:line: generation.a imports generation.b above it' for every import up the LAYERS order."""
    found = []
    for (source, dest), uses in sorted(edges.items()):
        low, high = _layer(source), _layer(dest)
        if low is not None and high is not None and high > low:
            found += [f"{path}:{line}: {source} imports {dest} above it" + (" (inside a function)" if local else "")
                      for path, line, local in uses]
    return found


def local_project_imports(local_imports, root: Path = ROOT) -> list[tuple[str, str]]:
    """(file:line, the import's first line) of every function-local import of a project module."""
    found = []
    for path, line, target in local_imports:
        if package_of(target) not in (None, "django"):
            found.append((f"{path.relative_to(root)}:{line}", path.read_text().splitlines()[line - 1].strip()))
    return found


@pytest.fixture(scope="module")
def edges():
    return package_edges()[0]


def test_no_import_crosses_the_layers_the_wrong_way(edges):
    assert layer_violations(edges) == []


def unplaced_packages(root: Path = ROOT) -> list[str]:
    """Packages of generation (folders with an ``__init__.py``) that LAYERS does not place, so nothing checks them."""
    return sorted(p.parent.name for p in (root / "generation").glob("*/__init__.py") if p.parent.name not in LAYERS)


def test_every_generation_package_has_a_layer():
    assert unplaced_packages() == []


def test_package_graph_has_no_cycle(edges):
    assert find_cycles(edges) == []


def test_function_local_project_imports_are_few_and_say_why():
    found = local_project_imports(package_edges()[1])
    assert [where for where, text in found if "#" not in text] == []
    assert len(found) <= LOCAL_IMPORT_BUDGET, found


def _tree(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root


def test_the_checks_see_local_imports_and_cycles(tmp_path):
    """The rules fail on a wrong-way import hidden in a function and on a cycle made of local imports."""
    root = _tree(tmp_path, {
        "protocol/vocabulary.py": "X = 1\n",
        "analysis/__init__.py": "",
        "analysis/a.py": "def f():\n    from generation.plans import schema\n    return schema\n",
        "generation/__init__.py": "",
        "generation/core/__init__.py": "from ..render import x\n",
        "generation/render/__init__.py": "def g():\n    from generation.core import y\n",
        "generation/plans/x.py": "import django.db\n",
        "generation/gesture/y.py": "def h():\n    from generation.quality import z\n",
        "generation/pipeline/w.py": "from generation.imports import run\n",
        "generation/extra/__init__.py": "",
        "studyapp/__init__.py": "",
    })
    edges, local = package_edges(root)
    found = layer_violations(edges)
    assert any("analysis/a.py:2 imports generation.plans (inside a function)" in v for v in found)
    assert any("generation/plans/x.py:1 imports django" in v for v in found)
    assert any("generation.core imports nothing above it" in v for v in found)
    assert any("generation/gesture/y.py:2: generation.gesture imports generation.quality above it (inside a "
               "function)" in v for v in found)
    assert any("generation/pipeline/w.py:1: generation.pipeline imports generation.imports above it" in v
               for v in found)
    assert unplaced_packages(root) == ["extra"]
    assert find_cycles(edges) == [["generation.core", "generation.render"]]
    assert {(p.name, line) for p, line, _ in local} == {("a.py", 2), ("__init__.py", 2), ("y.py", 2)}
    assert sorted(text for _, text in local_project_imports(local, root) if "#" not in text) == [
        "from generation.core import y", "from generation.plans import schema", "from generation.quality import z"]


STUDY_DESIGN = ("protocol.presets", "protocol.pools", "protocol.norming", "protocol.coverage")
"""The study design in protocol: the motion library reads the vocabulary only."""


def test_generation_reads_no_study_design():
    found = [f"{path.relative_to(ROOT)}:{line} imports {module}"
             for path in sorted((ROOT / "generation").rglob("*.py"))
             for module, line, _local in imports_of(path)
             if any(module == m or module.startswith(m + ".") for m in STUDY_DESIGN)]
    assert not found, "generation must not import the study design (presets, pools, norming):\n" + "\n".join(found)


def _import_nodes(path: Path) -> list[ast.Import | ast.ImportFrom]:
    """The import statements of a file in imports_of's order (one entry per name of a plain import)."""
    found: list = []

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.Import):
                found.extend([child] * len(child.names))
            elif isinstance(child, ast.ImportFrom):
                found.append(child)
            visit(child)

    visit(ast.parse(path.read_text()))
    return found


def studyapp_module_cycles(root: Path = ROOT) -> list[list[str]]:
    """Import cycles between the modules of studyapp (function-local imports included), each as a closed path."""
    graph: dict[str, set[str]] = {}
    for path in sorted((root / "studyapp").rglob("*.py")):
        if "migrations" not in path.parts:
            siblings = {f"{target}.{alias.name}" for (target, _line, _local), node
                        in zip(imports_of(path, root), _import_nodes(path), strict=True)
                        if isinstance(node, ast.ImportFrom) for alias in node.names}   # from . import a: module a
            graph[module_name(path, root)] = {m for m, _line, _local in imports_of(path, root)} | siblings
    graph = {m: {d for d in deps if d in graph and d != m and not m.startswith(d + ".")}
             for m, deps in graph.items()}          # a module's own packages run before it: no cycle
    found, state, stack = [], {}, []

    def visit(module: str) -> None:
        state[module] = "open"
        stack.append(module)
        for dep in sorted(graph[module]):
            if state.get(dep) == "open":
                found.append([*stack[stack.index(dep):], dep])
            elif dep not in state:
                visit(dep)
        stack.pop()
        state[module] = "done"

    for module in sorted(graph):
        if module not in state:
            visit(module)
    return found


def test_studyapp_modules_have_no_import_cycle():
    cycles = studyapp_module_cycles()
    assert not cycles, "studyapp import cycles:\n" + "\n".join(" -> ".join(c) for c in cycles)


def test_the_module_cycle_check_finds_one(tmp_path):
    (tmp_path / "studyapp").mkdir()
    (tmp_path / "studyapp" / "__init__.py").write_text("")
    (tmp_path / "studyapp" / "a.py").write_text("from .b import f\n")
    (tmp_path / "studyapp" / "b.py").write_text("def f():\n    from . import a\n")
    assert studyapp_module_cycles(tmp_path) == [["studyapp.a", "studyapp.b", "studyapp.a"]]
