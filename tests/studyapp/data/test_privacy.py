"""Participants' personal data: a deleted or withdrawn participant leaves no stored report (the admin says so, a
build running meanwhile discards its zip), exports pseudonymise external ids unless the study asks, the Prolific
IDs for payment are a separate permission-checked download, collected answers are read-only in the admin, and
staff pages and downloads are sent with Cache-Control: no-store."""
from __future__ import annotations

import csv
import io
import os
import zipfile

import pytest
from django.contrib.auth.models import Group, Permission, User
from django.core.management import call_command
from django.test import Client
from django.urls import reverse

from studyapp.data.export import stream_csv
from studyapp.data.privacy import PURGED_NAME, pseudonym
from studyapp.models import Participant, Response, Study
from studyapp.permissions import RESEARCHER_GROUP
from studyapp.staff import reports
from studyapp.staff.presets import create_study_from_preset
from studyapp.staff.reports import forget_reports
from studyapp.testing import make_catalogue
from tests.studyapp.staff.test_study_admin import finish

pytestmark = pytest.mark.django_db


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.REPORTS_DIR = tmp_path / "reports"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("gait_ismar2020", "private", plan="test", status="open")
    for pid in ("PROLIFIC-AAA", "PROLIFIC-BBB"):
        finish(Participant.objects.create(study=study, external_id=pid, external_study_id="S1",
                                          external_session_id=f"sess-{pid}"))
    return study


@pytest.fixture
def root():
    c = Client()
    c.force_login(User.objects.create_superuser("root", "r@example.org", "pw-root-12345"))
    return c


def researcher(*extra: str) -> Client:
    user = User.objects.create_user(f"r{len(extra)}", password="pw-researcher-1", is_staff=True)
    user.groups.add(Group.objects.get(name=RESEARCHER_GROUP))
    user.user_permissions.add(*Permission.objects.filter(codename__in=extra))
    c = Client()
    c.force_login(user)
    return c


def report_text(path) -> str:
    with zipfile.ZipFile(path) as zf:
        return "".join(zf.read(n).decode(errors="replace") for n in zf.namelist() if n.endswith(".csv"))


def build(study) -> str:
    call_command("build_report", str(study.pk), stdout=io.StringIO())
    state = reports.report_state(study)
    assert state.status == "ready"
    return state.zip_path


def test_deleting_a_participant_deletes_the_stored_report_and_the_admin_says_so(study, root):
    gone = Participant.objects.get(external_id="PROLIFIC-AAA")
    zip_path = build(study)
    assert gone.public_id in report_text(zip_path)
    page = root.post(reverse("admin:studyapp_participant_delete", args=[gone.pk]), {"post": "yes"}, follow=True)
    assert page.status_code == 200
    text = " ".join(str(m) for m in page.context["messages"])
    assert "Deleted 1 stored analysis report(s)" in text and "build the report again" in text
    assert not zip_path.exists() and reports.report_state(study).status == "none"
    rebuilt = build(study)                                 # the new report is made without them
    assert gone.public_id not in report_text(rebuilt) and "PROLIFIC-AAA" not in report_text(rebuilt)


def test_withdrawing_a_participant_removes_them_from_exports_and_reports(study, root):
    leaving = Participant.objects.get(external_id="PROLIFIC-BBB")
    zip_path = build(study)
    url = reverse("admin:studyapp_participant_change", args=[leaving.pk])
    page = root.post(url, {"study": study.pk, "status": "withdrawn", "seed": leaving.seed, "n_items": 0,
                           "assignments-TOTAL_FORMS": 0, "assignments-INITIAL_FORMS": 0}, follow=True)
    assert page.status_code == 200, page.content[:500]
    leaving.refresh_from_db()
    assert leaving.status == "withdrawn"
    assert "Deleted 1 stored analysis report(s)" in " ".join(str(m) for m in page.context["messages"])
    assert not zip_path.exists()
    for kind in ("responses", "participants", "assignments", "viewing"):
        assert leaving.public_id not in "".join(stream_csv(study, kind)), kind
    assert Response.objects.filter(participant=leaving).exists()          # kept in the database, out of the data


