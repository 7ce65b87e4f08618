"""What a save of one section does to the clips other sections give (studyapp.admin.section_impact): the measure, the
warning after a save that names the other section and the change, and the note beside that section's pool."""
from __future__ import annotations

import pytest
from django.urls import reverse

from studyapp.admin import section_impact
from studyapp.models import Section, Study
from studyapp.testing import admin_form_data, make_catalogue

pytestmark = pytest.mark.django_db

GENERATED_WALKS = {"modality": "gait", "origin": "generated", "transition": False, "rbf": False}
"""make_catalogue's 10 generated walks without a transition."""
SOURCE_WALKS = {"modality": "gait", "origin": "source"}


@pytest.fixture
def study(settings, tmp_path):
    """Two emotion_choice sections drawing from the same 10 walks (4, then 5 each), and one of source walks."""
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = Study.objects.create(slug="shared", title="Shared pools")
    for order, (pool, k) in enumerate(((GENERATED_WALKS, 4), (GENERATED_WALKS, 5), (SOURCE_WALKS, 2)), start=1):
        Section.objects.create(study=study, order=order, section_type="emotion_choice", pool=pool,
                               clips_per_participant=k, name=f"part {order}")
    return study


def sections(study) -> list[Section]:
    return section_impact.study_sections(study)


def test_clips_given_counts_what_earlier_sections_leave(study):
    first, second, third = sections(study)
    assert section_impact.clips_given(sections(study)) == {first.pk: 4, second.pk: 5, third.pk: 2}
    first.clips_per_participant = 8
    assert section_impact.clips_given([first, second, third]) == {first.pk: 8, second.pk: 2, third.pk: 2}


def test_a_reusing_section_gives_what_its_source_gives(study):
    first, _second, _third = sections(study)
    Section.objects.create(study=study, order=9, section_type="affect_likert", reuse_section=first,
                           clips_per_participant=0)
    reuse = sections(study)[-1]
    before = section_impact.clips_given(sections(study))
    assert before[reuse.pk] == 4
    first.clips_per_participant = 3
    first.save()
    found = section_impact.impacts(before, section_impact.clips_given(sections(study)), sections(study),
                                   {first.pk})
    assert [(i.section.pk, i.before, i.after) for i in found] == [(reuse.pk, 4, 3)]
    assert "it shows the clips section 1 (emotion_choice, \"part 1\") gives" in found[0].message()


def test_impacts_name_only_other_sections_that_changed(study):
    first, second, third = sections(study)
    before = section_impact.clips_given([first, second, third])
    first.clips_per_participant = 8
    after = section_impact.clips_given([first, second, third])
    found = section_impact.impacts(before, after, [first, second, third], {first.pk})
    assert len(found) == 1 and found[0].section.pk == second.pk and (found[0].before, found[0].after) == (5, 2)
    assert found[0].message() == (
        'Saving section 1 (emotion_choice, "part 1") changes what section 2 (emotion_choice, "part 2") gives each '
        "participant: 5 clips before, 2 now (its pool shares clips with another section, and a participant never "
        "sees a clip twice).")
    assert section_impact.impacts(None, after, [first, second, third], {first.pk}) == []


def test_a_study_that_cannot_be_planned_has_no_measure(study):
    first, second, _third = sections(study)
    first.reuse_section = second       # reuses a later section: the plan refuses, the save's checks say why
    assert section_impact.clips_given([first, second]) is None


# ---- through the admin ----------------------------------------------------------------------------------------

def clips_step(study) -> str:
    return reverse("admin:studyapp_study_change", args=[study.pk]) + "?step=clips"


def save_clips_step(client, study, edit: dict):
    data = admin_form_data(client.get(clips_step(study)))
    data.update(edit)
    data["_continue"] = "Save and continue editing"
    return client.post(clips_step(study), data, follow=True)


def test_a_save_that_changes_another_section_says_so(admin_client, study):
    r = save_clips_step(admin_client, study, {"sections-0-clips_per_participant": "8"})
    warnings = [str(m) for m in r.context["messages"] if m.level_tag == "warning"]
    assert any('changes what section 2 (emotion_choice, "part 2") gives each participant: 5 clips before, 2 now'
               in m for m in warnings), warnings
    assert not any("section 3" in m and "changes what" in m for m in warnings)
    # and beside the other section's pool, on the page the save comes back to
    html = r.content.decode()
    assert "a participant gets 2 here, not 5" in html


def test_a_save_that_changes_nobody_else_warns_nobody(admin_client, study):
    r = save_clips_step(admin_client, study, {"sections-2-clips_per_participant": "3"})
    assert not [m for m in r.context["messages"] if "changes what" in str(m)]


def test_a_move_that_changes_what_sections_give_says_so(admin_client, study):
    first, second, _third = sections(study)
    second.clips_per_participant = 8          # after the first section's 4 it gets 6 of the 10 walks
    second.save()
    r = admin_client.post(reverse("admin:studyapp_study_move_section", args=[study.pk, second.pk, "up"]),
                          follow=True)
    texts = [str(m) for m in r.context["messages"]]
    assert ('Moving section 1 (emotion_choice, "part 2") changes what section 2 (emotion_choice, "part 1") gives '
            "each participant: 4 clips before, 2 now (its pool shares clips with another section, and a "
            "participant never sees a clip twice).") in texts, texts
