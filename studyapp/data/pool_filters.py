"""The clips a pool's filters admit before any norms rule: not retired, through the quality gate, matching the
filter lookups (protocol.pools). :func:`studyapp.data.catalogue.pool_queryset` adds the norms rule on top; the exports,
which list a study's pool clips without judging norms, read this module directly, so the norms service (which
exports a study to compute its norms) and the catalogue do not import each other.
"""
from __future__ import annotations

from itertools import combinations

from django.db.models import Q, QuerySet

from protocol.pools import INCLUDE_FLAGGED, PoolError, kept_checks, pool_lookups
from protocol.vocabulary import QA_CHECKS

from ..models import Clip


def kept_flags(checks: tuple[str, ...]) -> tuple[str, ...]:
    """Every ``qa_flag`` value made only of ``checks`` (joined in QA_CHECKS order), "" (passed) first."""
    ordered = [c for c in QA_CHECKS if c in checks]
    return ("", *(";".join(subset) for n in range(1, len(ordered) + 1) for subset in combinations(ordered, n)))


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
    """Clips (not retired) matching the pool's filters, a norms rule aside. Clips that failed a quality check are
    left out unless ``include_flagged`` (default: the pool's ``include_flagged``) or the pool's switches keep the
    checks they failed (``protocol.pools.kept_checks``: ``keep_advisory`` the advisory ones, ``observer_advisory``
    the observer's); for the clips in ``normed`` (those with norms) under a norms rule the observer's check is kept
    too. CatalogueError naming the filter when the pool is not valid."""
    calls = pool_calls(pool)
    qs = Clip.objects.filter(retired=False)
    if include_flagged is None:
        include_flagged = bool((pool or {}).get(INCLUDE_FLAGGED, False))
    if not include_flagged:
        kept = kept_checks(pool)
        flags = Q(qa_flag__in=kept_flags(kept))
        with_norms = kept_checks(pool, normed=True)
        if normed and with_norms != kept:      # a norm outranks an observer for clips people rated
            flags |= Q(qa_flag__in=kept_flags(with_norms), clip_id__in=normed)
        qs = qs.filter(flags)
    for method, kwargs in calls:
        qs = getattr(qs, method)(**kwargs)
    return qs
