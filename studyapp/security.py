"""Small security pieces that need no extra package:

- `ContentSecurityPolicyMiddleware`: a Content-Security-Policy on every response (no inline script or style: every
  script and style sheet is a file under static/), and a Permissions-Policy that turns off the browser features
  the site never uses (camera, microphone, location, sensors, payment, USB, ...).
- `NoStoreMiddleware`: ``Cache-Control: no-store`` (and no caching at all) on every response under the admin and the
  researcher pages (settings.NO_STORE_PREFIXES, default /admin/ and /staff/): exports, reports, payment ids and
  the pages showing participants' data are never kept by a browser or a proxy.
- `RedactTokensFilter`: a logging filter that blanks participant credentials (the /p/<token>/ path segment and the
  PROLIFIC_PID / STUDY_ID / SESSION_ID query values) in any log line, e.g. Django's "Not Found: /p/<token>/...".
- `redact()`: the same rewriting for one string (the gunicorn access logger of studyapp.gunicorn_logging uses it).
"""
from __future__ import annotations

import logging
import re

from django.conf import settings
from django.utils.cache import add_never_cache_headers

CONTENT_SECURITY_POLICY = "; ".join([
    "default-src 'self'",
    "script-src 'self'",
    "style-src 'self'",
    "img-src 'self' data:",
    "media-src 'self'",
    "font-src 'self'",
    "connect-src 'self'",
    "object-src 'none'",
    "base-uri 'none'",
    "frame-ancestors 'none'",
    "form-action 'self'",
])

POLICY_FEATURES_OFF = ("accelerometer", "camera", "display-capture", "geolocation", "gyroscope", "hid",
                       "magnetometer", "microphone", "midi", "payment", "serial", "usb", "xr-spatial-tracking")
"""Features turned off: only names browsers recognise (an unknown one, such as ambient-light-sensor or bluetooth,
is a console warning on every page in Chromium)."""

PERMISSIONS_POLICY = ", ".join([
    *(f"{feature}=()" for feature in POLICY_FEATURES_OFF),
    # the clip player may go full screen and play on its own page
    "autoplay=(self)", "fullscreen=(self)", "picture-in-picture=(self)",
])

SECRET_PARAMS = ("PROLIFIC_PID", "STUDY_ID", "SESSION_ID", "token")
_PATH_TOKEN = re.compile(r"(/p/)[^/?#\s\"]+")
_QUERY_SECRET = re.compile(r"(?i)\b(" + "|".join(SECRET_PARAMS) + r")=[^&#\s\"]*")


def redact(text: str) -> str:
    """`text` with the participant token of /p/<token>/ URLs and the Prolific query values replaced by '***'."""
    if not text or not isinstance(text, str):
        return text
    return _QUERY_SECRET.sub(r"\1=***", _PATH_TOKEN.sub(r"\1***", text))


class RedactTokensFilter(logging.Filter):
    """Rewrites a record's message (and string arguments) with `redact`; never drops a record."""

    def filter(self, record: logging.LogRecord) -> bool:
        """Redact the record's message and string arguments in place; always True (the record is kept)."""
        if isinstance(record.msg, str):
            record.msg = redact(record.msg)
        if isinstance(record.args, tuple):
            record.args = tuple(redact(a) if isinstance(a, str) else a for a in record.args)
        elif isinstance(record.args, dict):
            record.args = {k: redact(v) if isinstance(v, str) else v for k, v in record.args.items()}
        return True


class ContentSecurityPolicyMiddleware:
    """Adds settings.CONTENT_SECURITY_POLICY and settings.PERMISSIONS_POLICY (defaults above) unless the view
    already set that header; an empty setting leaves its header out."""

    def __init__(self, get_response):
        self.get_response = get_response
        self.headers = {"Content-Security-Policy": getattr(settings, "CONTENT_SECURITY_POLICY",
                                                           CONTENT_SECURITY_POLICY),
                        "Permissions-Policy": getattr(settings, "PERMISSIONS_POLICY", PERMISSIONS_POLICY)}

    def __call__(self, request):
        response = self.get_response(request)
        for header, policy in self.headers.items():
            if policy and header not in response:
                response[header] = policy
        return response


NO_STORE_PREFIXES = ("/admin/", "/staff/")


class NoStoreMiddleware:
    """Marks every response below settings.NO_STORE_PREFIXES (default NO_STORE_PREFIXES) not to be stored:
    ``Cache-Control: max-age=0, no-cache, no-store, must-revalidate, private`` (django.utils.cache's never-cache
    headers), whatever the view set."""

    def __init__(self, get_response):
        self.get_response = get_response
        self.prefixes = tuple(getattr(settings, "NO_STORE_PREFIXES", NO_STORE_PREFIXES))

    def __call__(self, request):
        response = self.get_response(request)
        if request.path.startswith(self.prefixes):
            if "Cache-Control" in response:
                del response["Cache-Control"]
            add_never_cache_headers(response)
        return response
