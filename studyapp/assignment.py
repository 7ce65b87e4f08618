"""Per-participant randomized, balanced clip assignment and the participant's position in the study.

Rules (seed 000 section 6.1, seed 003 section 6.1, seed 004 section V):
- every participant gets a recorded random seed; the clips of each section are drawn with it;
- balanced: within a section the clips with the fewest assignments so far come first (ties broken at random);
- no clip twice for one participant, except in a section that reuses another section's clips on purpose;
- naturalness mixes generated and source clips, unlabelled, in random order, and never shows a generated clip
  whose source clip is also shown (seed 003);
- gesture_emotion records four options: the intended emotion and three others drawn from the 11 categories.
Assignment happens once, inside a transaction that row-locks the study (`select_for_update`; PostgreSQL serialises
concurrent starters on it, SQLite serialises all writers anyway), so counts stay balanced under concurrent arrivals
and the participant limit holds.
"""
from __future__ import annotations

import random
from collections import Counter
from dataclasses import dataclass, field
from datetime import timedelta

from django.db import transaction
from django.db.models import Count
from django.utils import timezone

from study_protocol import GESTURE_EMOTIONS

from .catalogue import pool_queryset
from .models import Assignment, Clip, Participant, Section, Study
from .pools import DEFAULT_GESTURE_OPTIONS, SUB_POOLS


class StudyUnavailable(Exception):
    """The study is closed, or full; the message says which, for the participant."""


@dataclass
class PlannedItem:
    clip: Clip
    options: list[str] = field(default_factory=list)


def _rng(seed: int, section: Section) -> random.Random:
    return random.Random(f"{seed}:{section.pk}:{section.order}")


def _balanced_pick(rng: random.Random, clips: list[Clip], counts: dict[int, int], k: int) -> list[Clip]:
    """k clips with the fewest assignments so far; random among equals. k <= 0 means all."""
    clips = list(clips)
    rng.shuffle(clips)
    clips.sort(key=lambda c: counts.get(c.pk, 0))     # stable: keeps the random order among ties
    return clips if k <= 0 else clips[:k]


def _section_counts(section: Section) -> dict[int, int]:
    rows = (Assignment.objects.filter(section=section).values("clip_id").annotate(n=Count("id")))
    return {r["clip_id"]: r["n"] for r in rows}


def _gesture_options(rng: random.Random, clip: Clip, section: Section) -> list[str]:
    categories = list(section.options.get("categories") or GESTURE_EMOTIONS)
    n_options = int(section.options.get("n_options", DEFAULT_GESTURE_OPTIONS))
    intended = clip.emotion_label or "neutral"
    others = [c for c in categories if c != intended]
    shown = [intended, *rng.sample(others, min(n_options - 1, len(others)))]
    rng.shuffle(shown)
    return shown


