"""Response bodies that stream under both servers: a file's byte range read block by block, and any synchronous
iterator (a CSV export's lines) handed on in batches.

Under WSGI (gunicorn's threaded workers behind nginx) a body is a plain iterator. Under ASGI (demo.sh's workers,
django.test.AsyncClient) Django would consume a synchronous iterator whole into a list before the first byte is
sent ("StreamingHttpResponse must consume synchronous iterators"): a 1 GiB clip, or each open-ended range request of
it, would sit in memory. There the body is an asynchronous iterator instead: a file is read in ASYNC_BLOCK pieces in
a worker thread (``asyncio.to_thread``: the event loop never waits on the disk) and only its range is read; a
synchronous iterator that reads the database is advanced in Django's thread for database work
(``sync_to_async``, thread-sensitive) a batch of about BATCH_BYTES at a time. Memory per response: one block.
"""
from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator, Iterable, Iterator
from pathlib import Path

from asgiref.sync import sync_to_async
from django.core.handlers.asgi import ASGIRequest

BLOCK = 64 * 1024
"""Bytes per read of a file under WSGI."""
ASYNC_BLOCK = 256 * 1024
"""Bytes per read of a file under ASGI (one thread hop each)."""
BATCH_BYTES = 64 * 1024
"""About this many bytes of a synchronous iterator's output per thread hop under ASGI."""


def is_asgi(request) -> bool:
    """Whether the request is served by Django's ASGI handler (its response bodies should be async)."""
    return isinstance(request, ASGIRequest)


def iter_file(path: Path, start: int, length: int, block: int = BLOCK) -> Iterator[bytes]:
    """``length`` bytes of ``path`` from ``start``, ``block`` bytes at a time (fewer if the file is shorter)."""
    with open(path, "rb") as fh:
        fh.seek(start)
        remaining = length
        while remaining > 0:
            chunk = fh.read(min(block, remaining))
            if not chunk:
                break
            remaining -= len(chunk)
            yield chunk


async def aiter_file(path: Path, start: int, length: int, block: int = ASYNC_BLOCK) -> AsyncIterator[bytes]:
    """:func:`iter_file` as an async iterator: each read runs in a worker thread; the file is closed when the
    iteration ends or is abandoned (a client that disconnects)."""
    fh = await asyncio.to_thread(open, path, "rb")
    try:
        await asyncio.to_thread(fh.seek, start)
        remaining = length
        while remaining > 0:
            chunk = await asyncio.to_thread(fh.read, min(block, remaining))
            if not chunk:
                break
            remaining -= len(chunk)
            yield chunk
    finally:
        await asyncio.to_thread(fh.close)


def file_body(request, path: Path, start: int, length: int):
    """The body of a response sending ``length`` bytes of ``path`` from ``start``: async under ASGI."""
    return aiter_file(path, start, length) if is_asgi(request) else iter_file(path, start, length)


def _batch(iterator: Iterator, size: int) -> bytes | str | None:
    """Up to about ``size`` bytes (or characters) of the iterator's next items joined; None when it is done."""
    parts, n = [], 0
    for part in iterator:
        parts.append(part)
        n += len(part)
        if n >= size:
            break
    if not parts:
        return None
    return b"".join(parts) if isinstance(parts[0], bytes) else "".join(parts)


async def aiter_sync(iterable: Iterable, size: int = BATCH_BYTES) -> AsyncIterator:
    """A synchronous iterable (e.g. CSV lines read from the database) as an async iterator of batches, each batch
    produced in Django's thread for synchronous work."""
    iterator = iter(iterable)
    next_batch = sync_to_async(_batch, thread_sensitive=True)
    while (batch := await next_batch(iterator, size)) is not None:
        yield batch


def body(request, iterable: Iterable):
    """A streaming response's body from a synchronous iterable: itself under WSGI, batched and async under ASGI."""
    return aiter_sync(iterable) if is_asgi(request) else iterable
