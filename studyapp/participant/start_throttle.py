"""A start rate limit per client address: how fast one address may consent new participants into studies.

Generic cell rate (GCRA, a token bucket kept as one timestamp per address): an address may start ``burst``
participants at once, then one every ``interval_s`` seconds (settings.START_RATE_BURST, START_RATE_INTERVAL_S; burst
0 turns the limit off). A Prolific launch, where each participant has an address of their own, never meets it (200
starts in one minute from 200 addresses: docs/benchmarks/study.md, "Start rate limit"); a script filling a study from
one address gets ``burst`` places, then one per interval, and a 429 page with Retry-After in between. Only a consent
that would create a participant counts; a participant resuming never does. The address is
studyapp.login_throttle.client_ip (X-Forwarded-For behind TRUSTED_PROXY_COUNT proxies).

The state is Django's cache (CACHES): shared by every process when the deployment configures a shared cache, per
process with the default local-memory cache (then each worker process admits its own burst).
"""
from __future__ import annotations

import math
import threading
import time

from django.conf import settings
from django.core.cache import cache

from ..login_throttle import client_ip

_lock = threading.Lock()
KEY = "studyapp:start-rate:{}"


def limits() -> tuple[int, float]:
    """(burst, interval in seconds) from the settings."""
    return int(getattr(settings, "START_RATE_BURST", 6)), float(getattr(settings, "START_RATE_INTERVAL_S", 20.0))


def admit(request, now: float | None = None) -> float:
    """Count one start from the request's address: 0.0 when admitted, else the seconds until one would be
    (nothing is counted for a refused start)."""
    burst, interval = limits()
    if burst <= 0 or interval <= 0:
        return 0.0
    address = client_ip(request) or "unknown"
    key = KEY.format(address)
    now = time.time() if now is None else now
    with _lock:                         # one process at a time; another process may race by one start at most
        tat = max(float(cache.get(key) or 0.0), now)     # theoretical arrival time of the next start
        wait = tat - now - (burst - 1) * interval
        if wait > 0:
            return wait
        cache.set(key, tat + interval, timeout=math.ceil(burst * interval) + 1)
    return 0.0
