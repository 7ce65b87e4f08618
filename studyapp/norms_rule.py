"""The pool rule ``norms``: admit only clips whose per-clip norms pass (protocol.pools.NORMS_RULE).

``{"norms": {"from": "<study slug>" | "<path to clip_norms.csv>", "min_ratings": 10, "min_intended_share": 0.5,
"max_entropy_bits": 1.5}}``. The norms come from a study of this site (computed from its exports with its
exclusion rules, as the report does: analysis.norms) or from a clip_norms.csv file (a path, relative to
``settings.DATA_DIR`` unless absolute), read and checked whole by analysis.norms.read_clip_norms before anything is
used, so a bad file changes nothing.

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

import io
import os
import threading
from dataclasses import dataclass, field
from pathlib import Path

from django.conf import settings

from analysis import exclusion
from analysis.io import StudyData, ValidationError, load_study
from analysis.norms import clip_norms, read_clip_norms
from protocol.pools import NORMS_RULE, SUB_POOLS

from .export import stream_csv
from .models import Clip, Response, Study
from .permissions import studies_for


class NormsSourceError(ValueError):
    """The ``from`` of a norms rule cannot give norms; the message names the field, and the file, line and column
    of each problem of a clip_norms.csv."""


@dataclass
class ClipVerdict:
    """A clip's norm (a dict of clip_norms.csv cells, None when it has none) and the reasons it is out (none: in)."""
    norm: dict | None
    reasons: list[str] = field(default_factory=list)

    @property
    def passes(self) -> bool:
        return not self.reasons


_cache: dict[tuple, dict[str, dict]] = {}
_lock = threading.Lock()


def _is_path(source: str) -> bool:
    return source.endswith(".csv") or "/" in source or os.sep in source


def norms_file(source: str) -> Path:
    """The file a ``from`` path names: relative to settings.DATA_DIR unless absolute, and, with symbolic links and
    ``..`` resolved, a .csv inside DATA_DIR; NormsSourceError before the file is opened otherwise."""
    root = Path(getattr(settings, "DATA_DIR", ".")).resolve()
    path = (root / source).resolve()           # an absolute source replaces root
    if path.suffix.lower() != ".csv":
        raise NormsSourceError(f"pool.norms.from: {source!r} is not a .csv file (give a study's slug or the path of "
                               "a clip_norms.csv under the data folder, DATA_DIR)")
    if not path.is_relative_to(root):
        raise NormsSourceError(f"pool.norms.from: {source!r} is outside the data folder: a clip_norms.csv must lie "
                               "under DATA_DIR (give it relative to that folder, e.g. norms/clip_norms.csv)")
    return path


def _from_file(source: str) -> tuple[tuple, callable]:
    path = norms_file(source)
    try:
        stat = path.stat()
    except OSError as exc:
        raise NormsSourceError(f"pool.norms.from: cannot read {source!r} ({exc.strerror or exc})") from None

    def load():
        try:
            return read_clip_norms(path, known_clips=Clip.objects.values_list("clip_id", flat=True))
        except ValidationError as exc:
            more = f"; and {exc.total - len(exc.problems)} more" if exc.total > len(exc.problems) else ""
            raise NormsSourceError("pool.norms.from: " + "; ".join(map(str, exc.problems)) + more) from None
    return ("file", str(path), stat.st_mtime_ns, stat.st_size), load


def _from_study(slug: str) -> tuple[tuple, callable]:
    study = Study.objects.filter(slug=slug).first()
    if study is None:
        raise NormsSourceError(f"pool.norms.from: no study {slug!r} on this site (give a study's slug or a "
                               "clip_norms.csv path)")
    answers = Response.objects.filter(section__study=study)
    last = answers.order_by("-id").values_list("id", flat=True).first()

    def load():
        texts = {k: io.StringIO("".join(stream_csv(study, k)))
                 for k in ("responses", "clips", "participants", "viewing")}
        data = load_study(texts["responses"], texts["clips"], texts["participants"], texts["viewing"])
        rules = exclusion.resolve_rules(study.exclusion_rules)
        excl = exclusion.exclusions(data.responses, data.clips, participants=data.participants, rules=rules,
                                    viewing=data.viewing)
        kept = StudyData(exclusion.apply_exclusions(data.responses, excl), data.clips, data.participants)
        norms = clip_norms(kept.responses, kept.clips)
        if norms.empty:
            raise NormsSourceError(f"pool.norms.from: study {slug!r} has no norms yet (no answers to an emotion "
                                   "question of its clips)")
        return norms
    return ("study", study.pk, last, answers.count()), load


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
        if not source or _is_path(source) or source in already_saved:
            continue
        if readable is None:
            readable = set(studies_for(reader).values_list("slug", flat=True))
        if source not in readable:
            raise NormsSourceError(f"pool.{where}.from: no study {source!r} among the studies you may see (give the "
                                   "slug of a study you own or collaborate on, or a clip_norms.csv path)")


def load_norms(source: str) -> dict[str, dict]:
    """clip_id -> its norm (the chosen clip_norms row as a dict) from a norms rule's ``from``; cached per source
    version (file mtime and size, or the study's answers). Raises NormsSourceError."""
    source = (source or "").strip()
    key, load = _from_file(source) if _is_path(source) else _from_study(source)
    with _lock:
        if key in _cache:
            return _cache[key]
    table = load()
    with_intended = table.assign(_has=table["intended"].notna() & (table["intended"].astype(str) != ""))
    best = (with_intended.sort_values(["clip_id", "_has", "n_ratings"], ascending=[True, False, False])
            .drop_duplicates("clip_id").drop(columns="_has"))
    norms = {row["clip_id"]: row for row in best.to_dict("records")}
    with _lock:
        _cache[key] = norms
        while len(_cache) > 16:
            _cache.pop(next(iter(_cache)))
    return norms


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


def clear() -> None:
    with _lock:
        _cache.clear()
