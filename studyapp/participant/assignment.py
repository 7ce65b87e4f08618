"""Per-participant randomized, balanced clip assignment and the participant's position in the study.

Rules (seed 000 section 6.1, seed 003 section 6.1, seed 004 section V):
- every participant gets a recorded random seed; the clips of each section are drawn with it;
- balanced: within a section the clips with the fewest assignments so far come first (ties broken at random); a
  norming section (``options["norming"]``) follows the cyclic balanced incomplete design of protocol.norming instead,
  balanced over participants and positions;
- no clip twice for one participant, except in a section that reuses another section's clips on purpose;
- naturalness mixes generated and source clips, unlabelled, in random order, and never shows a generated clip
  whose source clip is also shown (seed 003);
- gesture_emotion records four options: the intended emotion and three others drawn from the 11 categories;
- practice items and attention checks (studyapp.participant.trial_extras) and the counterbalanced section order
  (studyapp.participant.counterbalance) are fixed at the start too, and so are the instruction and break pages
  (studyapp.data.section_pages: sections without clips, recorded on the participant, each before the clip it precedes).

Concurrency: a start plans without any lock: pools from a per-study cache (studyapp.data.pool_cache), the
balancing counts from SectionClipCount (one row per section and pool clip) read plainly. Its transaction then
claims the participant, locks the count rows of its sections (FOR NO KEY UPDATE on PostgreSQL, in (section, clip)
order; SQLite runs one writer at a time anyway), plans again only if another start changed the counts meanwhile
(in memory, from the cached pools), adds its clips with F() updates, inserts its assignments and commits. Starts
therefore queue only for that short tail, never for another's planning, and the counts every start sees are
exact: the balance is that of one-at-a-time starts (spread of a section's clips at most 1 where the pool allows;
a section that draws from clips an earlier section also takes, such as demo naturalness after emotion_choice, can
reach 2, as with sequential starts). The participant limit is exact: the check runs last, under a row lock on the
study's counter row (StudyCounter), held only for the count and the commit.
"""
from __future__ import annotations

import random
import threading
import time
from collections import Counter
from contextlib import nullcontext
from dataclasses import dataclass
from datetime import timedelta

from django.db import OperationalError, connection, transaction
from django.db.models import F
from django.utils import timezone

from protocol.norming import clip_order, cyclic_block, ratings_per_clip
from protocol.pools import SUB_POOLS
from protocol.section_types import get_section_type

from ..data.pool_cache import SectionPool, load_section_pool, section_pools
from ..data.section_pages import due_page, is_page, page_records
from ..models import Assignment, Clip, Participant, Section, SectionClipCount, Study, StudyCounter
from .counterbalance import SectionInfo, attach_pages, section_order
from .page_reads import open_assignments
from .trial_extras import PlannedItem, gesture_options, with_extras

__all__ = ["PlannedItem", "Step", "StudyUnavailable", "active_count", "check_open", "current_step",
           "plan_section", "plan_study", "start_participant"]


class StudyUnavailable(Exception):
    """The study is closed, or full; the message says which, for the participant."""


def _rng(seed: int, section: Section) -> random.Random:
    return random.Random(f"{seed}:{section.pk}:{section.order}")


def _balanced_pick(rng: random.Random, clips: list[Clip], counts: dict[int, int], k: int) -> list[Clip]:
    """k clips with the fewest assignments so far; random among equals. k <= 0 means all."""
    clips = list(clips)
    rng.shuffle(clips)
    clips.sort(key=lambda c: counts.get(c.pk, 0))     # stable: keeps the random order among ties
    return clips if k <= 0 else clips[:k]


