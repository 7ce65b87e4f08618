"""Completion URLs (Study.completion_redirect): only http(s) addresses are accepted and ever rendered as a link or a
refresh, so a ``javascript:``, ``data:`` or other scheme can never run in a participant's browser."""
from __future__ import annotations

from django.core.exceptions import ValidationError
from django.core.validators import URLValidator

CODE_PLACEHOLDER = "{code}"
_URL = URLValidator(schemes=["http", "https"])


def check_completion_url(value: str) -> None:
    """Raise ValidationError with a clear message unless ``value`` (with {code} in place of the completion code)
    is an absolute http:// or https:// URL; an empty value is fine (no completion URL)."""
    if not value:
        return
    scheme = value.split(":", 1)[0].strip().lower() if ":" in value else ""
    if scheme not in ("http", "https"):
        raise ValidationError(
            "The completion URL must start with https:// or http:// (got %(scheme)s); other kinds of link, such "
            "as javascript: or data:, are refused.", code="scheme",
            params={"scheme": f"'{scheme[:20]}:'" if scheme else "no scheme"})
    try:
        _URL(value.replace(CODE_PLACEHOLDER, "CODE"))
    except ValidationError:
        raise ValidationError("The completion URL is not a valid web address, e.g. "
                              "https://app.prolific.com/submissions/complete?cc={code}", code="invalid") from None


def safe_completion_url(url: str) -> str:
    """``url`` when it passes check_completion_url, else "" (a row saved before the check was added)."""
    try:
        check_completion_url(url)
    except ValidationError:
        return ""
    return url
