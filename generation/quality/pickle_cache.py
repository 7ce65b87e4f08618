"""A fitted object kept in a pickle file: read it when it is there and of the expected type, else build it and
write it atomically (the synthetic observers of :mod:`generation.quality` use it)."""
from __future__ import annotations

import os
import pickle
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

T = TypeVar("T")


def load_or_build(path: Path, kind: type[T], build: Callable[[], T]) -> T:
    """The ``kind`` instance pickled at ``path``, or ``build()`` written there (a stale, foreign or unreadable
    pickle is rebuilt; the write goes through a per-process temporary file so parallel workers never read half a
    file). Exceptions of ``build`` propagate."""
    obj = None
    if path.is_file():
        try:
            obj = pickle.loads(path.read_bytes())
        except Exception:  # noqa: BLE001 - a stale or foreign pickle: rebuild
            obj = None
    if isinstance(obj, kind):
        return obj
    obj = build()
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_bytes(pickle.dumps(obj))
    tmp.replace(path)
    return obj
