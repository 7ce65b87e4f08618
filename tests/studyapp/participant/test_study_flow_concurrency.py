"""Concurrent starts through the whole view stack, and the lock order that keeps PostgreSQL free of deadlocks.

Run these on PostgreSQL too (DATABASE_URL=postgres://...): there the starts really run at the same time, and the
test asserts that no start needed a deadlock/serialization retry (the retry is a safety net only; the ops helper's
load test had hit "deadlock detected" in starts before the count rows were locked in one (section, clip) order).
"""
from __future__ import annotations

import re
import threading
import traceback
from collections import Counter

import psycopg.errors
import pytest
from django.db import OperationalError, connection, transaction
from django.test import Client
from django.test.utils import CaptureQueriesContext
from django.urls import reverse

from studyapp.models import Assignment, Participant, SectionClipCount, Study
from studyapp.participant import assignment
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue


def _wrapped(cls, message: str) -> OperationalError:
    """A Django OperationalError caused by the psycopg 3 exception ``cls`` (as Django's wrapper raises it)."""
    try:
        try:
            raise cls(message)
        except psycopg.Error as inner:
            raise OperationalError(message) from inner
    except OperationalError as outer:
        return outer


def test_retryable_reads_the_psycopg3_sqlstate():
    assert assignment._retryable(_wrapped(psycopg.errors.DeadlockDetected, "deadlock detected"), "postgresql")
    assert assignment._retryable(_wrapped(psycopg.errors.SerializationFailure, "could not serialize access"),
                                 "postgresql")
    assert not assignment._retryable(_wrapped(psycopg.errors.QueryCanceled, "canceling statement"), "postgresql")
    assert assignment._retryable(OperationalError("database is locked"), "sqlite")
    assert not assignment._retryable(OperationalError("no such table: x"), "sqlite")


@pytest.mark.django_db
def test_count_rows_are_locked_in_section_clip_order(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("demo", "lock-order", plan="test", status=Study.Status.OPEN)
    sections = list(study.sections.filter(reuse_section__isnull=True))
    with transaction.atomic(), CaptureQueriesContext(connection) as q:
        assignment.read_counts(sections, lock=True)
    sql = q.captured_queries[-1]["sql"].upper()
    columns = re.match(r'SELECT "\w+"\."(\w+)".*?, "\w+"\."(\w+)"', sql).groups()
    positional = columns == ("SECTION_ID", "CLIP_ID") and re.search(r"ORDER BY 1 ASC, 2 ASC\b", sql)
    assert positional or re.search(r"ORDER BY \S*SECTION_ID\S* ASC, \S*CLIP_ID\S* ASC", sql), sql
    if connection.vendor == "postgresql":
        assert sql.rstrip().endswith("FOR NO KEY UPDATE"), sql


def _consented(study: Study) -> tuple[Client, str]:
    """A client that consented (with the form's one-time key) and gave demographics; its participant token."""
    client = Client(raise_request_exception=False)
    entry = reverse("studyapp:study_entry", args=[study.slug])
    key = re.search(r'name="consent_key" value="([^"]+)"', client.get(entry).content.decode())
    r = client.post(entry, {"consent": "on", "consent_key": key.group(1)})
    token = r["Location"].rstrip("/").split("/")[-1]
    client.post(reverse("studyapp:demographics", args=[token]), {"gender": "female", "age_group": "25-34"})
    return client, token


def _spread_ok(study: Study) -> None:
    """Each balanced section's trial clips within 1 of each other (naturalness per origin half; the demo's
    section-4 generated half may reach 2, as with one-at-a-time starts: section 1 draws from the same clips);
    the stored counters equal the assignments."""
    for section in study.sections.filter(reuse_section__isnull=True):
        rows = Assignment.objects.filter(section=section, kind="")
        stored = dict(SectionClipCount.objects.filter(section=section).values_list("clip_id", "n"))
        assert {k: v for k, v in stored.items() if v} == dict(Counter(rows.values_list("clip_id", flat=True)))
        for origin in set(rows.values_list("clip__origin", flat=True)):
            half = Counter(rows.filter(clip__origin=origin).values_list("clip_id", flat=True))
            allowed = 2 if section.section_type == "naturalness" and origin == "generated" else 1
            assert max(half.values()) - min(half.values()) <= allowed, (section, origin, half)


@pytest.mark.django_db(transaction=True)
def test_demo_starts_over_http_at_once_no_error_no_deadlock_retry(settings, tmp_path, monkeypatch):
    """24 participants of the demo study (9 sections, shared clips, a reusing section) GET /resume at the same
    moment from 24 threads: every one gets a redirect to clip 1 (no 500), starts, and the balance holds. On
    PostgreSQL no start needed a deadlock/serialization retry. PostgreSQL only: SQLite's test database is a
    shared-cache in-memory database, where even a plain read fails at once with "database table is locked" while
    another thread writes (the production SQLite database is a WAL file, where readers never wait on writers);
    the SQLite start path is covered by the library-level threaded tests in test_study_flow_cost.py."""
    if connection.vendor != "postgresql":
        pytest.skip("HTTP-level concurrent starts need PostgreSQL: SQLite's shared-cache test database locks "
                    "tables for readers")
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("demo", "burst", plan="test", status=Study.Status.OPEN,
                                     counterbalance_sections=True)
    clients = [_consented(study) for _ in range(24)]
    retried: list[str] = []
    real = assignment._retryable

    def recording(exc, vendor=None):
        verdict = real(exc, vendor)
        if verdict:
            retried.append(str(exc)[:80])
        return verdict

    monkeypatch.setattr(assignment, "_retryable", recording)
    barrier, statuses, errors = threading.Barrier(len(clients)), [], []

    def run(client, token):
        barrier.wait()
        try:
            r = client.get(reverse("studyapp:resume", args=[token]))
            statuses.append((r.status_code, r.get("Location", "").endswith("/clip/1/")))
            if r.status_code >= 500 and getattr(r, "exc_info", None):
                errors.append("".join(traceback.format_exception(*r.exc_info))[-2000:])
        finally:
            connection.close()

    threads = [threading.Thread(target=run, args=ct) for ct in clients]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert Counter(statuses) == {(302, True): len(clients)}, errors
    assert not Participant.objects.filter(study=study).exclude(status="started").exists()
    _spread_ok(study)
    if connection.vendor == "postgresql":
        assert retried == [], retried
