"""Researcher pages honour Django permissions: a staff account without the page's permission gets 403, with it the
page answers; the "researcher" group of the data migration holds the set those pages need."""
from __future__ import annotations

import pytest
from django.contrib.auth.models import Group, Permission, User
from django.test import Client
from django.urls import reverse

from studyapp.models import Study
from studyapp.permissions import EXPORT_PERMISSION, RESEARCHER_GROUP, RESEARCHER_PERMISSIONS
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.REPORTS_DIR = tmp_path / "reports"
    make_catalogue(settings.MEDIA_ROOT)
    return create_study_from_preset("demo", "demo", plan="test", status="open")


def pages(study) -> list[tuple[str, str, set[int]]]:
    """(url, permission it needs, statuses that mean "allowed") of every staff-only page."""
    sid = study.pk
    return [
        (reverse("studyapp:create_from_preset"), "studyapp.add_study", {200}),
        (reverse("admin:studyapp_study_from_preset"), "studyapp.add_study", {200}),
        (reverse("studyapp:preview_start", args=[sid]), "studyapp.view_study", {200}),
        (reverse("studyapp:preview_item", args=[sid, 1]), "studyapp.view_study", {200}),
        (reverse("studyapp:progress", args=[sid]), "studyapp.view_study", {200}),
        (reverse("studyapp:export_csv", args=[sid, "responses"]), EXPORT_PERMISSION, {200}),
        (reverse("studyapp:export_csv", args=[sid, "participants"]), EXPORT_PERMISSION, {200}),
        (reverse("studyapp:export_csv", args=[sid, "clips"]), EXPORT_PERMISSION, {200}),
        # no report built yet: the allowed answer sends the researcher to the progress page's report box
        (reverse("studyapp:report_zip", args=[sid]), EXPORT_PERMISSION, {302}),
        (reverse("admin:studyapp_pool_count") + "?section_type=gait_emotion&pool_modality=gait",
         "studyapp.view_clip", {200}),
    ]


def staff_client(username: str, *perms: str) -> Client:
    """A staff member holding ``perms`` who owns every study there is (per-study access:
    tests/studyapp/staff/test_study_access.py)."""
    user = User.objects.create_user(username, password="pw-" + username + "-1", is_staff=True)
    for study in Study.objects.all():
        study.owners.add(user)
    for perm in perms:
        app_label, codename = perm.split(".")
        user.user_permissions.add(Permission.objects.get(content_type__app_label=app_label, codename=codename))
    client = Client()
    client.force_login(user)
    return client


def test_staff_without_permissions_gets_403_everywhere(study):
    client = staff_client("noperms")
    for url, perm, _ in pages(study):
        r = client.get(url)
        assert r.status_code == 403, (url, r.status_code)
        if "pool-count" in url:
            assert perm in r.json()["error"]


def test_each_page_opens_with_its_permission_and_only_that(study):
    for i, (url, perm, allowed) in enumerate(pages(study)):
        client = staff_client(f"holder{i}", perm)
        r = client.get(url)
        assert r.status_code in allowed, (url, perm, r.status_code)
        if r.status_code == 302:
            assert reverse("studyapp:progress", args=[study.pk]) in r["Location"]
        others = {other_url for other_url, other_perm, _ in pages(study) if other_perm != perm}
        for other in others:
            assert client.get(other).status_code == 403, (perm, other)


def test_export_page_content_needs_the_export_permission(study):
    viewer = staff_client("viewer", "studyapp.view_study")
    progress = viewer.get(reverse("studyapp:progress", args=[study.pk]))
    assert progress.status_code == 200
    assert viewer.get(reverse("studyapp:export_csv", args=[study.pk, "participants"])).status_code == 403
    assert viewer.post(reverse("studyapp:report_zip", args=[study.pk])).status_code == 403


def test_anonymous_and_non_staff_still_go_to_the_login(study):
    user = User.objects.create_user("member", password="pw-member-1")
    user.user_permissions.add(*Permission.objects.filter(content_type__app_label="studyapp"))
    member = Client()
    member.force_login(user)
    for client in (Client(), member):
        for url, _, _ in pages(study):
            r = client.get(url)
            if "pool-count" in url:
                assert r.status_code == 403
            else:
                assert r.status_code == 302 and "/admin/login/" in r["Location"], url


def test_researcher_group_from_the_migration_opens_every_page(study):
    group = Group.objects.get(name=RESEARCHER_GROUP)
    held = set(group.permissions.filter(content_type__app_label="studyapp").values_list("codename", flat=True))
    assert held == set(RESEARCHER_PERMISSIONS)
    assert not group.permissions.filter(codename__in=["delete_study", "delete_participant", "change_response",
                                                      "delete_response", "change_clip"]).exists()
    user = User.objects.create_user("res", password="pw-res-1", is_staff=True)
    user.groups.add(group)
    study.collaborators.add(user)
    client = Client()
    client.force_login(user)
    for url, perm, allowed in pages(study):
        assert client.get(url).status_code in allowed, (url, perm)
    assert client.get("/admin/studyapp/study/").status_code == 200
    assert client.get(f"/admin/studyapp/study/{study.pk}/delete/").status_code == 403
