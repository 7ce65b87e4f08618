"""Per-study access: a researcher (staff with the researcher group, not a superuser) sees, previews, exports and
analyses only the studies they own or collaborate on; another lab's study is a 404 on every staff page and absent
or refused in the admin; superusers see every study."""
from __future__ import annotations

import json

import pytest
from django.contrib.auth.models import Group, User
from django.test import Client
from django.urls import reverse

from studyapp.data.export import EXPORT_KINDS
from studyapp.models import Clip, Participant, Response, Section, Study
from studyapp.permissions import RESEARCHER_GROUP, can_access_study, studies_for
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import admin_form_data, make_catalogue

pytestmark = pytest.mark.django_db


def researcher(name: str) -> User:
    user = User.objects.create_user(name, password=f"pw-{name}-1", is_staff=True)
    user.groups.add(Group.objects.get(name=RESEARCHER_GROUP))
    return user


def client_of(user: User) -> Client:
    c = Client()
    c.force_login(user)
    return c


@pytest.fixture
def labs(settings, tmp_path):
    """Two studies with a participant and an answer each: ours (owned by alice, bob collaborates) and theirs
    (owned by mallory)."""
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.REPORTS_DIR = tmp_path / "reports"
    make_catalogue(settings.MEDIA_ROOT)
    ours = create_study_from_preset("demo", "ours", plan="test", status="open")
    theirs = create_study_from_preset("demo", "theirs", plan="test", status="open")
    alice, bob, mallory = researcher("alice"), researcher("bob"), researcher("mallory")
    ours.owners.add(alice)
    ours.collaborators.add(bob)
    theirs.owners.add(mallory)
    for study in (ours, theirs):
        p = Participant.objects.create(study=study, external_id=f"PID-{study.slug}")
        section = study.sections.first()
        Response.objects.create(participant=p, section=section, clip=Clip.objects.first(), question="perceived",
                                answer="happy")
    root = User.objects.create_superuser("root", password="pw-root-1")
    return {"ours": ours, "theirs": theirs, "alice": alice, "bob": bob, "mallory": mallory, "root": root}


def participants_request(c: Client):
    from django.test import RequestFactory

    request = RequestFactory().get("/admin/studyapp/participant/")
    request.user = User.objects.get(pk=c.session["_auth_user_id"])
    return request


def staff_pages(study: Study) -> list[tuple[str, str]]:
    """(method, url) of every staff page of one study."""
    sid = study.pk
    pages = [("get", reverse("studyapp:preview_start", args=[sid])),
             ("get", reverse("studyapp:preview_item", args=[sid, 1])),
             ("get", reverse("studyapp:progress", args=[sid])),
             ("get", reverse("studyapp:norming_monitor", args=[sid])),
             ("get", reverse("studyapp:report_zip", args=[sid])),
             ("post", reverse("studyapp:report_zip", args=[sid]))]
    return pages + [("get", reverse("studyapp:export_csv", args=[sid, kind])) for kind in EXPORT_KINDS]


def test_who_sees_which_study(labs):
    ours, theirs = labs["ours"], labs["theirs"]
    assert set(studies_for(labs["alice"])) == {ours} and set(studies_for(labs["bob"])) == {ours}
    assert set(studies_for(labs["mallory"])) == {theirs}
    assert set(studies_for(labs["root"])) == {ours, theirs}
    assert not can_access_study(labs["alice"], theirs) and can_access_study(labs["bob"], ours.pk)
    outsider = User.objects.create_user("nobody", password="pw-nobody-1", is_staff=True, is_active=False)
    assert not studies_for(outsider).exists()


@pytest.mark.parametrize("who", ["alice", "bob"])
def test_staff_pages_of_another_labs_study_are_404(labs, who, monkeypatch):
    from studyapp.staff import views as views_staff

    monkeypatch.setattr(views_staff, "start_build", lambda study: pytest.fail("a build of another lab's study"))
    c = client_of(labs[who])
    for method, url in staff_pages(labs["theirs"]):
        r = getattr(c, method)(url)
        assert r.status_code == 404, (who, method, url, r.status_code)
        assert b"PID-theirs" not in r.content


