"""The record every benchmark result carries (machine, load, date), printed and optionally written as JSON."""
from __future__ import annotations

import json
import os
import platform
import subprocess
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def record(result: dict, json_path: str | Path | None = None) -> dict:
    """``result`` with ``machine``, ``load_average_1m`` and ``date`` added; printed, and written to ``json_path``
    when given. Returns the completed record."""
    result = {**result, "machine": f"{platform.node()} {platform.machine()}, {os.cpu_count()} CPUs",
              "load_average_1m": round(os.getloadavg()[0], 1),
              "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")}
    text = json.dumps(result, indent=1)
    print(text)
    if json_path:
        Path(json_path).write_text(text + "\n")
    return result


def machine_label(torch_threads: str | None = None) -> str:
    """'<arch>, <n> CPUs (shared), Python <version>', then ', <torch_threads>' when given (e.g. "1 torch
    thread"): the machine line of the JSON-writing benchmarks' run records."""
    label = f"{platform.machine()}, {os.cpu_count()} CPUs (shared), Python {platform.python_version()}"
    return label if torch_threads is None else f"{label}, {torch_threads}"


def commit_label() -> str:
    """'commit <short hash>' of the repository, '+ uncommitted changes' when tracked files differ from it."""
    def git(*args):
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True).stdout.strip()

    dirty = git("status", "--porcelain", "--untracked-files=no")
    return f"commit {git('rev-parse', '--short', 'HEAD')}" + (" + uncommitted changes" if dirty else "")


def one_thread() -> None:
    """Run the numerical libraries of this process on $OMP_NUM_THREADS threads (1 unless set): the BLAS and OpenMP
    pools and torch's. The benchmarks that time single-threaded work call it first in ``main``."""
    import torch  # heavy: only the benchmarks that time torch work load it
    from threadpoolctl import threadpool_limits

    n = int(os.environ.get("OMP_NUM_THREADS") or 1)
    threadpool_limits(n)
    torch.set_num_threads(n)
