"""Sharing a study: a signed, expiring preview link anyone can open without an account (django.core.signing; the
preview records nothing, studyapp.staff.views_share), and the Prolific study URL with its placeholders.

A preview token is ``signing.dumps({"study": pk, "exp": epoch seconds})`` with the salt PREVIEW_SALT: it cannot be
forged or altered without SECRET_KEY, and it is refused after ``exp``. Nothing is stored on the server.
"""
from __future__ import annotations

import time
from urllib.parse import urlencode

from django.core import signing
from django.urls import reverse

from ..models import Study

PREVIEW_SALT = "studyapp.shared-preview"
MAX_DAYS = 90
PROLIFIC_PLACEHOLDERS = {"PROLIFIC_PID": "{{%PROLIFIC_PID%}}", "STUDY_ID": "{{%STUDY_ID%}}",
                         "SESSION_ID": "{{%SESSION_ID%}}"}
"""The study URL's query parameters as Prolific fills them in (its "URL parameters" option)."""


class PreviewLinkError(ValueError):
    """A preview token that is forged, altered, expired or names no study."""


def preview_token(study: Study, days: float, now: float | None = None) -> str:
    """A token for ``study``'s shared preview, valid for ``days`` (0 < days <= MAX_DAYS)."""
    if not 0 < days <= MAX_DAYS:
        raise ValueError(f"a preview link lasts between a day and {MAX_DAYS} days, got {days}")
    expires = int((time.time() if now is None else now) + days * 86400)
    return signing.dumps({"study": study.pk, "exp": expires}, salt=PREVIEW_SALT, compress=True)


def study_of_token(token: str, now: float | None = None) -> tuple[Study, int]:
    """(study, expiry in epoch seconds) of a valid token; PreviewLinkError otherwise."""
    try:
        data = signing.loads(token, salt=PREVIEW_SALT)
    except signing.BadSignature:
        raise PreviewLinkError("this preview link is not valid") from None
    if not isinstance(data, dict) or not isinstance(data.get("exp"), int) or not isinstance(data.get("study"), int):
        raise PreviewLinkError("this preview link is not valid")
    if data["exp"] < (time.time() if now is None else now):
        raise PreviewLinkError("this preview link has expired: ask the researcher for a new one")
    study = Study.objects.filter(pk=data["study"]).first()
    if study is None:
        raise PreviewLinkError("the study of this preview link no longer exists")
    return study, data["exp"]


def prolific_study_url(request, study: Study) -> str:
    """The URL to paste into Prolific's study settings: the study's entry page with Prolific's placeholders (kept
    unescaped: Prolific replaces them literally)."""
    base = request.build_absolute_uri(reverse("studyapp:study_entry", args=[study.slug]))
    return base + "?" + "&".join(f"{k}={v}" for k, v in PROLIFIC_PLACEHOLDERS.items())


def prolific_completion_url(study: Study) -> str:
    """Prolific's completion URL for the study's code (what the end page sends participants to)."""
    return "https://app.prolific.com/submissions/complete?" + urlencode({"cc": study.completion_code})