def plan_section(section: Section, seed: int, used: set[int], earlier: dict[int, list[PlannedItem]],
                 counts: dict[int, int] | None = None, pool: SectionPool | None = None) -> list[PlannedItem]:
    """The ordered clips of one section for one participant (no DB writes; practice and checks not included).

    used: pks of clips already given to this participant (excluded); earlier: section pk -> planned items of the
    sections before this one (for reuse); counts: clip pk -> assignments so far in this section (balancing);
    pool: the section's cached pool (studyapp.data.pool_cache; queried when None).
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
    pool = pool if pool is not None else load_section_pool(section)
    base = [c for c in pool.clips if c.pk not in used]
    k = section.clips_per_participant
    spec = get_section_type(section.section_type)
    if spec.sub_pools and (any(key in section.pool for key in SUB_POOLS) or "n_source" in section.options):
        chosen = _plan_naturalness(section, rng, base, pool, counts, k)
        rng.shuffle(chosen)          # mixed, unlabelled, random order (seed 003)
        return [PlannedItem(c) for c in chosen]
    if spec.norming and ratings_per_clip(section.options) is not None:
        chosen = _plan_norming(section, pool.clips, used, counts, k)   # the design fixes the order too
    else:
        chosen = _balanced_pick(rng, base, counts, k)
        if section.randomize_order:
            rng.shuffle(chosen)
        else:
            chosen.sort(key=lambda c: c.clip_id)
    items = [PlannedItem(c) for c in chosen]
    if spec.drawn_choices:
        for it in items:
            it.options = gesture_options(rng, section, it.clip.emotion_label or "neutral")
    return items


def _plan_norming(section: Section, clips: list[Clip], used: set[int], counts: dict[int, int], k: int
                  ) -> list[Clip]:
    """A norming section's clips for the next participant, in the order shown: the cyclic balanced incomplete
    design of protocol.norming over the pool in its fixed order (seeded by the section), the participant's ordinal
    being the section's trial assignments so far / M. Clips this participant already has are skipped."""
    by_id = {c.clip_id: c for c in clips}
    order = clip_order(list(by_id), str(section.pk))
    m = min(k, len(order)) if k > 0 else len(order)
    ordinal = sum(counts.get(c.pk, 0) for c in clips) // max(m, 1)
    return [c for c in (by_id[order[i]] for i in cyclic_block(len(order), m, ordinal)) if c.pk not in used]


def _in_sub_pool(pool: SectionPool, key: str, clip: Clip) -> bool:
    return key not in pool.sub_pools or clip.pk in pool.sub_pools[key]


