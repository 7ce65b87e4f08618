"""The clips a pool's filters admit before any norms rule: not retired, through the quality gate, matching the
filter lookups (protocol.pools). :func:`studyapp.catalogue.pool_queryset` adds the norms rule on top; the exports,
which list a study's pool clips without judging norms, read this module directly, so the norms service (which
exports a study to compute its norms) and the catalogue do not import each other.
"""
from __future__ import annotations

from itertools import combinations

from django.db.models import Q, QuerySet

from protocol.pools import INCLUDE_FLAGGED, OBSERVER_ADVISORY, PoolError, pool_lookups
from protocol.vocabulary import QA_ADVISORY_CHECKS, QA_CHECKS

from .models import Clip

#: ``qa_flag`` values that keep a clip in pools: passed, or failed only advisory checks (in QA_CHECKS order).
ADVISORY_FLAGS = ("", *(";".join(c for c in QA_CHECKS if c in subset)
                        for n in range(1, len(QA_ADVISORY_CHECKS) + 1)
                        for subset in combinations(QA_ADVISORY_CHECKS, n)))

#: ``qa_flag`` values that failed only the observer check and advisory ones: they keep a clip in a pool that says
#: ``observer_advisory`` (a norming section's candidates), and a clip with norms in a pool with a norms rule.
OBSERVER_ADVISORY_FLAGS = tuple(";".join(c for c in QA_CHECKS if c in subset)
                                for n in range(1, len(QA_ADVISORY_CHECKS) + 2)
                                for subset in combinations(("observer", *QA_ADVISORY_CHECKS), n)
                                if "observer" in subset)


class CatalogueError(ValueError):
    """A clip record or pool filter that cannot be used; the message names the record/field."""


def pool_calls(pool: dict | None) -> list[tuple[str, dict]]:
    """The ORM calls of a pool's filters (protocol.pools.pool_lookups); CatalogueError naming the bad filters."""
    try:
        return pool_lookups(pool)
    except PoolError as exc:
        raise CatalogueError(f"pool: {'; '.join(exc.errors['pool'])}") from exc


def filtered_clips(pool: dict | None, include_flagged: bool | None = None, normed: set[str] | None = None
                   ) -> QuerySet:
    """Clips (not retired) matching the pool's filters, a norms rule aside. Clips that failed a non-advisory quality
    check are left out unless ``include_flagged`` (default: the pool's ``include_flagged``); the observer's check is
    advisory in a pool that says ``observer_advisory`` and, for the clips in ``normed`` (those with norms), in a
    pool with a norms rule. CatalogueError naming the filter when the pool is not valid."""
    calls = pool_calls(pool)
    qs = Clip.objects.filter(retired=False)
    if include_flagged is None:
        include_flagged = bool((pool or {}).get(INCLUDE_FLAGGED, False))
    if not include_flagged:
        flags = Q(qa_flag__in=ADVISORY_FLAGS)
        if (pool or {}).get(OBSERVER_ADVISORY):
            flags |= Q(qa_flag__in=OBSERVER_ADVISORY_FLAGS)
        elif normed:      # a norm outranks an observer: its verdict is advisory for clips people rated
            flags |= Q(qa_flag__in=OBSERVER_ADVISORY_FLAGS, clip_id__in=normed)
        qs = qs.filter(flags)
    for method, kwargs in calls:
        qs = getattr(qs, method)(**kwargs)
    return qs
