"""The clips of each section's pool, cached per study so a participant's start does not query the catalogue.

A cache entry holds, per section: its pool's clips (light Clip rows: only the fields planning and the clip page
use), the pks of the naturalness ``generated``/``source`` sub-pools, and the practice candidates (clips of the
section's modality outside its pool). The key is the study id, a hash of every section's pool and options, and
the catalogue's version (max ``updated_at``, number of clips, number of usable clips: one aggregate query), so an
edited section, a new render or a retired clip gives a new key; stale entries simply expire.
Django's cache (``CACHES``; per-process local memory by default) holds it.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field

from django.core.cache import cache
from django.db.models import Count, Max, Q

from protocol.pools import SUB_POOLS
from protocol.section_types import is_page_type
from protocol.vocabulary import SECTION_MODALITY

from ..models import Clip, Section
from .catalogue import pool_queryset, section_queryset

CLIP_FIELDS = ("id", "clip_id", "modality", "origin", "source_clip_id", "emotion_label", "theme", "duration_s",
               "media_key", "video", "webm", "poster", "loop")
"""The Clip fields a start and a clip page need (the rest stays in the database)."""

CACHE_SECONDS = 600


@dataclass
class SectionPool:
    """A section's pool: clips in clip_id order, sub-pool pks (naturalness), practice candidates and the dedicated
    attention-check clip (``attention_checks.clip``; None when the section names none or it is not in the
    catalogue)."""
    clips: list[Clip] = field(default_factory=list)
    sub_pools: dict[str, set[int]] = field(default_factory=dict)
    practice: list[Clip] = field(default_factory=list)
    check_clip: Clip | None = None

    @property
    def pks(self) -> set[int]:
        return {c.pk for c in self.clips}


def light(qs):
    """A Clip queryset limited to CLIP_FIELDS."""
    return qs.only(*CLIP_FIELDS)


def practice_modality(section: Section) -> str | None:
    """The modality of a practice clip: the section type's, else the pool's ``modality`` filter."""
    wanted = SECTION_MODALITY.get(section.section_type)
    pool_modality = (section.pool or {}).get("modality")
    return wanted or (pool_modality if isinstance(pool_modality, str) else None)


def dedicated_check_clip(section: Section) -> Clip | None:
    """The clip the section's options name for its attention checks (``attention_checks.clip``), if any."""
    options = section.options if isinstance(section.options, dict) else {}
    config = options.get("attention_checks")
    clip_id = config.get("clip") if isinstance(config, dict) else None
    if not isinstance(clip_id, str) or not clip_id:
        return None
    return light(Clip.objects.filter(clip_id=clip_id, retired=False)).first()


def load_section_pool(section: Section) -> SectionPool:
    """Query one section's pool (no cache). A reusing section has no pool of its own (its checks draw on the
    reused section's). An instruction or break page has none."""
    if is_page_type(section.section_type):
        return SectionPool()
    if section.reuse_section_id:
        return SectionPool(check_clip=dedicated_check_clip(section))
    clips = list(light(section_queryset(section.section_type, section.pool)).order_by("clip_id"))
    # a sub-pool only narrows the section's pool, which already decided about flagged clips
    subs = {key: set(pool_queryset(section.pool[key], include_flagged=True).filter(pk__in=[c.pk for c in clips])
                     .values_list("pk", flat=True))
            for key in SUB_POOLS if isinstance((section.pool or {}).get(key), dict) and section.pool[key]}
    practice = []
    options = section.options if isinstance(section.options, dict) else {}
    if options.get("practice_clip"):
        practice = list(light(Clip.objects.filter(clip_id=options["practice_clip"])))
    elif options.get("practice"):
        qs = Clip.objects.filter(retired=False).exclude(pk__in=[c.pk for c in clips])
        modality = practice_modality(section)
        if modality:
            qs = qs.filter(modality=modality)
        practice = list(light(qs).order_by("clip_id")[:50])
    return SectionPool(clips, subs, practice, dedicated_check_clip(section))


def catalogue_version() -> str:
    """Changes whenever a clip is added, saved, retired or deleted (one aggregate query)."""
    v = Clip.objects.aggregate(latest=Max("updated_at"), n=Count("id"), usable=Count("id", filter=Q(retired=False)))
    return f"{v['latest'].isoformat() if v['latest'] else '-'}:{v['n']}:{v['usable']}"


def _sections_hash(sections: list[Section]) -> str:
    spec = [(s.pk, s.section_type, s.reuse_section_id, s.pool, s.options) for s in sections]
    return hashlib.sha1(json.dumps(spec, sort_keys=True, default=str).encode()).hexdigest()[:16]


def section_pools(study_id: int, sections: list[Section]) -> dict[int, SectionPool]:
    """Section pk -> SectionPool for the given sections of one study, from the cache when it is current."""
    key = f"studyapp:pools:{study_id}:{_sections_hash(sections)}:{catalogue_version()}"
    pools = cache.get(key)
    if pools is None:
        pools = {s.pk: load_section_pool(s) for s in sections}
        cache.set(key, pools, CACHE_SECONDS)
    return pools
