"""The one digest of a file's content: hex SHA-256, read in blocks. It names the corpus a model or an observer was
trained on, the weights a clip was made with and a researcher's captured take."""
from __future__ import annotations

import functools
import hashlib
from pathlib import Path


def file_sha256(path: str | Path) -> str:
    """Hex SHA-256 of the file's bytes (64 digits)."""
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


@functools.lru_cache(maxsize=64)
def _cached(path: str, size: int, mtime_ns: int) -> str:
    return file_sha256(path)


def cached_file_sha256(path: str | Path) -> str:
    """:func:`file_sha256`, read once per process for each path, size and modification time."""
    st = Path(path).stat()
    return _cached(str(Path(path).resolve()), st.st_size, st.st_mtime_ns)
