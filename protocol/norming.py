"""The balanced incomplete design of a norming study, as plain arithmetic (no Django, no numpy).

A norming section rates C candidate clips so that every clip gets at least K ratings while each participant sees
only M of them (``Section.clips_per_participant``; ``Section.options["norming"] = {"ratings_per_clip": K}``). The
design is cyclic: the section's clips are put once in a fixed random order (seeded by the section, so it never
changes while the study runs), and the i-th participant to start (0-based; the section's assignments so far / M)
takes the M clips from position i*M on, wrapping round, shown rotated (:func:`cyclic_block`). Therefore

- no clip twice per participant (M <= C);
- presentations are balanced across participants: after N participants every clip has floor(N*M/C) or
  ceil(N*M/C) ratings (exactly N*M/C when C divides N*M);
- and across positions: each clip is shown about equally often in each of the M positions (the rotation; exact
  when M divides C and N is a multiple of C, e.g. C = 20, M = 5, N = 80: every clip 4 times in each position;
  otherwise, checked for every C <= 60 and M <= 10 after N = C*M participants, within 2 of the expected M per clip
  and position except C, M = 9, 6; 27, 6; 45, 6 (6 off) and 25, 10 (15 off));
- N participants give every clip at least K ratings exactly when floor(N*M/C) >= K, so the planned N must be at
  least ceil(K*C/M) (:func:`required_participants`).

This is a cyclic (Latin-square-like) incomplete block design in the sense of Cochran & Cox, *Experimental Designs*
(2nd ed., Wiley 1957), chapter 11: blocks (participants) of size M, C treatments (clips), every treatment replicated
equally often.
"""
from __future__ import annotations

import math
import random

NORMING_OPTION = "norming"
"""``Section.options`` key of a norming section: ``{"ratings_per_clip": K}``."""
DEFAULT_RATINGS_PER_CLIP = 20


def ratings_per_clip(options: dict | None) -> int | None:
    """K of a section's options, or None when the section is not a norming section."""
    config = (options or {}).get(NORMING_OPTION)
    if not isinstance(config, dict):
        return None
    return int(config.get("ratings_per_clip", DEFAULT_RATINGS_PER_CLIP))


def required_participants(n_clips: int, k: int, m: int) -> int:
    """The fewest participants N for which every one of ``n_clips`` clips gets at least ``k`` ratings when each
    participant rates ``m`` (capped at n_clips): ceil(k * n_clips / m). 0 when there are no clips."""
    if n_clips <= 0 or k <= 0:
        return 0
    m = min(m, n_clips) if m > 0 else n_clips
    return math.ceil(k * n_clips / m)


def min_ratings(n_clips: int, m: int, n: int) -> int:
    """The ratings the least-rated clip gets after ``n`` participants of ``m`` clips each: floor(n*m / n_clips)."""
    if n_clips <= 0:
        return 0
    m = min(m, n_clips) if m > 0 else n_clips
    return (n * m) // n_clips


def design_errors(n_clips: int, k: int, m: int, n: int) -> list[str]:
    """Why a norming section cannot give ``k`` ratings per clip with ``n`` planned participants ([] when it can)."""
    if n_clips <= 0:
        return ["the pool matches no clip"]
    if k < 1:
        return [f"ratings_per_clip must be at least 1, not {k}"]
    if m < 0:
        return [f"clips per participant must be >= 0, not {m}"]
    errors = []
    if n <= 0:
        errors.append(f"set the participant limit (the planned N): {required_participants(n_clips, k, m)} "
                      f"participants give {k} ratings to each of {n_clips} clips at {min(m or n_clips, n_clips)} "
                      "clips each")
    elif min_ratings(n_clips, m, n) < k:
        errors.append(f"{n} participants x {min(m or n_clips, n_clips)} clips give the {n_clips} clips at least "
                      f"{min_ratings(n_clips, m, n)} ratings each, fewer than {k}: plan at least "
                      f"{required_participants(n_clips, k, m)} participants or show more clips each")
    return errors


def clip_order(clip_ids: list[str], salt: str) -> list[str]:
    """The fixed cyclic order of a section's clips: sorted ids shuffled with ``salt`` (e.g. the section's key)."""
    order = sorted(clip_ids)
    random.Random(f"norming:{salt}").shuffle(order)
    return order


def cyclic_block(n_clips: int, m: int, ordinal: int) -> list[int]:
    """Positions (into :func:`clip_order`) of the clips of the ``ordinal``-th participant (0-based), in the order
    shown: the m consecutive clips from ordinal*m on (wrapping), rotated by the pass over the pool
    (ordinal*m // C) when m divides C, else by the ordinal, mod m."""
    if n_clips <= 0:
        return []
    m = min(m, n_clips) if m > 0 else n_clips
    start = ordinal * m
    block = [(start + j) % n_clips for j in range(m)]
    # M divides C: every pass over the pool shows each clip in the same slot, so rotate by the pass number; else
    # the block boundaries move from pass to pass and rotating by the ordinal spreads the positions
    rot = (start // n_clips if n_clips % m == 0 else ordinal) % m
    return block[rot:] + block[:rot]


__all__ = ["DEFAULT_RATINGS_PER_CLIP", "NORMING_OPTION", "clip_order", "cyclic_block", "design_errors",
           "min_ratings", "ratings_per_clip", "required_participants"]
