"""Completion URLs are http(s) only, CSV cells are checked for formulas after NFKC normalisation, HEAD is answered
on participant pages and /healthz, every response carries a Permissions-Policy."""
from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.test import Client
from django.urls import reverse

from studyapp.data.export import safe_cell
from studyapp.models import Assignment, Participant, Study
from studyapp.participant.assignment import current_step, start_participant
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import admin_form_data, make_catalogue

pytestmark = pytest.mark.django_db

BAD_URLS = ["javascript:alert(document.cookie)", " JavaScript:alert(1)", "data:text/html,<script>x</script>",
            "vbscript:msgbox", "//evil.example/complete", "ftp://files.example/x", "https://"]
GOOD_URLS = ["https://app.prolific.com/submissions/complete?cc={code}", "http://localhost:8000/thanks?c={code}"]


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    return create_study_from_preset("demo", "demo", plan="test", status=Study.Status.OPEN)


@pytest.mark.parametrize("url", BAD_URLS)
def test_model_refuses_non_http_completion_urls(study, url):
    study.completion_redirect = url
    with pytest.raises(ValidationError) as info:
        study.full_clean()
    message = " ".join(info.value.message_dict["completion_redirect"])
    assert "https://" in message


@pytest.mark.parametrize("url", GOOD_URLS)
def test_model_accepts_http_completion_urls(study, url):
    study.completion_redirect = url
    study.full_clean()


def test_admin_form_shows_the_error(study):
    admin = Client()
    admin.force_login(User.objects.create_superuser("boss", password="pw-boss-1"))
    url = reverse("admin:studyapp_study_change", args=[study.pk])
    data = admin_form_data(admin.get(url))
    data["completion_redirect"] = "javascript:alert(1)"
    r = admin.post(url, data)
    assert r.status_code == 200
    assert "The completion URL must start with https:// or http:// (got &#x27;javascript:&#x27;)" in r.content.decode()
    study.refresh_from_db()
    assert study.completion_redirect == ""


def test_an_unsafe_url_saved_earlier_is_never_rendered(study):
    Study.objects.filter(pk=study.pk).update(completion_redirect="javascript:alert(1)", redirect_automatically=True)
    p = Participant.objects.create(study=study, status=Participant.Status.COMPLETED)
    page = Client().get(reverse("studyapp:done", args=[p.token])).content.decode()
    assert "javascript:" not in page and "completion-link" not in page and "refresh" not in page


@pytest.mark.parametrize("cell", ["＝HYPERLINK(\"http://x\")", "＋1+2", "－1+2", "＠SUM(A1)", "－７", "-７",
                                  "=1", "+cmd", "@x", "\tx"])
def test_formula_cells_are_quoted_after_nfkc(cell):
    assert safe_cell(cell) == "'" + cell


@pytest.mark.parametrize("cell", ["-7", "-0.25", "+3e5", "７", "ｈａｐｐｙ", "happy", 4, -2.5])
def test_plain_cells_stay(cell):
    assert safe_cell(cell) == cell


def test_head_is_answered_on_participant_pages(study):
    client = Client()
    assert client.head("/healthz").status_code == 200
    assert client.head(reverse("studyapp:study_entry", args=[study.slug])).status_code == 200
    p = Participant.objects.create(study=study, demographics_done=True, gender="female", age_group="18-24")
    start_participant(p)
    step = current_step(p)
    for url in (reverse("studyapp:resume", args=[p.token]), reverse("studyapp:demographics", args=[p.token]),
                reverse("studyapp:feedback", args=[p.token]), reverse("studyapp:done", args=[p.token])):
        assert client.head(url).status_code in (200, 302), url
    item = reverse("studyapp:item", args=[p.token, step.index])
    r = client.head(item)
    assert r.status_code == 200 and r.content == b""
    # a HEAD shows nothing, so it does not start the clip's response-time clock
    assert Assignment.objects.get(pk=step.assignment.pk).shown_at is None
    assert client.get(item).status_code == 200
    assert Assignment.objects.get(pk=step.assignment.pk).shown_at is not None


def test_permissions_policy_on_every_response(study):
    client = Client()
    for url in ("/healthz", reverse("studyapp:study_entry", args=[study.slug]), "/admin/login/", "/nowhere"):
        policy = client.get(url)["Permissions-Policy"]
        assert "camera=()" in policy and "microphone=()" in policy and "geolocation=()" in policy, url
        # Chromium warns on every page about a feature it does not know
        assert "ambient-light-sensor" not in policy and "bluetooth" not in policy, url
