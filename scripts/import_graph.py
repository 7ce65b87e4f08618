"""Print the package import graph of the project: one line per edge ``package -> package (n imports)``.

Packages are the subpackages of ``generation`` (``generation.core``, ``generation.render``, ...), ``analysis``,
``studyapp`` and ``protocol`` (the study protocol, the ground floor).
Imports inside functions count as edges too (marked ``local``):
they hide cycles as well as top-level ones do. Exits 1 when the package graph has a cycle, naming it.

    python -m scripts.import_graph            # edges, then cycles if any
    python -m scripts.import_graph --local    # also list each function-local import with its file and line

Importable (``from scripts.import_graph import package_edges, find_cycles``): tests/test_layers.py checks the layer
rules on the same edges.
"""
from __future__ import annotations

import argparse
import ast
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LIBRARIES = ("protocol", "generation", "analysis", "studyapp")
GROUND = "protocol"


def package_of(module: str) -> str | None:
    """The graph node of a dotted module name, or None for a module outside the project."""
    parts = module.split(".")
    if parts[0] == "generation":
        return ".".join(parts[:2]) if len(parts) > 1 else "generation"
    if parts[0] in LIBRARIES:
        return parts[0]
    if parts[0] == "django":
        return "django"
    return None


def module_name(path: Path, root: Path = ROOT) -> str:
    """Dotted module name of a file under ``root`` (a package's ``__init__.py`` is the package)."""
    rel = path.relative_to(root).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def imports_of(path: Path, root: Path = ROOT) -> list[tuple[str, int, bool]]:
    """(imported module, line, inside a function) for every import statement of a file."""
    tree = ast.parse(path.read_text(), filename=str(path))
    this = module_name(path, root)
    is_package = path.name == "__init__.py"
    found: list[tuple[str, int, bool]] = []

    def visit(node: ast.AST, local: bool) -> None:
        for child in ast.iter_child_nodes(node):
            inner = local or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef))
            if isinstance(child, ast.Import):
                found.extend((alias.name, child.lineno, local) for alias in child.names)
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    base = this.split(".")
                    base = base if is_package else base[:-1]
                    base = base[: len(base) - (child.level - 1)]
                    target = ".".join(base + ([child.module] if child.module else []))
                else:
                    target = child.module or ""
                found.append((target, child.lineno, local))
            visit(child, inner)

    visit(tree, False)
    return found


def project_files(root: Path = ROOT) -> list[Path]:
    """Every module of the protocol and the three libraries (migrations left out)."""
    files = []
    for library in LIBRARIES:
        files += sorted(p for p in (root / library).rglob("*.py") if "migrations" not in p.parts)
    return files


def package_edges(root: Path = ROOT) -> tuple[dict[tuple[str, str], list[tuple[str, int, bool]]],
                                              list[tuple[Path, int, str]]]:
    """Edges between distinct packages, each with its (file, line, local) occurrences; and all local imports."""
    edges: dict[tuple[str, str], list] = defaultdict(list)
    local_imports: list[tuple[Path, int, str]] = []
    for path in project_files(root):
        source = package_of(module_name(path, root))
        for target, line, local in imports_of(path, root):
            if local:
                local_imports.append((path, line, target))
            dest = package_of(target)
            if dest is None or dest == source:
                continue
            edges[(source, dest)].append((str(path.relative_to(root)), line, local))
    return edges, local_imports


def find_cycles(edges) -> list[list[str]]:
    """Strongly connected components with more than one package (Tarjan)."""
    graph: dict[str, set[str]] = defaultdict(set)
    for a, b in edges:
        graph[a].add(b)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[list[str]] = []

    def strongconnect(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                strongconnect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                components.append(sorted(component))

    for node in list(graph):
        if node not in index:
            strongconnect(node)
    return components


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--local", action="store_true", help="list every function-local import")
    args = parser.parse_args(argv)
    edges, local_imports = package_edges()
    for (a, b), uses in sorted(edges.items()):
        n_local = sum(1 for *_, local in uses if local)
        print(f"{a} -> {b} ({len(uses)} imports, {n_local} local)")
    print(f"\n{len(local_imports)} function-local imports in "
          f"{len({p for p, *_ in local_imports})} files")
    if args.local:
        for path, line, target in local_imports:
            print(f"  {path.relative_to(ROOT)}:{line} {target}")
    cycles = find_cycles(edges)
    for cycle in cycles:
        print("cycle:", " <-> ".join(cycle))
    if not cycles:
        print("no cycles")
    return 1 if cycles else 0


if __name__ == "__main__":
    sys.exit(main())
