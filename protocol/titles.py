"""Readable clip titles: generator, condition and variant, e.g. ``"gait net, happy 0.8 + neutral 0.2, path 2"``.

A title is derived from a clip record (the clips.csv intent columns plus the renderer's ``metadata``: ``generator``,
``fallback_for``, ``inputs``, ``seed``, ``entry_id``) so a researcher recognises a clip without its 16-hex id. It
is a label for staff pages and exports, never shown to participants (it names the condition).

- generator: the generator that made the clip, underscores as spaces (``gait_net`` -> ``gait net``); a fallback
  says whom it replaced; a clip without one is named by its modality and origin (``gait, source``), an imported
  file ``imported <modality>``.
- condition: a gait emotion vector as its non-zero components, largest first (``happy 0.8 + neutral 0.2``, a
  pure one by its name), a transition as ``initial to final``, a gesture by its label (else its VAD), an RBF
  clip by theme and weight, a captured take by its file; ``no emotion`` when none of these is known.
- variant: the clips of one plan with the same generator and condition are numbered in seed order, ``path k``
  for walks along a trajectory, else ``variant k``; a clip alone in its group has none.
"""
from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable, Mapping

from .vocabulary import FINAL_EMOTION_COLUMNS, GAIT_EMOTIONS, NEUTRAL_THEME, VAD_DIMENSIONS

TITLE_MAX_LENGTH = 200
"""Longest title kept (characters); longer ones are cut with an ellipsis."""


def _num(value) -> float | None:
    if value is None or isinstance(value, bool):
        return None
    try:
        out = float(value)
    except (TypeError, ValueError):
        return None
    return out if math.isfinite(out) else None


def _short(value: float) -> str:
    return f"{round(value, 2):g}"


def _meta(record: Mapping) -> dict:
    meta = record.get("metadata")
    return meta if isinstance(meta, dict) else {}


def generator_label(record: Mapping) -> str:
    """The generator part of a title."""
    meta = _meta(record)
    gen = str(meta.get("generator") or "").strip()
    if gen:
        label = gen.replace("_", " ")
        if meta.get("fallback_for"):
            label += f" (in place of {str(meta['fallback_for']).replace('_', ' ')})"
        return label
    modality = str(record.get("modality") or "clip")
    if str(record.get("plan") or "").startswith("import:"):
        return f"imported {modality}"
    origin = str(record.get("origin") or "")
    return f"{modality}, {origin}" if origin else modality


def emotion_mix(values: Iterable) -> str:
    """``happy 0.8 + neutral 0.2`` from a gait emotion vector in GAIT_EMOTIONS order ("" when it has none)."""
    parts = [(v, i) for i, v in enumerate(_num(x) for x in values) if v is not None and v > 0]
    if not parts:
        return ""
    total = sum(v for v, _ in parts)
    parts.sort(key=lambda p: (-p[0], p[1]))
    if len(parts) == 1:
        return GAIT_EMOTIONS[parts[0][1]]
    return " + ".join(f"{GAIT_EMOTIONS[i]} {_short(v / total)}" for v, i in parts)


def condition_label(record: Mapping) -> str:
    """The condition part of a title (see the module docstring)."""
    initial = emotion_mix(record.get(e) for e in GAIT_EMOTIONS)
    final = emotion_mix(record.get(c) for c in FINAL_EMOTION_COLUMNS)
    if initial and final:
        return f"{initial} to {final}"
    theme = str(record.get("theme") or "").strip()
    if theme:
        if theme == NEUTRAL_THEME:
            return "neutral input walk"
        weight = _num(record.get("weight"))
        return f"{theme} {_short(weight)}" if weight is not None else theme
    if initial:
        return initial
    label = str(record.get("emotion_label") or "").strip()
    if label:
        return label
    vad = [_num(record.get(d)) for d in VAD_DIMENSIONS]
    if all(v is not None for v in vad):
        return ", ".join(f"{d} {_short(v)}" for d, v in zip(VAD_DIMENSIONS, vad, strict=True))
    inputs = _meta(record).get("inputs")
    inputs = inputs if isinstance(inputs, dict) else {}
    take = inputs.get("clip") or inputs.get("file")
    if isinstance(take, str) and take.strip():
        name = take.strip().replace("\\", "/").rsplit("/", 1)[-1]
        return "take " + (name.rsplit(".", 1)[0] or name)
    return "no emotion"


def _has_path(record: Mapping) -> bool:
    inputs = _meta(record).get("inputs")
    return isinstance(inputs, dict) and isinstance(inputs.get("trajectory"), dict)


def _order_key(record: Mapping) -> tuple:
    meta = _meta(record)
    seed = _num(meta.get("seed"))
    return (seed if seed is not None else math.inf, str(meta.get("entry_id") or ""), str(record.get("clip_id")))


def clip_title(record: Mapping, variant: str = "") -> str:
    """The title of one clip record: its own ``title`` (or ``metadata["title"]``, an imported file's) when it has
    one, else ``generator, condition[, variant]``."""
    own = record.get("title") or _meta(record).get("title")
    if isinstance(own, str) and own.strip():
        text = " ".join(own.split())
    else:
        text = ", ".join(p for p in (generator_label(record), condition_label(record), variant) if p)
    return text if len(text) <= TITLE_MAX_LENGTH else text[:TITLE_MAX_LENGTH - 1] + "\u2026"


def clip_titles(records: Iterable[Mapping]) -> dict[str, str]:
    """clip_id -> title for ``records`` taken together: clips of one plan with the same generator and condition
    are numbered (``path 1``, ``path 2``... in seed order) so their titles differ."""
    records = list(records)
    groups: dict[tuple, list[Mapping]] = defaultdict(list)
    for rec in records:
        groups[(str(rec.get("plan") or ""), generator_label(rec), condition_label(rec))].append(rec)
    variants: dict[str, str] = {}
    for members in groups.values():
        if len(members) < 2:
            continue
        for k, rec in enumerate(sorted(members, key=_order_key), start=1):
            variants[str(rec.get("clip_id"))] = f"{'path' if _has_path(rec) else 'variant'} {k}"
    return {str(rec.get("clip_id")): clip_title(rec, variants.get(str(rec.get("clip_id")), "")) for rec in records}
