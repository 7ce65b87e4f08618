"""The study page in the admin: "reuse section" offers only earlier sections of the same study."""
from __future__ import annotations

import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.urls import reverse

from studyapp.presets import create_study_from_preset

pytestmark = pytest.mark.django_db


def test_reuse_section_lists_only_earlier_sections_of_the_same_study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    client = Client()
    client.force_login(User.objects.create_user("lead", password="pw-lead-12345", is_staff=True,
                                                is_superuser=True))
    study = create_study_from_preset("gait_ismar2020", "builder", plan="test")
    other = create_study_from_preset("gait_ismar2020", "elsewhere", plan="test")
    page = client.get(reverse("admin:studyapp_study_change", args=[study.pk]))
    formset = next(f.formset for f in page.context["inline_admin_formsets"] if f.formset.model.__name__ == "Section")
    sections = list(study.sections.order_by("order", "id"))
    for form in formset.forms:
        offered = list(form.fields["reuse_section"].queryset)
        assert offered == [s for s in sections if s.order < form.instance.order], form.instance.order
    assert formset.forms[0].fields["reuse_section"].queryset.count() == 0
    assert not set(formset.empty_form.fields["reuse_section"].queryset) & set(other.sections.all())
    assert set(formset.empty_form.fields["reuse_section"].queryset) == set(sections)