def plan_section(section: Section, seed: int, used: set[int], earlier: dict[int, list[PlannedItem]],
                 counts: dict[int, int] | None = None) -> list[PlannedItem]:
    """The ordered clips of one section for one participant (no DB writes).

    used: pks of clips already given to this participant (excluded); earlier: section pk -> planned items of the
    sections before this one (for reuse); counts: clip pk -> assignments so far in this section (balancing).
    """
    rng = _rng(seed, section)
    counts = counts or {}
    if section.reuse_section_id:
        if section.reuse_section_id not in earlier:
            raise ValueError(f"section {section} reuses a section that does not come before it")
        items = [PlannedItem(it.clip) for it in earlier[section.reuse_section_id]]
        if section.randomize_order:
            rng.shuffle(items)
        return items
    base = [c for c in pool_queryset(section.pool) if c.pk not in used]
    k = section.clips_per_participant
    if section.section_type == "naturalness" and (any(key in section.pool for key in SUB_POOLS)
                                                  or "n_source" in section.options):
        n_source = int(section.options.get("n_source", k // 2 if k else 0))
        n_generated = int(section.options.get("n_generated", (k - n_source) if k else 0))
        sources = [c for c in base if c.origin == "source" and _matches(c, section.pool.get("source"))]
        generated = [c for c in base if c.origin == "generated" and _matches(c, section.pool.get("generated"))]
        chosen_src = _pick_sources(rng, sources, generated, counts, n_source, n_generated)
        src_ids = {c.clip_id for c in chosen_src}
        generated = [c for c in generated if c.source_clip_id not in src_ids]
        chosen = chosen_src + (_balanced_pick(rng, generated, counts, n_generated) if n_generated else [])
        rng.shuffle(chosen)          # mixed, unlabelled, random order (seed 003)
        return [PlannedItem(c) for c in chosen]
    chosen = _balanced_pick(rng, base, counts, k)
    if section.randomize_order:
        rng.shuffle(chosen)
    else:
        chosen.sort(key=lambda c: c.clip_id)
    items = [PlannedItem(c) for c in chosen]
    if section.section_type == "gesture_emotion":
        for it in items:
            it.options = _gesture_options(rng, it.clip, section)
    return items


def _pick_sources(rng: random.Random, sources: list[Clip], generated: list[Clip], counts: dict[int, int],
                  n_source: int, n_generated: int) -> list[Clip]:
    """Balanced source clips, skipping one whose generated version is needed to still fill n_generated."""
    if n_source <= 0:
        return []
    ordered = _balanced_pick(rng, sources, counts, 0)
    by_source = Counter(c.source_clip_id for c in generated if c.source_clip_id)
    eligible = len(generated)
    chosen, skipped = [], []
    for c in ordered:
        if len(chosen) == n_source:
            break
        blocked = by_source.get(c.clip_id, 0)
        if eligible - blocked >= n_generated:
            chosen.append(c)
            eligible -= blocked
        else:
            skipped.append(c)
    return chosen + skipped[:n_source - len(chosen)]


def _matches(clip: Clip, sub_pool: dict | None) -> bool:
    if not sub_pool:
        return True
    return pool_queryset(sub_pool).filter(pk=clip.pk).exists()


def plan_study(study: Study, seed: int, balanced: bool = True) -> list[tuple[Section, list[PlannedItem]]]:
    """Plan every section of `study` for a participant with `seed` (no writes; previews use balanced=False)."""
    used: set[int] = set()
    earlier: dict[int, list[PlannedItem]] = {}
    plan = []
    for section in study.sections.order_by("order", "id"):
        counts = _section_counts(section) if balanced else {}
        items = plan_section(section, seed, used, earlier, counts)
        earlier[section.pk] = items
        if not section.reuse_section_id:
            used.update(it.clip.pk for it in items)
        plan.append((section, items))
    return plan


def active_count(study: Study) -> int:
    """Participants who hold a place: completed ones, and started ones not inactive past the study's timeout."""
    qs = study.participants.filter(status__in=[Participant.Status.STARTED, Participant.Status.COMPLETED])
    if study.abandon_after_minutes:
        cutoff = timezone.now() - timedelta(minutes=study.abandon_after_minutes)
        qs = qs.exclude(status=Participant.Status.STARTED, last_active_at__lt=cutoff)
    return qs.count()


def check_open(study: Study) -> None:
    if study.status != Study.Status.OPEN:
        raise StudyUnavailable("This study is closed and is not accepting participants. Thank you for your interest.")
    if study.max_participants and active_count(study) >= study.max_participants:
        raise StudyUnavailable("This study is full: it has all the participants it needs. Thank you for your interest.")


def start_participant(participant: Participant) -> bool:
    """Fix the participant's clips for every section (once). Returns True if this call assigned them.

    Raises StudyUnavailable if the study closed or filled up before this participant started.
    """
    with transaction.atomic():
        study = Study.objects.select_for_update().get(pk=participant.study_id)
        p = Participant.objects.select_for_update().get(pk=participant.pk)
        if p.status != Participant.Status.CONSENTED:
            return False
        check_open(study)
        rows = []
        for section, items in plan_study(study, p.seed):
            rows += [Assignment(participant=p, section=section, position=i, clip=it.clip, options=it.options)
                     for i, it in enumerate(items)]
        Assignment.objects.bulk_create(rows)
        p.status = Participant.Status.STARTED
        p.started_at = p.last_active_at = timezone.now()
        p.save(update_fields=["status", "started_at", "last_active_at"])
    participant.refresh_from_db()
    return True


@dataclass
class Step:
    """Where a participant is: kind in demographics | start | item | feedback | done."""
    kind: str
    assignment: Assignment | None = None
    index: int = 0          # 1-based number of this clip among all of the participant's clips
    total: int = 0


def current_step(participant: Participant) -> Step:
    """The participant's next page, computed from the database only (so reloads and restarts resume)."""
    study = participant.study
    if study.ask_demographics and not participant.demographics_done:
        return Step("demographics")
    if participant.status == Participant.Status.CONSENTED:
        return Step("start")
    assignments = list(participant.assignments.select_related("section", "clip").order_by("section__order",
                                                                                           "section_id", "position"))
    total = len(assignments)
    for i, a in enumerate(assignments):
        if a.answered_at is None:
            return Step("item", a, i + 1, total)
    if study.feedback_questions and not participant.feedback_done:
        return Step("feedback", None, total, total)
    return Step("done", None, total, total)
