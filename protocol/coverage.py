"""Do a preset's sections still get the clips they ask for after the quality gate? Which section is short, and why.

The study side of a plan: given the plan's planned clip rows (the rows the catalogue will hold, as
``generation.plans.planned.planned_clip_rows`` makes them or ``analysis.design.read_planned_clips`` reads them) and
each entry's quality flag, it tells which preset section is short. The motion library does not import it: the study
app's ``generate_clips`` command and ``python -m analysis.coverage`` call it.

A study made from a preset (``protocol.presets.PRESETS``) draws each section's clips from its pool (catalogue filters,
``protocol.pools``; the study app adds the preset's plan, ``protocol.presets.PRESET_PLANS``) and leaves out clips
that failed a quality check (``qa_flag``) unless the pool keeps those checks (``protocol.pools.kept_checks``:
``include_flagged`` all, ``keep_advisory`` the advisory ones, ``observer_advisory`` the observer's).
:func:`section_coverage` applies the same filters to the plan's planned clip rows with each entry's quality flag from
the gate (``generation.pipeline.plan_qa``), and compares what is left with the section's ``clips_per_participant``
(0: every clip of the pool; naturalness sections also their ``n_generated`` / ``n_source`` halves; a norming
section, which shows each participant min(M, C) of its C candidates, is full with one usable candidate). Plain
Python: the pool filters are evaluated on dict rows, no Django.
"""
from __future__ import annotations

from .norming import ratings_per_clip
from .pools import SUB_POOLS, blocking_checks, pool_lookups
from .presets import PRESET_PLANS, PRESETS


def _value(row: dict, field: str):
    v = row.get(field)
    return "" if v is None and field in ("theme", "emotion_label", "sections", "plan", "origin") else v


def _match(row: dict, key: str, want) -> bool:
    field, _, lookup = key.partition("__")
    v = _value(row, field)
    if lookup == "":
        return v == want
    if lookup == "in":
        return v in want
    if lookup == "isnull":
        return (v is None) == bool(want)
    if lookup == "contains":
        return str(want) in str(v or "")
    if lookup == "startswith":
        return str(v or "").startswith(str(want))
    if v is None:
        return False
    return {"lt": v < want, "lte": v <= want, "gt": v > want, "gte": v >= want}[lookup]


def matches(row: dict, pool: dict | None) -> bool:
    """Whether a planned clip row is in ``pool`` (its filters as ``protocol.pools.pool_lookups`` turns them into ORM
    calls; sub-pools and ``include_flagged`` are not filters)."""
    for method, kwargs in pool_lookups(pool):
        ok = all(_match(row, k, v) for k, v in kwargs.items())
        if ok != (method == "filter"):
            return False
    return True


def section_coverage(preset: str, rows: list[dict], flags: dict[str, str], plan_name: str | None = None
                     ) -> list[dict]:
    """Per section of ``preset``: ``index``, ``title``, ``section_type``, ``asks`` (clips per participant; None for a
    section that reuses another's clips), ``in_pool``, ``usable`` (in the pool and not kept out by the gate),
    ``left_out`` ([(entry id, blocking checks)]), ``short`` (bool) and ``why`` (a sentence), and for naturalness
    sections with halves ``halves`` ({generated|source: {asks, usable}}).

    Args:
        preset: a key of ``protocol.presets.PRESETS``.
        rows: the plan's planned clip rows (dicts: ``entry_id`` and the catalogue fields a pool filters on; blank
            cells None).
        flags: entry id -> its quality flag (``qa_flag``; "" passed). Entries missing from it count as passed.
        plan_name: the plan the rows come from (default: the preset's own, ``PRESET_PLANS[preset]``).
    """
    plan_name = plan_name or PRESET_PLANS[preset]
    out = []
    for i, sec in enumerate(PRESETS[preset]["sections"]):
        base = {"index": i, "title": sec.get("title", ""), "section_type": sec["section_type"]}
        if "reuse" in sec:
            out.append({**base, "asks": None, "in_pool": None, "usable": None, "left_out": [], "short": False,
                        "why": f"shows the clips of section {sec['reuse'] + 1} again"})
            continue
        pool = {**(sec.get("pool") or {}), "plan": plan_name}
        in_pool = [r for r in rows if matches(r, pool)]
        left = [(r["entry_id"], blocking_checks(flags.get(r["entry_id"]), pool)) for r in in_pool]
        left = [(e, b) for e, b in left if b]
        gone = {e for e, _ in left}
        usable = [r for r in in_pool if r["entry_id"] not in gone]
        options = sec.get("options") or {}
        norming = ratings_per_clip(options) is not None
        asks = int(sec.get("clips_per_participant") or 0)
        need = asks if asks else len(in_pool)
        if norming:
            # a norming design shows each participant min(M, C) of its C candidates: any candidate is enough
            need = min(need, max(len(usable), 1))
        item = {**base, "asks": asks, "in_pool": len(in_pool), "usable": len(usable), "left_out": left}
        halves = {}
        for half in SUB_POOLS:
            n = options.get(f"n_{half}")
            if n is None:
                continue
            sub = {**(sec.get("pool") or {}).get(half, {"origin": half}), "plan": plan_name}
            halves[half] = {"asks": int(n), "usable": sum(matches(r, sub) for r in usable)}
        if halves:
            item["halves"] = halves
        short_halves = [h for h, v in halves.items() if v["usable"] < v["asks"]]
        item["short"] = len(usable) < need or bool(short_halves)
        if item["short"]:
            reasons = "; ".join(f"{e}: {', '.join(b)}" for e, b in left) or "the pool itself is too small"
            half_txt = "".join(f"; its {h} half asks {halves[h]['asks']}, {halves[h]['usable']} usable"
                               for h in short_halves)
            item["why"] = (f"asks {need}, {len(usable)} usable of {len(in_pool)} in its pool{half_txt}; left out by "
                           f"the quality gate: {reasons}")
        else:
            item["why"] = (f"asks {need}, {len(usable)} usable of {len(in_pool)} in its pool"
                           + (f" ({len(left)} left out by the gate)" if left else "")
                           + (f"; norming: each participant rates {need} of the {len(usable)} candidates"
                              if norming else ""))
        out.append(item)
    return out


def coverage_lines(preset: str, rows: list[dict], flags: dict[str, str], plan_name: str | None = None) -> list[str]:
    """One line per section: 'section 1 (emotion_choice) Perceived emotion: walks: full: asks 2, ...' or SHORT."""
    return [f"section {s['index'] + 1} ({s['section_type']}) {s['title']}: "
            f"{'SHORT' if s['short'] else 'full'}: {s['why']}"
            for s in section_coverage(preset, rows, flags, plan_name)]


def presets_of_plan(plan_name: str) -> list[str]:
    """The presets whose sections draw on the plan ``plan_name``."""
    return [p for p, name in PRESET_PLANS.items() if name == plan_name]
