"""Moving sections up and down on the study page's sections step (studyapp.admin.section_order, studyapp.admin.steps):
the swap, what is refused and why, POST with CSRF and change permission only, and the order assignment reads."""
from __future__ import annotations

import pytest
from django.contrib.auth.models import Permission, User
from django.test import Client
from django.urls import reverse

from studyapp.admin import section_order
from studyapp.models import Participant, Section
from studyapp.participant.assignment import participant_order
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


@pytest.fixture
def study(settings, tmp_path):
    """gait_ismar2020: 1 emotion_choice, 2 emotion_transition, 3 affect_likert (reuses 1), 4 naturalness."""
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    return create_study_from_preset("gait_ismar2020", "order", plan="test")


def types(study) -> list[str]:
    return list(study.sections.order_by("order", "id").values_list("section_type", flat=True))


def move_url(study, section: Section, direction: str) -> str:
    return reverse("admin:studyapp_study_move_section", args=[study.pk, section.pk, direction])


def test_move_swaps_with_the_neighbour(study):
    naturalness = study.sections.get(section_type="naturalness")
    other = section_order.move(naturalness, "up")
    assert other.section_type == "affect_likert"
    assert types(study) == ["emotion_choice", "emotion_transition", "naturalness", "affect_likert"]
    section_order.move(study.sections.get(section_type="emotion_choice"), "down")
    assert types(study) == ["emotion_transition", "emotion_choice", "naturalness", "affect_likert"]
    assert sorted(study.sections.values_list("order", flat=True)) == [1, 2, 3, 4]


def test_sections_of_equal_order_are_numbered_first(study):
    study.sections.update(order=0)
    last = study.sections.order_by("id").last()
    section_order.move(last, "up")
    orders = list(study.sections.order_by("order", "id").values_list("order", flat=True))
    assert orders == [1, 2, 3, 4]
    assert study.sections.order_by("order", "id")[2].pk == last.pk


@pytest.mark.parametrize("kind,direction,words", [
    ("emotion_choice", "up", "already the first section"),
    ("naturalness", "down", "already the last section"),
    ("emotion_choice", "sideways", "Unknown direction 'sideways'"),
])
def test_moves_past_the_ends_are_refused(study, kind, direction, words):
    with pytest.raises(section_order.MoveRefused, match=words):
        section_order.move(study.sections.get(section_type=kind), direction)


def test_a_reusing_section_never_passes_the_section_it_reuses(study):
    likert = study.sections.get(section_type="affect_likert")
    section_order.move(likert, "up")        # past emotion_transition: fine
    assert types(study)[:2] == ["emotion_choice", "affect_likert"]
    with pytest.raises(section_order.MoveRefused, match="shows the clips of section 1 .*must come after it"):
        section_order.move(likert, "up")
    with pytest.raises(section_order.MoveRefused, match="must come after it"):
        section_order.move(study.sections.get(section_type="emotion_choice"), "down")
    assert types(study)[:2] == ["emotion_choice", "affect_likert"]


def test_refused_once_participants_take_part(study):
    p = Participant.objects.create(study=study)
    with pytest.raises(section_order.MoveRefused, match="1 participant has taken part"):
        section_order.move(study.sections.get(section_type="naturalness"), "up")
    p.status = Participant.Status.WITHDRAWN
    p.save()
    section_order.move(study.sections.get(section_type="naturalness"), "up")


def test_the_next_participant_takes_the_new_order(study):
    section_order.move(study.sections.get(section_type="naturalness"), "up")
    sections = list(study.sections.order_by("order", "id"))
    study.counterbalance_sections = False
    assert [s.section_type for s in participant_order(study, sections)] == [
        "emotion_choice", "emotion_transition", "naturalness", "affect_likert"]


# ---- through the admin ----------------------------------------------------------------------------------------

def test_buttons_post_and_come_back_to_the_sections_step(admin_client, study):
    page = admin_client.get(reverse("admin:studyapp_study_change", args=[study.pk]) + "?step=sections")
    html = page.content.decode()
    naturalness = study.sections.get(section_type="naturalness")
    assert f'action="{move_url(study, naturalness, "up")}"' in html and "Move up" in html
    assert 'name="csrfmiddlewaretoken"' in html
    r = admin_client.post(move_url(study, naturalness, "up"), follow=True)
    assert r.redirect_chain[0][0].endswith("?step=sections")
    assert types(study)[2] == "naturalness"
    assert any("Moved section 3 (naturalness" in str(m) for m in r.context["messages"])


def test_get_is_refused_and_nothing_moves(admin_client, study):
    before = types(study)
    assert admin_client.get(move_url(study, study.sections.last(), "up")).status_code == 405
    assert types(study) == before


def test_refusal_is_a_message_and_the_buttons_go(admin_client, study):
    Participant.objects.create(study=study)
    r = admin_client.post(move_url(study, study.sections.get(section_type="naturalness"), "up"), follow=True)
    assert any("cannot be reordered: 1 participant has taken part" in str(m) for m in r.context["messages"])
    assert "Move up" not in r.content.decode().split('id="section-moves-title"')[1].split("</section>")[0]


def test_csrf_token_is_required(study):
    user = User.objects.create_superuser("root", password="pw-root-1")
    client = Client(enforce_csrf_checks=True)
    client.force_login(user)
    before = types(study)
    assert client.post(move_url(study, study.sections.last(), "up")).status_code == 403
    assert types(study) == before


def test_only_those_who_may_change_the_study_move(study):
    before = types(study)
    stranger = User.objects.create_user("stranger", password="pw-stranger-1", is_staff=True)
    stranger.user_permissions.add(*Permission.objects.filter(codename__in=["view_study", "change_study"]))
    viewer = User.objects.create_user("viewer", password="pw-viewer-1", is_staff=True)
    viewer.user_permissions.add(Permission.objects.get(codename="view_study"))
    study.collaborators.add(viewer)
    for user, status in ((stranger, 404), (viewer, 403)):
        client = Client()
        client.force_login(user)
        assert client.post(move_url(study, study.sections.last(), "up")).status_code == status, user
    assert types(study) == before


def test_a_section_of_another_study_is_not_found(admin_client, study):
    other = create_study_from_preset("gait_ismar2020", "other", plan="test")
    assert admin_client.post(move_url(study, other.sections.last(), "up")).status_code == 404


def test_a_typed_order_change_is_refused_the_same_way(admin_client, study):
    from studyapp.testing import admin_form_data

    Participant.objects.create(study=study)
    url = reverse("admin:studyapp_study_change", args=[study.pk]) + "?step=sections"
    data = admin_form_data(admin_client.get(url))
    data["sections-0-order"], data["sections-1-order"] = "2", "1"
    r = admin_client.post(url, data)
    assert r.status_code == 200
    errors = r.context["inline_admin_formsets"][0].formset.forms[0].errors
    assert "cannot be reordered: 1 participant has taken part" in str(errors["order"])
    assert types(study)[:2] == ["emotion_choice", "emotion_transition"]
