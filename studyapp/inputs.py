"""Control characters never reach the database.

PostgreSQL refuses a NUL in any text value (a 500 where SQLite stored it), and the other control characters have
no place in an id, a token or an answer. ``ControlCharacterMiddleware`` answers 400 before any view (and before
the session lookup) when the path, a query value, a form value or a cookie holds one; free-text form values may
keep tab, newline and carriage return. ``refuse_control_characters`` is the same check as a form-field validator.
"""
from __future__ import annotations

import re

from django.core.exceptions import ValidationError
from django.http import HttpResponseBadRequest
from django.utils.translation import gettext_lazy as _

# C0 controls, DEL and C1 controls (Unicode category Cc).
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")
_CONTROL_BUT_WHITESPACE = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f]")

CONTROL_MESSAGE = _("This field holds a control character (such as NUL), which is not allowed.")
BAD_REQUEST_TEXT = ("The request holds a control character (such as NUL) in its address, a form field or a "
                    "cookie. Please open the study again from its link.")


def has_control_character(value: str, allow_whitespace: bool = False) -> bool:
    """True when ``value`` holds a control character; allow_whitespace: tab, newline and CR do not count."""
    pattern = _CONTROL_BUT_WHITESPACE if allow_whitespace else _CONTROL
    return bool(pattern.search(value))


def refuse_control_characters(value) -> None:
    """Form-field validator: ValidationError for any control character (ids, tokens, one-line fields)."""
    if isinstance(value, str) and has_control_character(value):
        raise ValidationError(CONTROL_MESSAGE, code="control_character")


def refuse_control_characters_in_text(value) -> None:
    """Form-field validator for free text: tab, newline and CR are allowed, other control characters not."""
    if isinstance(value, str) and has_control_character(value, allow_whitespace=True):
        raise ValidationError(CONTROL_MESSAGE, code="control_character")


def request_has_control_character(request) -> str:
    """Where the request holds a control character ("path", "query", "form", "cookie"), or "" if nowhere."""
    if has_control_character(request.path_info):
        return "path"
    if any(has_control_character(k) or has_control_character(v) for k, values in request.GET.lists()
           for v in values):
        return "query"
    if request.method == "POST" and any(
            has_control_character(k) or has_control_character(v, allow_whitespace=True)
            for k, values in request.POST.lists() for v in values):
        return "form"
    if any(has_control_character(v) for v in request.COOKIES.values()):
        return "cookie"
    return ""


class ControlCharacterMiddleware:
    """400 (plain text, nothing echoed) for a request with a control character anywhere a view could read it."""

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        if request_has_control_character(request):
            return HttpResponseBadRequest(BAD_REQUEST_TEXT, content_type="text/plain; charset=utf-8")
        return self.get_response(request)
