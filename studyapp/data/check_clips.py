"""Whether a section's attention checks have clips of their own: the admin's check when a section is saved.

A check never shows a clip the participant rates (studyapp.participant.trial_extras). Its clips are the dedicated check
clip (``attention_checks.clip``), the pool clips a participant does not rate (the pool's size minus the clips each
participant rates from it; a reusing section: the reused section's), and the practice clip. A section whose checks
would find fewer clips than ``count`` is refused with a message that says what to add. Other sections drawing on
the same clips can take spares too; the planner then gives fewer checks, never a rated clip.
"""
from __future__ import annotations

from protocol.pools import PoolError
from protocol.section_types import find_section_type, page_types

from ..models import Clip, Section
from .catalogue import section_queryset
from .pool_cache import practice_modality


def rated_per_participant(section: Section, pool_size: int) -> int:
    """How many clips of its pool one participant rates in ``section`` (0 = the whole pool; naturalness: the
    generated + source counts when it sets them: a type's sub-pools, each counted by ``n_<sub-pool>``)."""
    options = section.options if isinstance(section.options, dict) else {}
    k = section.clips_per_participant
    spec = find_section_type(section.section_type)
    halves = [f"n_{half}" for half in (spec.sub_pools if spec else ())]
    if any(key in options for key in halves):
        k = max(k, sum(int(options.get(key, 0) or 0) for key in halves))
    return pool_size if k <= 0 else min(k, pool_size)


def spare_pool_clips(section: Section) -> int:
    """Clips of the pool a section's checks draw (its own, or the reused section's) that a participant does not
    rate there. One COUNT query; 0 when the pool is malformed (its own errors say why)."""
    source = section.reuse_section if section.reuse_section_id else section
    if source is None:
        return 0
    try:
        size = section_queryset(source.section_type, source.pool).count()
    except (PoolError, ValueError, TypeError):
        return 0
    return size - rated_per_participant(source, size)


def _in_pool(section: Section, clip: Clip) -> bool:
    try:
        return section_queryset(section.section_type, section.pool).filter(pk=clip.pk).exists()
    except (PoolError, ValueError, TypeError):
        return False


def _practice_clip_exists(section: Section, options: dict) -> bool:
    """Whether the section's practice item will have a clip (the named one, or a clip of its modality outside its
    pool, as studyapp.data.pool_cache draws them)."""
    if isinstance(options.get("practice_clip"), str) and options["practice_clip"]:
        return Clip.objects.filter(clip_id=options["practice_clip"]).exists()
    if not options.get("practice"):
        return False
    qs = Clip.objects.filter(retired=False)
    if not section.reuse_section_id:
        try:
            qs = qs.exclude(pk__in=section_queryset(section.section_type, section.pool).values("pk"))
        except (PoolError, ValueError, TypeError):
            return False
    modality = practice_modality(section)
    return (qs.filter(modality=modality) if modality else qs).exists()


def _rating_section(section: Section, clip: Clip) -> Section | None:
    """Another section of the study whose pool holds ``clip`` (participants may rate it there), if any."""
    if not section.study_id:
        return None
    others = (Section.objects.filter(study_id=section.study_id, reuse_section__isnull=True).exclude(pk=section.pk)
              .exclude(section_type__in=[t.name for t in page_types()]))     # a page rates no clip
    return next((s for s in others.order_by("order", "id") if _in_pool(s, clip)), None)


def check_clip_problems(section: Section) -> list[str]:
    """Messages for ``Section.options`` when its attention checks cannot all have a clip no participant rates
    (none when it asks for no checks or they are malformed: protocol.pools reports those)."""
    options = section.options if isinstance(section.options, dict) else {}
    config = options.get("attention_checks")
    if not isinstance(config, dict) or not config:
        return []
    count = config.get("count") or (len(config["positions"]) if isinstance(config.get("positions"), list) else 1)
    if not isinstance(count, int) or count < 1:
        return []
    problems, dedicated = [], 0
    clip_id = config.get("clip")
    if isinstance(clip_id, str) and clip_id:
        clip = Clip.objects.filter(clip_id=clip_id).first()
        if clip is None or clip.retired:
            problems.append(f"'attention_checks': 'clip' {clip_id!r} is not a usable clip of the catalogue")
        elif not section.reuse_section_id and _in_pool(section, clip):
            problems.append(f"'attention_checks': 'clip' {clip_id!r} is in this section's pool, so participants "
                            "may rate it; choose a clip outside the pools of the study")
        elif (other := _rating_section(section, clip)) is not None:
            problems.append(f"'attention_checks': 'clip' {clip_id!r} is in the pool of section {other.order} "
                            f"({other.section_type}), so participants may rate it; choose a clip outside the pools "
                            "of the study")
        else:
            dedicated = 1
    practice = 1 if _practice_clip_exists(section, options) else 0
    spare = spare_pool_clips(section)
    available = dedicated + max(spare, 0) + practice
    if available < count and not problems:
        problems.append(
            f"'attention_checks': {count} check(s) need as many clips that participants do not rate, and this "
            f"section has {available} (spare pool clips: {max(spare, 0)}, dedicated check clip: {dedicated}, practice "
            f"clip: {practice}). A check on a rated clip would prime the answer the study measures: name a "
            "dedicated check clip (attention_checks.clip), add a practice item, let participants rate fewer clips "
            "than the pool holds, or ask for fewer checks.")
    return problems