@pytest.mark.parametrize("who", ["alice", "bob", "root"])
def test_staff_pages_of_ones_own_study_open(labs, who, monkeypatch):
    from studyapp.staff import views as views_staff

    monkeypatch.setattr(views_staff, "start_build", lambda study: type("S", (), {"status": "building"})())
    c = client_of(labs[who])
    for method, url in staff_pages(labs["ours"]):
        r = getattr(c, method)(url)
        assert r.status_code in (200, 302), (who, method, url, r.status_code)
    export = c.get(reverse("studyapp:export_csv", args=[labs["ours"].pk, "participants"]))
    from studyapp.data.privacy import pseudonym
    assert pseudonym(labs["ours"].pk, "PID-ours").encode() in b"".join(export.streaming_content)
    if who == "root":
        for method, url in staff_pages(labs["theirs"]):
            assert getattr(c, method)(url).status_code in (200, 302), url


def test_admin_lists_only_ones_own_studies_participants_and_responses(labs):
    c = client_of(labs["alice"])
    studies = c.get("/admin/studyapp/study/").content.decode()
    assert "/s/ours/" in studies and "/s/theirs/" not in studies
    participants = c.get("/admin/studyapp/participant/").content.decode()
    assert "PID-ours" in participants and "PID-theirs" not in participants
    from django.contrib.admin import RelatedOnlyFieldListFilter

    cl = c.get("/admin/studyapp/participant/").context["cl"]
    by_study = RelatedOnlyFieldListFilter(Participant._meta.get_field("study"), participants_request(c), {},
                                          Participant, cl.model_admin, "study")
    assert [label for _pk, label in by_study.lookup_choices] == [labs["ours"].title]      # no other lab's title
    responses = c.get("/admin/studyapp/response/")
    assert responses.status_code == 200 and len(responses.context["cl"].result_list) == 1
    assert c.get("/admin/studyapp/participant/?q=PID-theirs").context["cl"].result_count == 0


def test_admin_pages_of_another_labs_rows_are_refused(labs):
    c = client_of(labs["alice"])
    theirs = labs["theirs"]
    p = Participant.objects.get(study=theirs)
    r = Response.objects.get(participant=p)
    for url in (f"/admin/studyapp/study/{theirs.pk}/change/", f"/admin/studyapp/participant/{p.pk}/change/",
                f"/admin/studyapp/response/{r.pk}/change/"):
        page = c.get(url)
        assert page.status_code == 302 and page["Location"] == "/admin/", url     # "does not exist"
    # a change POST and the list actions cannot reach it either
    assert c.post(f"/admin/studyapp/study/{theirs.pk}/change/", {"title": "mine now"}).status_code == 302
    c.post("/admin/studyapp/study/", {"action": "close_studies", "_selected_action": [theirs.pk]})
    theirs.refresh_from_db()
    assert theirs.title != "mine now" and theirs.status == "open"


def test_owner_manages_access_a_collaborator_does_not(labs):
    ours = labs["ours"]
    url = f"/admin/studyapp/study/{ours.pk}/change/"
    owner, collaborator = client_of(labs["alice"]), client_of(labs["bob"])
    assert "owners" in owner.get(url).context["adminform"].form.fields
    assert "owners" not in collaborator.get(url).context["adminform"].form.fields      # shown read-only
    data = admin_form_data(owner.get(url))
    data["collaborators"] = [str(labs["bob"].pk), str(labs["mallory"].pk)]
    assert owner.post(url, data).status_code == 302
    assert can_access_study(labs["mallory"], ours)


def test_creating_a_study_makes_one_its_owner(labs):
    c = client_of(labs["mallory"])
    r = c.post(reverse("studyapp:create_from_preset"), {"preset": "demo", "slug": "fresh", "title": ""})
    assert r.status_code == 302
    fresh = Study.objects.get(slug="fresh")
    assert list(fresh.owners.all()) == [labs["mallory"]]
    assert not can_access_study(labs["alice"], fresh)


def test_section_reuse_choices_name_no_other_labs_section(labs):
    c = client_of(labs["alice"])
    page = c.get(f"/admin/studyapp/study/{labs['ours'].pk}/change/")
    formset = page.context["inline_admin_formsets"][0].formset
    offered = {slug for form in [*formset.forms, formset.empty_form]
               for slug in form.fields["reuse_section"].queryset.values_list("study__slug", flat=True)}
    assert offered == {"ours"}         # (each form offers only the earlier sections of its own study)


