"""Clip files served with HTTP Range support under opaque URLs.

Django's FileResponse ignores `Range`; Safari will not play an MP4 without byte ranges, and no browser can seek
without them. `ranged_file_response` answers `Range: bytes=a-b` (single range; suffix and open-ended forms) with
206 + Content-Range, an unsatisfiable range with 416, and anything else with the whole file (200). The body is
streamed block by block and reads only the requested range (studyapp.participant.streaming: an async iterator under
ASGI, so no body is ever held whole in memory). Every answer carries an ETag (size and modification time) and
Last-Modified: a revalidation with a matching If-None-Match (or, without one, an If-Modified-Since not older than the
file) gets 304 with no body, and an If-Range that no longer matches turns a range request into the whole file.

Behind nginx (settings.MEDIA_ACCEL_REDIRECT, e.g. "/protected-media/"), `accel_redirect_response` answers instead
with an empty 200 carrying `X-Accel-Redirect: /protected-media/<path below MEDIA_ROOT>`: nginx then serves the file
from its `internal` location (Range, ETag/Last-Modified, 304 and sendfile by nginx), so no application thread is
held while a slow player downloads. See deploy/nginx/study.conf and docs/deploy.md.
"""
from __future__ import annotations

import mimetypes
import os
import re
from pathlib import Path
from urllib.parse import quote

from django.conf import settings
from django.http import Http404, HttpResponse, StreamingHttpResponse
from django.utils.http import http_date, parse_http_date_safe

from .streaming import file_body

RANGE_RE = re.compile(r"^bytes=(\d*)-(\d*)$")
CONTENT_TYPES = {".mp4": "video/mp4", ".webm": "video/webm", ".png": "image/png", ".jpg": "image/jpeg"}


def media_root() -> Path:
    return Path(settings.MEDIA_ROOT).resolve()


def media_path(relative: str) -> Path:
    """Absolute path of a catalogue media path, refusing anything outside MEDIA_ROOT."""
    root = media_root()
    path = (root / relative).resolve()
    if root not in path.parents or not path.is_file():
        raise Http404("clip file not found")
    return path


def parse_range(header: str, size: int) -> tuple[int, int] | None:
    """(start, end inclusive) for a single byte range, None when the header is absent or not a simple range.
    Raises ValueError when the range cannot be satisfied."""
    m = RANGE_RE.match(header.strip()) if header else None
    if not m or (m.group(1) == "" and m.group(2) == ""):
        return None
    first, last = m.group(1), m.group(2)
    if first == "":                      # suffix: the last N bytes
        n = int(last)
        if n == 0:
            raise ValueError("empty suffix range")
        return max(0, size - n), size - 1
    start = int(first)
    end = size - 1 if last == "" else min(int(last), size - 1)
    if start >= size or end < start:
        raise ValueError("range not satisfiable")
    return start, end


def file_etag(stat: os.stat_result) -> str:
    """A strong validator of a file's version: its size and modification time in nanoseconds."""
    return f'"{stat.st_size:x}-{stat.st_mtime_ns:x}"'


def _etag_matches(header: str, etag: str) -> bool:
    tags = [t.strip() for t in header.split(",")]
    return "*" in tags or etag in tags or f"W/{etag}" in tags


def not_modified(request, etag: str, mtime: float) -> bool:
    """True when the client's cached copy is current (RFC 9110: If-None-Match wins over If-Modified-Since)."""
    inm = request.headers.get("If-None-Match")
    if inm is not None:
        return _etag_matches(inm, etag)
    since = parse_http_date_safe(request.headers.get("If-Modified-Since", ""))
    return since is not None and int(mtime) <= since


def _validators(response, etag: str, last_modified: str):
    response["ETag"] = etag
    response["Last-Modified"] = last_modified
    # revalidated on every use: a clip stops playing for a participant once it is answered (views.media_allowed)
    response["Cache-Control"] = "private, no-cache"
    return response


def ranged_file_response(request, path: Path, content_type: str | None = None):
    stat = path.stat()
    size = stat.st_size
    content_type = content_type or CONTENT_TYPES.get(path.suffix.lower()) or (
        mimetypes.guess_type(path.name)[0] or "application/octet-stream")
    mtime = http_date(stat.st_mtime)
    etag = file_etag(stat)
    if request.method in ("GET", "HEAD") and not_modified(request, etag, stat.st_mtime):
        return _validators(HttpResponse(status=304), etag, mtime)
    range_header = request.headers.get("Range", "")
    if_range = request.headers.get("If-Range", "").strip()
    if range_header and if_range and if_range != etag and if_range != mtime:
        range_header = ""                # the file changed since the client's partial copy: send it whole
    try:
        rng = parse_range(range_header, size)
    except ValueError:
        response = HttpResponse(status=416)
        response["Content-Range"] = f"bytes */{size}"
        return response
    if request.method == "HEAD":
        response = HttpResponse(content_type=content_type)
        response["Content-Length"] = str(size)
    elif rng is None:
        response = StreamingHttpResponse(file_body(request, path, 0, size), content_type=content_type)
        response["Content-Length"] = str(size)
    else:
        start, end = rng
        response = StreamingHttpResponse(file_body(request, path, start, end - start + 1), status=206,
                                         content_type=content_type)
        response["Content-Length"] = str(end - start + 1)
        response["Content-Range"] = f"bytes {start}-{end}/{size}"
    response["Accept-Ranges"] = "bytes"
    return _validators(response, etag, mtime)


def accel_redirect_response(path: Path, prefix: str, content_type: str | None = None) -> HttpResponse:
    """An empty response telling nginx to serve ``path`` (a file below MEDIA_ROOT, already checked by media_path)
    from its internal location ``prefix`` (which nginx maps to MEDIA_ROOT). The path is percent-encoded; nginx
    decodes it once. Content-Type is the app's choice (nginx would otherwise guess it from its mime.types)."""
    relative = path.relative_to(media_root()).as_posix()
    response = HttpResponse(content_type=content_type or CONTENT_TYPES.get(path.suffix.lower()) or (
        mimetypes.guess_type(path.name)[0] or "application/octet-stream"))
    response["X-Accel-Redirect"] = prefix + quote(relative, safe="/")
    return response