def _plan_naturalness(section: Section, rng: random.Random, base: list[Clip], pool: SectionPool,
                      counts: dict[int, int], k: int) -> list[Clip]:
    """Balanced source and generated clips of a naturalness section, no generated clip with its source."""
    n_source = int(section.options.get("n_source", k // 2 if k else 0))
    n_generated = int(section.options.get("n_generated", (k - n_source) if k else 0))
    sources = [c for c in base if c.origin == "source" and _in_sub_pool(pool, "source", c)]
    generated = [c for c in base if c.origin == "generated" and _in_sub_pool(pool, "generated", c)]
    chosen_src = _pick_sources(rng, sources, generated, counts, n_source, n_generated)
    src_ids = {c.clip_id for c in chosen_src}
    generated = [c for c in generated if c.source_clip_id not in src_ids]
    return chosen_src + (_balanced_pick(rng, generated, counts, n_generated) if n_generated else [])


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


def read_counts(sections: list[Section], lock: bool = False) -> dict[int, dict[int, int]]:
    """Section pk -> clip pk -> participants given the clip there so far (one query). lock: row-lock the counts
    (FOR NO KEY UPDATE, in (section, clip) order so two starts never deadlock) until the transaction ends."""
    out: dict[int, dict[int, int]] = {s.pk: {} for s in sections}
    rows = SectionClipCount.objects.filter(section__in=[s.pk for s in sections])
    if lock:
        rows = rows.select_for_update(no_key=True).order_by("section_id", "clip_id")
    for section_id, clip_id, n in rows.values_list("section_id", "clip_id", "n"):
        out[section_id][clip_id] = n
    return out


def plan_study(study: Study, seed: int, balanced: bool = True, sections: list[Section] | None = None,
               pools: dict[int, SectionPool] | None = None, counts: dict[int, dict[int, int]] | None = None,
               extras: bool = False) -> list[tuple[Section, list[PlannedItem]]]:
    """Plan every section of `study` for a participant with `seed`, in the study's order (no writes); the
    instruction and break pages are left out (they have no clips).

    balanced: use the balancing counts (previews pass False); sections/pools/counts: already loaded ones (the
    start passes them; otherwise they are queried); extras: add practice items and attention checks.
    """
    sections = [s for s in (sections if sections is not None else study.sections.order_by("order", "id"))
                if not is_page(s)]          # instruction and break pages show no clips
    pools = pools if pools is not None else {s.pk: load_section_pool(s) for s in sections}
    if counts is None:
        counts = read_counts(sections) if balanced else {}
    used: set[int] = set()
    earlier: dict[int, list[PlannedItem]] = {}
    plan = []
    for section in sections:
        pool = pools.get(section.pk) or SectionPool()
        items = plan_section(section, seed, used, earlier, counts.get(section.pk, {}), pool)
        earlier[section.pk] = items
        if not section.reuse_section_id:
            used.update(it.clip.pk for it in items)
        plan.append((section, items))
    if extras:
        taken: set[int] = set()
        plan = [(section, with_extras(section, items, _check_pool(section, pools), _pool(section, pools).practice,
                                      used, seed, _pool(section, pools).check_clip, taken))
                for section, items in plan]
    return plan


def _pool(section: Section, pools: dict[int, SectionPool]) -> SectionPool:
    return pools.get(section.pk) or SectionPool()


def _check_pool(section: Section, pools: dict[int, SectionPool]) -> list[Clip]:
    """The clips a section's attention checks may draw (those the participant rates are skipped later): its
    pool, or for a section that reuses another's clips the reused section's pool."""
    own = _pool(section, pools)
    if section.reuse_section_id:
        return (pools.get(section.reuse_section_id) or SectionPool()).clips
    return own.clips


def active_count(study: Study) -> int:
    """Participants who hold a place: completed ones, and started ones not inactive past the study's timeout."""
    qs = study.participants.filter(status__in=[Participant.Status.STARTED, Participant.Status.COMPLETED])
    if study.abandon_after_minutes:
        cutoff = timezone.now() - timedelta(minutes=study.abandon_after_minutes)
        qs = qs.exclude(status=Participant.Status.STARTED, last_active_at__lt=cutoff)
    return qs.count()


STUDY_CLOSED = "This study is closed and is not accepting participants. Thank you for your interest."
STUDY_FULL = "This study is full: it has all the participants it needs. Thank you for your interest."


def check_open(study: Study) -> None:
    """Raise StudyUnavailable when the study is not open (a draft in pilot mode is) or has all the participants it
    needs."""
    if study.status != Study.Status.OPEN and not (study.pilot and study.status == Study.Status.DRAFT):
        raise StudyUnavailable(STUDY_CLOSED)
    if study.max_participants and active_count(study) >= study.max_participants:
        raise StudyUnavailable(STUDY_FULL)


def _counter(study_id: int):
    """The study's StudyCounter row as a queryset (the row is created on first use)."""
    StudyCounter.objects.get_or_create(study_id=study_id)
    return StudyCounter.objects.filter(study_id=study_id)


def next_arrival(study_id: int) -> int:
    """The 0-based arrival index of the next starting participant (its own short transaction: the counter row
    is locked for one UPDATE and one SELECT). A start that then fails leaves a gap, which only shifts rows."""
    with _one_writer(), transaction.atomic():
        counter = _counter(study_id)
        counter.update(arrivals=F("arrivals") + 1)
        return counter.values_list("arrivals", flat=True).get() - 1


def participant_order(study: Study, sections: list[Section]) -> list[Section]:
    """The sections in the order this (next) participant takes them: the study's order, or a Williams row of the
    rotating sections by arrival index when the study counterbalances (studyapp.participant.counterbalance). Instruction
    and break pages do not rotate themselves: each travels with the section that follows it (``attach_pages``)."""
    pages = {s.pk for s in sections if is_page(s)}
    rotating = [s for s in sections if s.pk not in pages]
    infos = [SectionInfo(s.pk, s.counterbalance, s.reuse_section_id) for s in rotating]
    if not study.counterbalance_sections or sum(s.counterbalance for s in rotating) < 2:
        return list(sections)
    by_pk = {s.pk: s for s in sections}
    order = section_order(infos, next_arrival(study.pk))
    return [by_pk[pk] for pk in attach_pages(order, [s.pk for s in sections], pages)]


def _assignment_rows(participant: Participant, plan: list[tuple[Section, list[PlannedItem]]],
                     order: list[Section]) -> list[Assignment]:
    """Assignment rows of a plan in the participant's section order, seq 1..n over the study."""
    by_section = {section.pk: items for section, items in plan}
    rows, seq = [], 0
    for section in order:
        for position, it in enumerate(by_section.get(section.pk, ())):     # a page has no clips
            seq += 1
            rows.append(Assignment(participant=participant, section=section, position=position, clip=it.clip,
                                   options=it.options, seq=seq, kind=it.kind, instructed=it.instructed))
    return rows


def start_participant(participant: Participant) -> bool:
    """Fix the participant's clips for every section (once). Returns True if this call assigned them.

    Raises StudyUnavailable if the study closed or filled up before this participant started.
    """
    started = _with_retries(lambda: _start(participant))
    _with_retries(participant.refresh_from_db)
    return started


def _start(participant: Participant) -> bool:
    """Plan without any lock (cached pools, counts read plainly), then the start's short transaction."""
    p = Participant.objects.select_related("study").get(pk=participant.pk)
    if p.status != Participant.Status.CONSENTED:
        return False
    study = p.study
    check_open(study)
    every = list(study.sections.order_by("order", "id"))
    sections = [s for s in every if not is_page(s)]       # the sections with clips; pages only take a place
    pools = section_pools(study.pk, sections)
    balanced = [s for s in sections if not s.reuse_section_id]
    counts = read_counts(balanced)
    _ensure_count_rows(balanced, pools, counts)
    plan = plan_study(study, p.seed, sections=sections, pools=pools, counts=counts, extras=True)
    order = participant_order(study, every)

    def fresh_plan():
        """In the transaction: lock the counts; plan again only if they changed since planning."""
        locked = read_counts(balanced, lock=True)
        if _nonzero(locked) == _nonzero(counts):
            return plan
        return plan_study(study, p.seed, sections=sections, pools=pools, counts=locked, extras=True)

    return _commit_start(p, study, fresh_plan, order)


def _nonzero(counts: dict[int, dict[int, int]]) -> dict[int, dict[int, int]]:
    """The counts without zero rows (a missing row and a zero row mean the same)."""
    return {pk: {c: n for c, n in row.items() if n} for pk, row in counts.items()}


def _ensure_count_rows(sections: list[Section], pools: dict[int, SectionPool], counts) -> None:
    """Create the missing zero counter rows of the sections' pool clips (once per clip; autocommit), so the
    start's transaction can lock every count it reads."""
    missing = [SectionClipCount(section_id=s.pk, clip_id=c.pk) for s in sections
               for c in (pools.get(s.pk) or SectionPool()).clips if c.pk not in counts[s.pk]]
    if missing:
        SectionClipCount.objects.bulk_create(missing, ignore_conflicts=True, batch_size=500)


SQLITE_RETRY_SECONDS = 30.0
_SQLITE_WRITER = threading.Lock()


def _one_writer():
    """On SQLite, threads of this process queue for the start's write transaction (SQLite runs one writer at a
    time anyway; queueing avoids transactions that fail and retry against each other). Elsewhere: nothing."""
    return _SQLITE_WRITER if connection.vendor == "sqlite" else nullcontext()


RETRY_SQLSTATES = ("40P01", "40001")
"""PostgreSQL's deadlock_detected and serialization_failure."""


def _retryable(exc: Exception, vendor: str | None = None) -> bool:
    """A lock conflict worth running the start again for: SQLite's "database/table is locked", PostgreSQL's
    deadlock (40P01) or serialization failure (40001). Starts take their locks in one order (participant row,
    count rows by (section, clip), counter row), so on PostgreSQL this is a safety net (e.g. for a future
    REPEATABLE READ setting or a staff edit locking rows), not part of the normal path. The SQLSTATE is read
    from the driver's exception: ``sqlstate`` (psycopg 3) or ``pgcode`` (psycopg2)."""
    if (vendor or connection.vendor) == "sqlite":
        return "locked" in str(exc)
    cause = exc.__cause__
    code = getattr(cause, "sqlstate", None) or getattr(cause, "pgcode", None)
    return code in RETRY_SQLSTATES or "deadlock detected" in str(exc)


def _with_retries(action, patience_s: float = SQLITE_RETRY_SECONDS):
    """Run ``action``; retry it (jittered back-off, up to ``patience_s``) after a lock conflict (``_retryable``):
    SQLite serialises writers and, in some cases (a read transaction upgrading to write, shared-cache test
    databases), reports "locked" at once instead of waiting; PostgreSQL aborts one side of a deadlock."""
    deadline = time.monotonic() + patience_s
    attempt = 0
    while True:
        try:
            return action()
        except OperationalError as exc:
            if not _retryable(exc) or time.monotonic() > deadline:
                raise
            attempt += 1
            time.sleep(random.uniform(0.002, 0.002 * min(attempt, 25)))


def _commit_start(p: Participant, study: Study, fresh_plan, order: list[Section]) -> bool:
    """The start's transaction: claim the participant, lock and re-read the balancing counts (plan again only if
    a concurrent start changed them), count this participant's clips, insert the assignments, check the limit.
    Locks are taken in the same order by every start (participant row, count rows by (section, clip), counter
    row), so starts queue on the count rows for this short tail but never deadlock."""
    now = timezone.now()
    with _one_writer(), transaction.atomic():
        claimed = Participant.objects.filter(pk=p.pk, status=Participant.Status.CONSENTED).update(
            status=Participant.Status.STARTED, started_at=now, last_active_at=now,
            section_order=[s.pk for s in order])
        if not claimed:
            return False
        plan = fresh_plan()
        Participant.objects.filter(pk=p.pk).update(
            n_items=sum(len(items) for _, items in plan),
            pages=page_records(order, {section.pk: len(items) for section, items in plan}))
        _count_trials(plan)
        Assignment.objects.bulk_create(_assignment_rows(p, plan, order))
        if study.max_participants:
            _counter(study.pk).select_for_update(no_key=True).get()
            if active_count(study) > study.max_participants:
                raise StudyUnavailable(STUDY_FULL)
    return True


def _count_trials(plan: list[tuple[Section, list[PlannedItem]]]) -> None:
    """Add this participant's trial clips to the balancing counts: one F() UPDATE per balanced section
    (practice items, attention checks and reusing sections are not counted)."""
    for section, items in plan:
        pks = [it.clip.pk for it in items if not it.kind]
        if pks and not section.reuse_section_id:      # the rows exist: _ensure_count_rows made them
            SectionClipCount.objects.filter(section_id=section.pk, clip_id__in=pks).update(n=F("n") + 1)


@dataclass
class Step:
    """Where a participant is: kind in demographics | start | item | page | feedback | done."""
    kind: str
    assignment: Assignment | None = None
    index: int = 0          # 1-based number of this clip among all of the participant's clips (Assignment.seq);
    #                         of a page: its number among the participant's pages (studyapp.data.section_pages)
    total: int = 0
    next_assignment: Assignment | None = None     # the clip after this one (preloaded by the page), if asked for


def open_items(participant: Participant, n: int = 1) -> list[Assignment]:
    """The participant's first ``n`` unanswered assignments by seq, with section and clip: one indexed query
    (partial index on (participant, seq) where answered_at is null), whatever the size of the study."""
    return open_assignments(participant.pk, n)


def current_step(participant: Participant, lookahead: bool = False) -> Step:
    """The participant's next page, computed from the database only (so reloads and restarts resume): at most one
    query (the first unanswered assignment; with lookahead the one after it too). An instruction or break page due
    before that clip comes first (Participant.pages, read with the participant). The total is the stored
    Participant.n_items."""
    study = participant.study
    if study.ask_demographics and not participant.demographics_done:
        return Step("demographics")
    if participant.status == Participant.Status.CONSENTED:
        return Step("start")
    total = participant.n_items
    items = open_items(participant, 2 if lookahead else 1)
    page = due_page(participant.pages, items[0].seq if items else None)
    if page is not None:
        return Step("page", None, page, total)
    if items:
        return Step("item", items[0], items[0].seq, total, items[1] if len(items) > 1 else None)
    if study.feedback_questions and not participant.feedback_done:
        return Step("feedback", None, total, total)
    return Step("done", None, total, total)
