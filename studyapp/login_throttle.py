"""Login throttling glue for django-axes: the client address behind a trusted proxy, the lockout page, and an
authentication backend that leaves request-less logins (scripts, tests) alone.

Failed admin logins are counted per account-and-address pair and per address (settings.AXES_LOCKOUT_PARAMETERS);
after LOGIN_FAILURE_LIMIT failures that account from that address, or that address for every account, is refused
for LOGIN_LOCKOUT_MINUTES without the password being checked (no hashing cost for a flood). The account itself is
never locked everywhere, so failures from one address cannot lock its owner out from another. Participants
never log in, so nothing here touches them.
"""
from __future__ import annotations

from axes.backends import AxesStandaloneBackend
from django.conf import settings
from django.shortcuts import render

LOCKED_MESSAGE = ("Too many failed logins from this address: logging in is locked for now.")


def client_ip(request) -> str | None:
    """The client's address: REMOTE_ADDR, or with TRUSTED_PROXY_COUNT = n > 0 (the app behind n proxies, e.g.
    nginx with ``X-Forwarded-For $proxy_add_x_forwarded_for``) the n-th address from the right of
    X-Forwarded-For, the one the outermost trusted proxy saw; entries further left are the client's own claims."""
    n = getattr(settings, "TRUSTED_PROXY_COUNT", 0)
    if n > 0:
        hops = [h.strip() for h in request.META.get("HTTP_X_FORWARDED_FOR", "").split(",") if h.strip()]
        if len(hops) >= n:
            return hops[-n]
    return request.META.get("REMOTE_ADDR")


def lockout_response(request, *args, **kwargs):
    """The page a locked-out login gets: status settings.AXES_HTTP_RESPONSE_CODE (429) with the message and the
    lockout time. django-axes calls it with (request, original_response, credentials) or (request, credentials)."""
    minutes = max(1, round(settings.AXES_COOLOFF_TIME.total_seconds() / 60))
    return render(request, "studyapp/staff/login_locked.html", {"message": LOCKED_MESSAGE, "minutes": minutes},
                  status=settings.AXES_HTTP_RESPONSE_CODE)


class ThrottledLoginBackend(AxesStandaloneBackend):
    """django-axes' lockout check for logins made through a request (the admin login form). A login without a
    request (``authenticate(username=..., password=...)`` in a script or the test client) has no address to
    throttle and is passed on to the next backend unchanged."""

    def authenticate(self, request, username=None, password=None, **kwargs):
        """django-axes' check for a login through a request; None (the next backend decides) for one without a
        request."""
        if request is None:
            return None
        return super().authenticate(request, username=username, password=password, **kwargs)
