"""A liveness probe: GET (or HEAD, as uptime monitors send) /healthz answers "ok" without touching the database
or the session.

Load balancers poll it, and benchmarks/bench_study_load.py uses it as the requests/s ceiling of the stack (the
cost of a request through gunicorn and Django's middleware with no view work at all).
"""
from __future__ import annotations

from django.http import HttpResponse
from django.views.decorators.cache import never_cache
from django.views.decorators.http import require_safe


@never_cache
@require_safe
def healthz(request):
    return HttpResponse("ok", content_type="text/plain; charset=utf-8")
