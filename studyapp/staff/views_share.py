"""The shared preview: a study as participants see it, opened through a signed, expiring link (studyapp.staff.sharing)
by anyone, without an account; answers are checked like a participant's and never stored, and nothing is kept in
a session. Clip labels (which name no condition but are the researcher's) are not shown."""
from __future__ import annotations

from datetime import UTC, datetime

from django.http import Http404
from django.shortcuts import render
from django.urls import reverse
from django.views.decorators.cache import never_cache
from django.views.decorators.http import require_http_methods

from ..i18n import activate_study_language
from ..participant.forms import ConsentForm
from .sharing import PreviewLinkError, study_of_token
from .views import _preview_plan, _preview_seed, preview_page


def _study(token: str):
    try:
        return study_of_token(token)
    except PreviewLinkError as exc:
        raise Http404(str(exc)) from None


@never_cache
def shared_preview(request, token: str):
    """The shared preview's consent page for a valid link (else 404), in the study's language, saying when the link
    expires."""
    study, expires = _study(token)
    activate_study_language(study)
    seed = _preview_seed(request)
    start = reverse("studyapp:shared_preview_item", args=[token, 1]) + f"?seed={seed}"
    return render(request, "studyapp/shared_preview.html", {
        "study": study, "form": ConsentForm(), "preview": True, "seed": seed, "start_url": start,
        "expires": datetime.fromtimestamp(expires, UTC)})      # (the researcher's page says when it expires)


@never_cache
@require_http_methods(["GET", "POST"])
def shared_preview_item(request, token: str, n: int):
    """Clip page n of the shared preview, answers checked and never stored; past the last page a done page offers a run
    with the next seed."""
    study, _ = _study(token)
    activate_study_language(study)
    seed = _preview_seed(request)
    flat = _preview_plan(study, seed)
    again = reverse("studyapp:shared_preview", args=[token]) + f"?seed={seed + 1}"
    if n < 1 or n > len(flat):
        return render(request, "studyapp/shared_preview_done.html", {"study": study, "preview": True,
                                                                      "again_url": again})
    here = reverse("studyapp:shared_preview_item", args=[token, n]) + f"?seed={seed}"
    after = reverse("studyapp:shared_preview_item", args=[token, n + 1]) + f"?seed={seed}"
    return preview_page(request, study, flat, n, seed, here, after, {})