def live_norms(c: Client, source: str) -> dict:
    """The pool editor's live count of a pool whose norms rule reads ``source``."""
    pool = {"modality": "gait", "norms": {"from": source, "min_ratings": 1}}
    return c.get(reverse("admin:studyapp_pool_count"), {"section_type": "emotion_choice", "pool": json.dumps(pool),
                                                         "clips_per_participant": "4"}).json()


def pool_messages(answer: dict) -> str:
    return " ".join(m for e in answer["errors"] for m in e["messages"])


def test_pool_editor_reads_the_norms_of_ones_own_studies_only(labs):
    mallory = client_of(labs["mallory"])
    refused = {}
    for source in ("ours", "no-such-study"):
        answer = live_norms(mallory, source)
        assert answer["count"] is None and not answer.get("norms_html"), answer    # no other lab's ratings
        refused[source] = pool_messages(answer).replace(source, "<slug>")
    assert refused["ours"] == refused["no-such-study"]                              # a slug is not confirmed
    assert "pool.norms.from" in refused["ours"]
    for who, source in (("alice", "ours"), ("bob", "ours"), ("root", "theirs")):
        assert pool_messages(live_norms(client_of(labs[who]), source)).replace(source, "<slug>") != refused["ours"]


def test_a_section_may_name_only_a_readable_study_as_its_norms(labs):
    theirs = labs["theirs"]
    section = theirs.sections.get(order=1)
    before = section.pool
    url = reverse("admin:studyapp_study_change", args=[theirs.pk])
    mallory = client_of(labs["mallory"])
    data = admin_form_data(mallory.get(url))
    data["sections-0-pool"] = json.dumps({**before, "norms": {"from": "ours", "min_ratings": 1}})
    page = mallory.post(url, data)
    assert page.status_code == 200, "another lab's study accepted as a norms source"
    errors = page.context["inline_admin_formsets"][0].formset.errors[0]
    assert "pool.norms.from" in " ".join(errors["pool"]), errors
    section.refresh_from_db()
    assert section.pool == before
    # a source a superuser saved stays: the lab can still save its study without naming it anew
    Section.objects.filter(pk=section.pk).update(pool={**before, "norms": {"from": "ours", "min_ratings": 1}})
    assert mallory.post(url, admin_form_data(mallory.get(url))).status_code == 302


def live_sub_pool_norms(c: Client, source: str) -> dict:
    """The live count of a naturalness pool whose ``generated`` sub-pool carries a norms rule reading ``source``."""
    pool = {"modality": "gait", "generated": {"norms": {"from": source, "min_intended_share": 0.0}}}
    return c.get(reverse("admin:studyapp_pool_count"), {"section_type": "naturalness", "pool": json.dumps(pool),
                                                         "clips_per_participant": "2"}).json()


def test_a_sub_pools_norms_rule_is_checked_like_the_pools_own(labs, monkeypatch):
    from studyapp.data import norms_rule

    read = []
    monkeypatch.setattr(norms_rule, "load_norms", lambda source: read.append(source) or {})
    mallory = client_of(labs["mallory"])
    refused = {source: pool_messages(live_sub_pool_norms(mallory, source)).replace(source, "<slug>")
               for source in ("ours", "no-such-study")}
    assert read == [], "another lab's norms were read through a sub-pool"
    assert refused["ours"] == refused["no-such-study"] and "pool.generated.norms.from" in refused["ours"]
    assert live_sub_pool_norms(client_of(labs["alice"]), "ours")["count"] is not None


def test_a_sub_pool_naming_another_labs_study_does_not_save(labs):
    theirs = labs["theirs"]
    section = theirs.sections.get(section_type="naturalness", order=4)
    before = section.pool
    url = reverse("admin:studyapp_study_change", args=[theirs.pk])
    mallory = client_of(labs["mallory"])
    data = admin_form_data(mallory.get(url))
    index = list(theirs.sections.order_by("order")).index(section)
    data[f"sections-{index}-pool"] = json.dumps(
        {**before, "generated": {"origin": "generated", "norms": {"from": "ours", "min_ratings": 1}}})
    page = mallory.post(url, data)
    assert page.status_code == 200, "a sub-pool naming another lab's study was saved"
    errors = page.context["inline_admin_formsets"][0].formset.errors[index]
    assert "pool.generated.norms.from" in " ".join(errors["pool"]), errors
    section.refresh_from_db()
    assert section.pool == before