def test_a_build_running_when_a_participant_is_removed_discards_its_zip(study):
    version = reports.data_version(study)
    folder = reports.version_dir(study.pk, version)
    fd = reports.acquire_lock(folder)                     # a build holds the version's lock
    try:
        (folder / reports.REPORT_NAME).write_bytes(b"a zip finished a moment ago")
        assert forget_reports(study.pk) == 1
        assert (folder / PURGED_NAME).exists() and not (folder / reports.REPORT_NAME).exists()
        with pytest.raises(RuntimeError, match="build it again"):
            reports.build_report(study, version, fd)
        assert not (folder / reports.REPORT_NAME).exists()
    finally:
        os.close(fd)


def test_exports_pseudonymise_external_ids_unless_the_study_asks(study):
    people = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "participants")))))
    ids = {p["external_id"] for p in people}
    assert ids == {pseudonym(study.pk, "PROLIFIC-AAA"), pseudonym(study.pk, "PROLIFIC-BBB")}
    assert all(i.startswith("x") and len(i) == 13 for i in ids)
    assert pseudonym(study.pk, "PROLIFIC-AAA") != pseudonym(study.pk + 1, "PROLIFIC-AAA")   # not linkable across
    Study.objects.filter(pk=study.pk).update(export_external_ids=True)
    study.refresh_from_db()
    people = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "participants")))))
    assert {p["external_id"] for p in people} == {"PROLIFIC-AAA", "PROLIFIC-BBB"}


def test_payment_ids_are_a_separate_permission_checked_download(study):
    url = reverse("studyapp:payment_ids", args=[study.pk])
    plain = researcher()
    study.owners.add(User.objects.get(username="r0"))
    assert plain.get(url).status_code == 403                              # the researcher group lacks it
    payer = researcher("download_payment_ids")
    study.owners.add(User.objects.get(username="r1"))
    r = payer.get(url)
    assert r.status_code == 200 and "no-store" in r["Cache-Control"]
    rows = list(csv.DictReader(io.StringIO(b"".join(r.streaming_content).decode())))
    assert {row["external_id"] for row in rows} == {"PROLIFIC-AAA", "PROLIFIC-BBB"}
    assert set(rows[0]) == {"external_id", "external_study_id", "external_session_id", "status", "completed_at"}
    assert Client().get(url).status_code == 302                           # not logged in: the admin login


def test_answers_are_read_only_in_the_admin(study, root):
    answer = Response.objects.first()
    assert root.get(reverse("admin:studyapp_response_add")).status_code == 403
    assert root.get(reverse("admin:studyapp_response_delete", args=[answer.pk])).status_code == 403
    assert root.post(reverse("admin:studyapp_response_change", args=[answer.pk]),
                     {"answer": "forged"}).status_code == 403
    assert root.get(reverse("admin:studyapp_participant_add")).status_code == 403
    answer.refresh_from_db()
    assert answer.answer != "forged"


@pytest.mark.parametrize("name, args", [("studyapp:progress", None), ("studyapp:export_csv", "participants"),
                                        ("studyapp:report_zip", None), ("admin:studyapp_participant_changelist", 0)])
def test_staff_pages_and_downloads_are_not_stored(study, root, name, args):
    if name == "studyapp:report_zip":
        build(study)
    url = reverse(name, args=[study.pk, args] if isinstance(args, str) else ([] if args == 0 else [study.pk]))
    r = root.get(url)
    assert r.status_code == 200, (url, r.status_code)
    assert "no-store" in r["Cache-Control"], (url, r["Cache-Control"])


def test_participant_pages_keep_their_own_headers(study):
    r = Client().get("/")
    assert "no-store" not in r.get("Cache-Control", "")
