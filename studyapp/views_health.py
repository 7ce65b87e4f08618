"""A liveness probe, and the server-error page that tells a database outage from a bug.

GET (or HEAD, as uptime monitors send) /healthz answers "ok" without touching the database or the session. Load
balancers poll it, and benchmarks/bench_study_load.py uses it as the requests/s ceiling of the stack (the cost of a
request through gunicorn and Django's middleware with no view work at all).

``server_error`` is the app's handler500: when the request failed because no database connection could be had
(the pool's wait ran out, PostgreSQL refused a new connection or could not be reached, SQLite stayed locked) it
answers 503 with Retry-After, so a browser or a load balancer tries again; anything else, other database errors
included (a missing table, a failed password), gets Django's plain 500 page. Neither
shows a traceback, and neither touches the database or the session.
"""
from __future__ import annotations

import sys

from django.db import OperationalError
from django.http import HttpResponse, HttpResponsePermanentRedirect
from django.templatetags.static import static
from django.views import defaults
from django.views.decorators.cache import never_cache
from django.views.decorators.http import require_safe

RETRY_AFTER_S = 5
UNAVAILABLE_TEXT = ("The study server is busy right now. Please wait a few seconds and reload the page: your "
                    "answers so far are saved.")


@never_cache
@require_safe
def healthz(request):
    """/healthz: "ok" as plain text for GET or HEAD, never cached, without touching the database or the session."""
    return HttpResponse("ok", content_type="text/plain; charset=utf-8")


NO_CONNECTION_SQLSTATES = frozenset({"53300", "57P03"})
"""PostgreSQL's too_many_connections and cannot_connect_now (starting up, shutting down): whatever the server's
language."""
NO_CONNECTION_MESSAGES = (
    "couldn't get a connection",                    # psycopg_pool: the wait for a pooled connection ran out
    "too many clients",                             # PostgreSQL: max_connections reached
    "remaining connection slots are reserved",      # PostgreSQL: only superuser slots left
    "the database system is",                       # PostgreSQL: starting up, shutting down, in recovery
    "connection refused",                           # nothing listens at the address
    "is the server running",                        # libpq's hint when the server cannot be reached
    "could not connect",                            # libpq / psycopg 2
    "timeout expired",                              # libpq: connect_timeout ran out
    "database is locked",                           # SQLite: another writer held the lock past the timeout
)
"""Words of an OperationalError (lower case) that mean no connection could be had, not a fault of the query or of
the set-up. Not psycopg's "connection failed:" prefix alone: a missing database or role and a wrong password
carry it too."""


def _says_no_connection(exc: BaseException) -> bool:
    if type(exc).__name__ in {"PoolTimeout", "TooManyRequests"} and type(exc).__module__.startswith("psycopg_pool"):
        return True
    if getattr(exc, "sqlstate", None) in NO_CONNECTION_SQLSTATES:
        return True
    if isinstance(exc, OperationalError) or type(exc).__name__ == "OperationalError":    # Django's or a driver's
        text = str(exc).lower()
        return any(words in text for words in NO_CONNECTION_MESSAGES)
    return False


def database_unavailable(exc: BaseException | None) -> bool:
    """True when ``exc`` (or an exception it was raised from) says no database connection could be had: the
    pool's wait ran out (psycopg_pool.PoolTimeout, which Django wraps in its OperationalError), PostgreSQL refused
    a connection (too many clients, starting up) or could not be reached, or SQLite stayed locked. Any other
    OperationalError ("no such table", a failed password, a full disk) is a fault, not a busy server: False."""
    seen = 0
    while exc is not None and seen < 5:
        if _says_no_connection(exc):
            return True
        exc, seen = exc.__cause__ or exc.__context__, seen + 1
    return False


def unavailable_response() -> HttpResponse:
    """The 503 page of a database outage: UNAVAILABLE_TEXT with Retry-After (RETRY_AFTER_S seconds) and no-store."""
    response = HttpResponse(UNAVAILABLE_TEXT, status=503, content_type="text/plain; charset=utf-8")
    response["Retry-After"] = str(RETRY_AFTER_S)
    response["Cache-Control"] = "no-store"
    return response


def server_error(request, template_name: str = defaults.ERROR_500_TEMPLATE_NAME):
    """handler500: 503 + Retry-After for a database that could not be reached, else Django's 500 page."""
    if database_unavailable(sys.exc_info()[1]):
        return unavailable_response()
    return defaults.server_error(request, template_name)


@require_safe
def favicon(request):
    """/favicon.ico, which browsers ask for on pages that name no icon (the admin's): the static icon, resolved per
    request so that a missing static manifest never breaks the URL map."""
    return HttpResponsePermanentRedirect(static("studyapp/favicon.svg"))
