"""The one file digest (generation.core.digest): its value, its cache, and no second copy of it in generation/."""
from __future__ import annotations

import ast
import hashlib
import os
from pathlib import Path

from generation.core.digest import cached_file_sha256, file_sha256

GENERATION = Path(__file__).resolve().parent.parent / "generation"


def test_digest_is_the_sha256_of_the_bytes_and_the_cache_sees_a_change(tmp_path):
    path = tmp_path / "take.bvh"
    path.write_bytes(b"HIERARCHY\n" * 10_000)
    assert file_sha256(path) == cached_file_sha256(path) == hashlib.sha256(path.read_bytes()).hexdigest()
    path.write_bytes(b"MOTION\n")
    os.utime(path, ns=(1, 1))
    assert cached_file_sha256(path) == hashlib.sha256(b"MOTION\n").hexdigest()


def _hashes_a_file_inline(node: ast.AST) -> bool:
    """``hashlib.<algorithm>(<x>.read_bytes())``: one file's digest computed on the spot."""
    return (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and isinstance(node.func.value, ast.Name) and node.func.value.id == "hashlib"
            and any(isinstance(a, ast.Call) and isinstance(a.func, ast.Attribute) and a.func.attr == "read_bytes"
                    for a in node.args))


def second_digest_helpers(root: Path = GENERATION) -> list[str]:
    """'file:line' of every definition of a file digest outside core/digest.py and every inline one."""
    found = []
    for path in sorted(root.rglob("*.py")):
        if path == root / "core" / "digest.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            defines = isinstance(node, ast.FunctionDef) and node.name in ("file_sha256", "cached_file_sha256")
            if defines or _hashes_a_file_inline(node):
                found.append(f"{path.relative_to(root.parent)}:{node.lineno}")
    return found


def test_generation_has_one_file_digest():
    assert second_digest_helpers() == []
