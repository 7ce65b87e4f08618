"""Participants' personal data in what a study hands on: pseudonymised external ids, withdrawn and deleted
participants removed from stored reports, and the separate download of the ids a payment needs.

- :func:`pseudonym`: what exports and reports write for a participant's external id (a Prolific ID) unless the
  study asks for the ids themselves (``Study.export_external_ids``): ``x`` + 12 hex digits of an HMAC-SHA256 keyed
  with the site's SECRET_KEY over the study and the id, the same in every export of one study (duplicates stay
  visible) and not reversible without the key.
- Stored reports: a finished report zip (studyapp.staff.reports) holds the study's exports. When a participant is
deleted
  or withdrawn, ``studyapp.staff.reports.forget_reports`` deletes every stored report of their study (the admin says
  so); a build running at that moment finds the ``purged`` mark in its folder and discards its zip. Exports
  themselves are never stored; they are made from the database on each download, which has the participant no
  more (deleted) or leaves them out (withdrawn: studyapp.data.export).
- :data:`PAYMENT_PERMISSION`: who may download the external ids for payment (``payment_rows``): no participant
  id, no answer in that file, so it cannot be joined to the data.
"""
from __future__ import annotations

import hashlib
import hmac

from django.conf import settings

PAYMENT_PERMISSION = "studyapp.download_payment_ids"
"""Download a study's external ids (Prolific IDs) with their status, for paying participants."""
PURGED_NAME = "purged"
"""Mark left in a report version folder whose build was running when a participant was removed."""
PAYMENT_COLUMNS = ("external_id", "external_study_id", "external_session_id", "status", "completed_at")


def pseudonym(study_id: int, external_id: str) -> str:
    """The export's stand-in for ``external_id`` in study ``study_id`` ("" stays "")."""
    if not external_id:
        return ""
    key = str(settings.SECRET_KEY).encode()
    digest = hmac.new(key, f"external-id\0{int(study_id)}\0{external_id}".encode(), hashlib.sha256).hexdigest()
    return "x" + digest[:12]


def payment_rows(study) -> list[list]:
    """One row per participant with an external id (withdrawn ones included: they may be owed payment), in
    PAYMENT_COLUMNS order."""
    rows = study.participants.exclude(external_id="").order_by("id").values_list(
        "external_id", "external_study_id", "external_session_id", "status", "completed_at")
    return [[pid, sid, sess, status, done.isoformat() if done else ""] for pid, sid, sess, status, done in rows]
