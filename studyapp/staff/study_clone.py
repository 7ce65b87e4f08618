"""Clone a study: its texts, settings and sections (pools, options, the sections each one reuses) under a new slug,
as a draft, without participants, answers or counts; whoever clones it owns the copy (with the original's owners
and collaborators, who could see the original already)."""
from __future__ import annotations

from django.db import transaction

from ..models import Section, Study, new_completion_code

#: Study fields that are not copied: identity, state and timestamps.
NOT_COPIED = {"id", "slug", "title", "status", "pilot", "completion_code", "created_at", "owners", "collaborators"}
SECTION_NOT_COPIED = {"id", "study", "reuse_section"}


def clone_study(study: Study, slug: str, title: str, user=None) -> Study:
    """A draft copy of ``study`` named ``slug``/``title`` (a new completion code, pilot mode off); returns it."""
    fields = {f.name: getattr(study, f.name) for f in Study._meta.concrete_fields if f.name not in NOT_COPIED}
    with transaction.atomic():
        copy = Study.objects.create(slug=slug, title=title, status=Study.Status.DRAFT,
                                    completion_code=new_completion_code(), **fields)
        copy.owners.set(study.owners.all())
        copy.collaborators.set(study.collaborators.all())
        if user is not None:
            copy.owners.add(user)
        new_of: dict[int, Section] = {}
        sections = list(study.sections.order_by("order", "id"))
        for section in sections:
            values = {f.name: getattr(section, f.name) for f in Section._meta.concrete_fields
                      if f.name not in SECTION_NOT_COPIED}
            new_of[section.pk] = Section.objects.create(study=copy, **values)
        for section in sections:
            if section.reuse_section_id in new_of:
                Section.objects.filter(pk=new_of[section.pk].pk).update(reuse_section=new_of[section.reuse_section_id])
    return copy
