"""Starting participants: a Prolific-like burst (200 addresses in one minute) all admitted, a scripted flood from
one address slowed with 429 + Retry-After (studyapp.participant.start_throttle), the session key renewed at consent, and
a stale started participant's place freed by the default abandon time."""
from __future__ import annotations

import time

import pytest
from django.core.cache import cache
from django.test import Client
from django.urls import reverse

from studyapp.models import DEFAULT_ABANDON_MINUTES, Participant, Study
from studyapp.participant import start_throttle
from studyapp.staff.presets import create_study_from_preset

pytestmark = pytest.mark.django_db


@pytest.fixture
def study(settings):
    settings.START_RATE_BURST = 6
    settings.START_RATE_INTERVAL_S = 20
    cache.clear()
    return create_study_from_preset("rbf_thms2016", "rate", plan="test", status=Study.Status.OPEN)


def start(study, address: str, client: Client | None = None):
    return (client or Client()).post(reverse("studyapp:study_entry", args=[study.slug]),
                                     {"consent": "on", "PROLIFIC_PID": f"pid-{address}-{time.monotonic_ns()}"},
                                     REMOTE_ADDR=address)


def test_a_prolific_burst_of_200_addresses_in_a_minute_is_admitted(study):
    t0 = time.monotonic()
    codes = [start(study, f"10.{i // 250}.{i % 250}.7").status_code for i in range(200)]
    elapsed = time.monotonic() - t0
    assert elapsed < 60, f"200 starts took {elapsed:.1f} s: not a one-minute burst"
    assert codes == [302] * 200
    assert Participant.objects.filter(study=study).count() == 200


def test_a_flood_from_one_address_is_slowed(study, monkeypatch):
    now = [1_000_000.0]
    monkeypatch.setattr(start_throttle.time, "time", lambda: now[0])
    codes = [start(study, "203.0.113.9").status_code for _ in range(20)]
    assert codes == [302] * 6 + [429] * 14
    refused = start(study, "203.0.113.9")
    assert refused.status_code == 429 and 1 <= int(refused["Retry-After"]) <= 20
    assert b"Please wait" in refused.content
    assert start(study, "198.51.100.1").status_code == 302          # another address is not affected
    now[0] += 20
    assert start(study, "203.0.113.9").status_code == 302          # one more per interval
    assert start(study, "203.0.113.9").status_code == 429
    assert Participant.objects.filter(study=study).count() == 8


def test_the_limit_reads_the_forwarded_address_behind_a_trusted_proxy(study, settings):
    settings.TRUSTED_PROXY_COUNT = 1
    for i in range(20):                                   # one proxy address, twenty clients behind it
        r = Client().post(reverse("studyapp:study_entry", args=[study.slug]), {"consent": "on"},
                          REMOTE_ADDR="127.0.0.1", HTTP_X_FORWARDED_FOR=f"192.0.2.{i + 1}")
        assert r.status_code == 302


def test_session_key_changes_at_consent(study):
    client = Client()
    client.get(reverse("studyapp:study_entry", args=[study.slug]))
    planted = client.session.session_key
    assert planted
    r = start(study, "192.0.2.50", client)
    assert r.status_code == 302
    assert client.session.session_key != planted
    # the new session still knows its participant: the consent page resumes instead of starting again
    again = client.get(reverse("studyapp:study_entry", args=[study.slug]))
    assert again.status_code == 302 and "/p/" in again["Location"]


def test_new_studies_free_stale_places_by_default(study):
    assert DEFAULT_ABANDON_MINUTES > 0 and study.abandon_after_minutes == DEFAULT_ABANDON_MINUTES
