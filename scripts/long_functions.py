"""List functions longer than a limit (default 80 lines) in the three libraries.

    python -m scripts.long_functions [--limit N] [FOLDER ...]
"""
from __future__ import annotations

import argparse
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def long_functions(folders, limit: int) -> list[tuple[int, str]]:
    """(length in lines, 'path:line name') of every function over ``limit`` lines, longest first."""
    rows = []
    for folder in folders:
        for path in sorted((ROOT / folder).rglob("*.py")):
            if "migrations" in path.parts:
                continue
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    length = node.end_lineno - node.lineno + 1
                    if length > limit:
                        rows.append((length, f"{path.relative_to(ROOT)}:{node.lineno} {node.name}"))
    return sorted(rows, reverse=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="*", default=["generation", "studyapp", "analysis"])
    parser.add_argument("--limit", type=int, default=80)
    args = parser.parse_args()
    for length, where in long_functions(args.folders, args.limit):
        print(f"{length:4d}  {where}")


if __name__ == "__main__":
    main()
