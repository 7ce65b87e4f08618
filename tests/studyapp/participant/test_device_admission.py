"""A study's minimum viewport and the kinds of device it admits: checked when the participant consents (the
browser's report, else the User-Agent), recorded on the participant, and a clear page for those turned away."""
from __future__ import annotations

import pytest
from django.core.exceptions import ValidationError
from django.test import Client
from django.urls import reverse

from studyapp.models import Participant, Study
from studyapp.participant.device_check import device_record, kind_from_user_agent, min_viewport, refusal
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db

IPHONE = ("Mozilla/5.0 (iPhone; CPU iPhone OS 17_5 like Mac OS X) AppleWebKit/605.1.15 (KHTML, like Gecko) "
          "Version/17.5 Mobile/15E148 Safari/604.1")
ANDROID_PHONE = ("Mozilla/5.0 (Linux; Android 14; Pixel 8) AppleWebKit/537.36 (KHTML, like Gecko) "
                 "Chrome/126.0 Mobile Safari/537.36")
ANDROID_TABLET = ("Mozilla/5.0 (Linux; Android 14; SM-X710) AppleWebKit/537.36 (KHTML, like Gecko) "
                  "Chrome/126.0 Safari/537.36")
IPAD = ("Mozilla/5.0 (iPad; CPU OS 17_5 like Mac OS X) AppleWebKit/605.1.15 (KHTML, like Gecko) Version/17.5 "
        "Safari/604.1")
DESKTOP = "Mozilla/5.0 (X11; Linux x86_64) AppleWebKit/537.36 (KHTML, like Gecko) Chrome/126.0 Safari/537.36"


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    return create_study_from_preset("gait_ismar2020", "screens", plan="test", status=Study.Status.OPEN)


def consent(study: Study, ua: str = DESKTOP, **device) -> tuple:
    client = Client(HTTP_USER_AGENT=ua)
    url = reverse("studyapp:study_entry", args=[study.slug])
    client.get(url)
    return client.post(url, {"consent": "on", **device})


@pytest.mark.parametrize("ua, kind", [(IPHONE, "phone"), (ANDROID_PHONE, "phone"), (ANDROID_TABLET, "tablet"),
                                      (IPAD, "tablet"), (DESKTOP, "desktop"), ("", "desktop")])
def test_kind_from_user_agent(ua, kind):
    assert kind_from_user_agent(ua) == kind


def test_defaults_admit_every_device_and_record_it(study):
    r = consent(study, IPHONE, viewport_w="390", viewport_h="664", device_kind="phone")
    assert r.status_code == 302
    p = Participant.objects.get()
    assert (p.viewport_width, p.viewport_height, p.device_kind) == (390, 664, "phone")
    assert min_viewport(study) == (320, 300)


def test_phones_turned_away_with_a_clear_page_and_nothing_recorded(study):
    study.admit_phones = False
    study.save()
    page = consent(study, DESKTOP, viewport_w="390", viewport_h="664", device_kind="phone")      # the script says
    assert page.status_code == 200 and 'id="device-refused"' in page.content.decode()
    text = page.content.decode()
    assert "cannot be taken on a phone" in text and "computer or a tablet" in text
    assert "Nothing has been recorded" in text
    page = consent(study, IPHONE)                                   # no script: the User-Agent says
    assert "cannot be taken on a phone" in page.content.decode()
    assert not Participant.objects.exists()
    assert consent(study, IPAD).status_code == 302                  # tablets still admitted
    study.admit_tablets = False
    study.save()
    assert "cannot be taken on a tablet" in consent(study, ANDROID_TABLET).content.decode()
    assert Participant.objects.count() == 1


def test_minimum_viewport_checked_and_shown_to_the_script(study):
    study.min_viewport_width, study.min_viewport_height = 1200, 700
    study.save()
    page = Client().get(reverse("studyapp:study_entry", args=[study.slug])).content.decode()
    assert 'data-min-width="1200"' in page and 'data-min-height="700"' in page
    assert 'data-admits="desktop|tablet|phone"' in page and 'name="viewport_w"' in page
    refused = consent(study, viewport_w="1000", viewport_h="700", device_kind="desktop").content.decode()
    assert "at least 1200 × 700 pixels" in refused and "shows 1000 × 700" in refused
    assert consent(study, viewport_w="1366", viewport_h="768", device_kind="desktop").status_code == 302
    assert Participant.objects.get().viewport_width == 1366
    # not reported (no script), or nonsense: not checked, not stored
    assert consent(study, viewport_w="9e9", viewport_h="-1", device_kind="toaster").status_code == 302
    assert Participant.objects.filter(viewport_width__isnull=True, device_kind="desktop").count() == 1


def test_study_minimum_is_bounded(study):
    study.min_viewport_width = 5000
    with pytest.raises(ValidationError):
        study.full_clean()


def test_refusal_rules():
    study = Study(admit_phones=True, admit_tablets=True, min_viewport_width=0, min_viewport_height=0)
    record = device_record({"viewport_w": "300", "viewport_h": "500", "device_kind": "phone"}, "")
    assert "at least 320 × 300" in refusal(study, record)              # the player's own minimum holds
    assert refusal(study, {**record, "viewport_width": 320}) is None


def test_admin_shows_the_recorded_device(study, django_user_model):
    consent(study, viewport_w="1366", viewport_h="768", device_kind="desktop")
    p = Participant.objects.get()
    admin = django_user_model.objects.create_user("staff", password="pw-staff-12345", is_staff=True,
                                                  is_superuser=True)
    client = Client()
    client.force_login(admin)
    page = client.get(reverse("admin:studyapp_participant_change", args=[p.pk])).content.decode()
    assert "1366" in page and "768" in page and "Desktop" in page
