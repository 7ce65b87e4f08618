"""The pool rule ``norms``: admit only clips whose per-clip norms pass (protocol.pools.NORMS_RULE).

``{"norms": {"from": "<study slug>" | "<path to clip_norms.csv>", "min_ratings": 10, "min_intended_share": 0.5,
"max_entropy_bits": 1.5}}``. The norms come from a study of this site (computed from its exports with its
exclusion rules, as the report does: analysis.norms) or from a clip_norms.csv file (a path, relative to
``settings.DATA_DIR`` unless absolute), read and checked whole by analysis.norms.read_clip_norms before anything is
used, so a bad file changes nothing. The norms themselves come from the one norms service (studyapp.data.norms_service).

Who may read what: a file must be a .csv inside DATA_DIR once symbolic links and ``..`` are resolved (``norms_file``,
whoever reads it), so no other file of the server is opened. Where a user acts (the pool editor's live count, a
section saved in the admin) every study source of the pool tree, the naturalness sub-pools' rules included, must be
one of the user's studies (``check_reader``; superusers: any), checked before any norms are read, with one message
for another lab's study and for a slug that does not exist; the assignment of a participant, where no user acts,
reads the rules as saved.

A clip's norm is its row with an intended label and the most ratings (a clip rated in several sections: the
norming section's emotion question). A clip passes when it has a norm with at least ``min_ratings`` ratings, an
intended share of at least ``min_intended_share`` and an entropy of at most ``max_entropy_bits``; each failed
condition is a reason shown by the pool editor. Where a clip has a norm, the automatic observers' verdict (the
``observer`` quality check) is advisory: a clip flagged only by the observer (and advisory checks) stays in a pool
with a norms rule -- people's ratings outrank an observer's.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from protocol.pools import NORMS_RULE, SUB_POOLS

from ..permissions import studies_for
from .norms_service import NormsSourceError, clear, is_file_source, load_norms, norms_file  # noqa: F401 - the rule's API


@dataclass
class ClipVerdict:
    """A clip's norm (a dict of clip_norms.csv cells, None when it has none) and the reasons it is out (none: in)."""
    norm: dict | None
    reasons: list[str] = field(default_factory=list)

    @property
    def passes(self) -> bool:
        return not self.reasons


def norms_rules(pool) -> list[tuple[str, dict]]:
    """(where, rule) of every norms rule in a pool tree: the pool's own (``"norms"``) and each sub-pool's
    (``"generated.norms"``, ``"source.norms"``), in that order; [] when there is none."""
    if not isinstance(pool, dict):
        return []
    found = [(NORMS_RULE, pool[NORMS_RULE])] if isinstance(pool.get(NORMS_RULE), dict) else []
    for key in SUB_POOLS:
        sub = pool.get(key)
        if isinstance(sub, dict) and isinstance(sub.get(NORMS_RULE), dict):
            found.append((f"{key}.{NORMS_RULE}", sub[NORMS_RULE]))
    return found


def norms_sources(pool) -> set[str]:
    """The ``from`` of every norms rule of a pool tree (stripped)."""
    return {str(rule.get("from") or "").strip() for _, rule in norms_rules(pool)}


def norms_source(pool) -> str | None:
    """The ``from`` of a pool's own norms rule (stripped), None when the pool has no norms rule."""
    rule = pool.get(NORMS_RULE) if isinstance(pool, dict) else None
    return str(rule.get("from") or "").strip() if isinstance(rule, dict) else None


def check_reader(pool, reader, already_saved: set[str] | frozenset = frozenset()) -> None:
    """Raise NormsSourceError unless ``reader`` (the user acting) may read every study that a norms rule of the
    pool tree names (the pool's own rule and each sub-pool's): one of studies_for(reader). Sources in
    ``already_saved`` (the saved section's, :func:`norms_sources`) pass as they are. The message is the same for
    another lab's study and for none, so a slug is not confirmed. A file source is left to norms_file, which holds
    for everyone."""
    readable = None
    for where, rule in norms_rules(pool):
        source = str(rule.get("from") or "").strip()
        if not source or is_file_source(source) or source in already_saved:
            continue
        if readable is None:
            readable = set(studies_for(reader).values_list("slug", flat=True))
        if source not in readable:
            raise NormsSourceError(f"pool.{where}.from: no study {source!r} among the studies you may see (give the "
                                   "slug of a study you own or collaborate on, or a clip_norms.csv path)")


def judge(rule: dict, norm: dict | None) -> ClipVerdict:
    """Whether one clip's norm passes the rule, with the reasons it does not."""
    if norm is None:
        return ClipVerdict(None, ["no norms for this clip"])
    reasons = []
    n = norm.get("n_ratings")
    if "min_ratings" in rule and not (n == n and n >= rule["min_ratings"]):
        reasons.append(f"{int(n) if n == n else 0} ratings < {rule['min_ratings']}")
    if "min_intended_share" in rule:
        share = norm.get("intended_share")
        if share is None or share != share:
            reasons.append("no intended label to compare")
        elif share < rule["min_intended_share"]:
            reasons.append(f"intended share {share:.2f} < {rule['min_intended_share']:g}")
    if "max_entropy_bits" in rule:
        h = norm.get("entropy_bits")
        if h is None or h != h or h > rule["max_entropy_bits"]:
            reasons.append(f"entropy {h:.2f} bits > {rule['max_entropy_bits']:g}" if h == h and h is not None
                           else "no entropy")
    return ClipVerdict(norm, reasons)


def verdicts(pool: dict | None, clip_ids) -> dict[str, ClipVerdict]:
    """clip_id -> verdict of the pool's norms rule for each of ``clip_ids`` ({} when the pool has no rule)."""
    rule = (pool or {}).get(NORMS_RULE)
    if not isinstance(rule, dict):
        return {}
    norms = load_norms(rule.get("from", ""))
    return {cid: judge(rule, norms.get(cid)) for cid in clip_ids}


def passing_ids(pool: dict) -> tuple[set[str], set[str]]:
    """(clip ids that pass the pool's norms rule, clip ids that have a norm at all)."""
    rule = pool[NORMS_RULE]
    norms = load_norms(rule.get("from", ""))
    return {cid for cid, norm in norms.items() if judge(rule, norm).passes}, set(norms)


