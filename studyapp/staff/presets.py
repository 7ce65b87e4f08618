"""Study presets: one per paper's web study, and a demo with every section type.

A preset is plain data (defined Django-free in the top-level ``protocol.presets`` module, which the study simulator
``analysis.design`` reads too); `create_study_from_preset` turns it into Study + Section rows that the researcher can
then edit in the admin. Section `reuse` is the index of an earlier section of the same preset.
"""
from __future__ import annotations

import copy

from django.db import transaction

from protocol.presets import CONSENT, PRESET_PLANS, PRESETS

from ..models import Section, Study

__all__ = ["CONSENT", "PRESETS", "PRESET_PLANS", "create_study_from_preset", "preset_choices", "preset_sections"]

_OWN_PLAN = object()


def preset_choices() -> list[tuple[str, str]]:
    """(key, title) of every preset, the choices of the "New study from preset" form."""
    return [(key, value["title"]) for key, value in PRESETS.items()]


def preset_sections(preset: str, plan: str | None = _OWN_PLAN) -> list[dict]:
    """A deep copy of the preset's sections with ``plan`` (default the preset's own, :data:`PRESET_PLANS`) as a pool
    filter of every section that has a pool (a reused section shows the clips of the section it repeats);
    ``plan=None`` leaves the pools unfiltered."""
    plan = PRESET_PLANS[preset] if plan is _OWN_PLAN else plan
    sections = copy.deepcopy(PRESETS[preset]["sections"])
    if plan is not None:
        for sec in sections:
            if "reuse" not in sec:
                sec["pool"] = dict(sec.get("pool") or {}, plan=plan)
    return sections


def create_study_from_preset(preset: str, slug: str, title: str | None = None, status: str = "draft",
                             plan: str | None = _OWN_PLAN, **study_fields):
    """Create a Study and its Sections from a preset. Raises KeyError naming the preset if unknown.

    Every section pool draws only clips of ``plan``: by default the preset's own plan (:data:`PRESET_PLANS`), so a
    paper's study never shows demo clips; another plan name for a copy of a paper plan; None for no plan filter.
    """

    if preset not in PRESETS:
        raise KeyError(f"unknown preset {preset!r}; choose one of {sorted(PRESETS)}")
    spec = copy.deepcopy(PRESETS[preset])
    spec["sections"] = preset_sections(preset, plan)
    with transaction.atomic():
        study = Study.objects.create(
            slug=slug, title=title or spec["title"], preset=preset, status=status,
            introduction=spec.get("introduction", ""), consent_text=spec.get("consent_text", CONSENT),
            feedback_questions=spec.get("feedback_questions", []), **study_fields)
        created: list[Section] = []
        for order, sec in enumerate(spec["sections"], start=1):
            reuse = sec.pop("reuse", None)
            created.append(Section.objects.create(
                study=study, order=order,
                reuse_section=created[reuse] if reuse is not None else None,
                **{k: v for k, v in sec.items()}))
    return study
