"""The design of a simulated study, read from study presets and the stimulus plans they draw on. No Django.

A real study is a preset (``study_presets.PRESETS``: its sections, clips per participant, options, pools) filled
with the clips of a plan (``generation/plans/<name>.yaml``, ``study_presets.PRESET_PLANS``). The simulator
(:mod:`analysis.simulate`) takes the same two inputs, so a simulated study has the structure of a real export of that
preset: the same sections in the same order, the same number of clips per participant, the same questions and answer
options, and a clips.csv whose rows are the plan's entries (intended emotions, themes, weights as the renderer
records them; see :func:`generation.plans.schema.intent_fields`).

Each plan entry becomes one SYNTHETIC clip row with id ``sim-<plan>-<entry id>``. Its ``duration_s`` is the planned
one: the entry's ``duration_s`` input, else its pair's (a generated gesture and its source), else the plan's render
duration -- a rendered clip's real length may differ a little.

Pools are matched as ``study_pools`` defines them (field, ``field__lookup``, lists, the ``transition`` and ``rbf``
shorthands, naturalness sub-pools), on the clip rows plus their ``plan``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from study_pools import DEFAULT_GESTURE_OPTIONS, FLAGS, INCLUDE_FLAGGED, SUB_POOLS, pool_errors
from study_presets import PRESET_PLANS, PRESETS
from study_protocol import CLIP_COLUMNS, FINAL_EMOTION_COLUMNS, GESTURE_EMOTIONS, SECTION_QUESTIONS

PAPER_PRESETS = ("gait_ismar2020", "gestures_ieeevr2021", "rbf_thms2016")
"""The three papers' studies; simulated one after the other as one SYNTHETIC study by default."""
EXTRA_COLUMNS = ("plan", "entry_id", "source_clip_id")
"""Columns of :attr:`StudyDesign.clips` after CLIP_COLUMNS (the design's, not clips.csv's)."""


class DesignError(ValueError):
    """A preset or plan that cannot be simulated; the message names the preset, section or plan."""


@dataclass(frozen=True)
class SectionDesign:
    """One section of the simulated study.

    Attributes:
        order: 1-based position in the study; preset: the preset it comes from.
        section_type: one of study_protocol.SECTION_TYPES; questions: its question keys (SECTION_QUESTIONS).
        pool: indices into :attr:`StudyDesign.clips` of the clips the section may show (empty when ``reuse``).
        n_per_participant: clips each participant gets (0 = the whole pool, as the study app).
        reuse: index into :attr:`StudyDesign.sections` of the section whose clips this one shows again, or None.
        options: the section's options (naturalness n_generated/n_source, gesture_emotion n_options/categories).
        sub_pools: naturalness ``generated``/``source`` -> indices of the pool's clips matching that sub-pool.
    """

    order: int
    preset: str
    section_type: str
    pool: np.ndarray
    n_per_participant: int
    reuse: int | None = None
    options: dict = field(default_factory=dict)
    sub_pools: dict = field(default_factory=dict)

    @property
    def questions(self) -> tuple[str, ...]:
        return tuple(SECTION_QUESTIONS[self.section_type])

    @property
    def mixed_naturalness(self) -> bool:
        """A naturalness section that mixes given numbers of generated and source clips (studyapp.assignment)."""
        return self.section_type == "naturalness" and (bool(self.sub_pools) or "n_source" in self.options)

    def naturalness_counts(self) -> tuple[int, int]:
        """(n_generated, n_source) of a mixed naturalness section, with the study app's defaults."""
        k = self.n_per_participant
        n_source = int(self.options.get("n_source", k // 2 if k else 0))
        return int(self.options.get("n_generated", (k - n_source) if k else 0)), n_source

    def n_options(self) -> int:
        return int(self.options.get("n_options", DEFAULT_GESTURE_OPTIONS))

    def categories(self) -> tuple[str, ...]:
        return tuple(self.options.get("categories") or GESTURE_EMOTIONS)


@dataclass(frozen=True)
class StudyDesign:
    """Sections in study order and the clip rows (CLIP_COLUMNS + :data:`EXTRA_COLUMNS`; blanks are "" or NaN)."""

    name: str
    presets: tuple[str, ...]
    plans: dict
    sections: tuple[SectionDesign, ...]
    clips: pd.DataFrame

    def clips_csv(self) -> pd.DataFrame:
        """The clips.csv of the simulated study: CLIP_COLUMNS only, as the study app exports."""
        return self.clips[list(CLIP_COLUMNS)].copy()

    def source_index(self) -> np.ndarray:
        """(n_clips,) index of each clip's source clip, -1 for none."""
        pos = {cid: i for i, cid in enumerate(self.clips["clip_id"])}
        return np.array([pos.get(s, -1) for s in self.clips["source_clip_id"]], dtype=int)


# ---- clips from a plan ---------------------------------------------------------------------------------------------
def _duration(entry, by_id: dict) -> float:
    if "duration_s" in entry.inputs:
        return float(entry.inputs["duration_s"])
    pair = by_id.get(entry.pair)
    if pair is not None and "duration_s" in pair.inputs:
        return float(pair.inputs["duration_s"])
    return float(entry.render.duration_s)


def plan_clip_rows(plan) -> list[dict]:
    """One SYNTHETIC clip row per entry of a validated plan (generation.plans.schema.Plan): CLIP_COLUMNS +
    :data:`EXTRA_COLUMNS`, intent columns from the entry (blanks ``None``)."""
    from generation.plans.schema import intent_fields

    by_id = {e.id: e for e in plan.entries}
    rows = []
    for e in plan.entries:
        row = {c: None for c in CLIP_COLUMNS}
        row.update(intent_fields(e))
        row.update(clip_id=f"sim-{plan.name}-{e.id}", modality=e.modality, origin=e.origin,
                   duration_s=round(_duration(e, by_id), 3), plan=plan.name, entry_id=e.id,
                   source_clip_id=f"sim-{plan.name}-{e.pair}" if e.pair else "")
        rows.append(row)
    return rows


# ---- pool filters (study_pools semantics) -----------------------------------------------------------------------
def _text(s: pd.Series) -> pd.Series:
    return s.fillna("").astype(str)


def _one_filter(clips: pd.DataFrame, key: str, value) -> np.ndarray:
    """Rows of ``clips`` matching one filter ``field[__lookup]: value``."""
    if key == "transition":
        return clips[FINAL_EMOTION_COLUMNS[0]].notna().to_numpy() == bool(value)
    if key == "rbf":
        return (_text(clips["theme"]) != "").to_numpy() == bool(value)
    name, _, lookup = key.partition("__")
    col = clips[name]
    numeric = pd.api.types.is_numeric_dtype(col) and name != "clip_id"
    if lookup == "isnull":
        blank = col.isna() if numeric else _text(col) == ""
        return blank.to_numpy() == bool(value)
    if isinstance(value, list) or lookup == "in":
        return (col if numeric else _text(col)).isin(value).to_numpy()
    if lookup in ("lt", "lte", "gt", "gte"):
        x = pd.to_numeric(col, errors="coerce").to_numpy(float)
        with np.errstate(invalid="ignore"):
            return {"lt": x < value, "lte": x <= value, "gt": x > value, "gte": x >= value}[lookup]
    text = _text(col)
    if lookup == "startswith":
        return text.str.startswith(value).to_numpy()
    if lookup == "contains":
        return text.str.contains(value, regex=False).to_numpy()
    return (col == value).to_numpy() if numeric else (text == value).to_numpy()


def pool_mask(clips: pd.DataFrame, pool: dict | None) -> np.ndarray:
    """(n_clips,) bool: the clips a section pool (without its sub-pools) selects. DesignError for a bad pool."""
    errors = pool_errors(pool)
    if errors:
        raise DesignError("; ".join(errors))
    mask = np.ones(len(clips), bool)
    for key, value in (pool or {}).items():
        if key in SUB_POOLS or key == INCLUDE_FLAGGED:   # simulated clips have no quality flags
            continue
        if key not in FLAGS and key.partition("__")[0] not in clips.columns:
            raise DesignError(f"pool filter {key!r}: the simulated catalogue has no such column")
        mask &= _one_filter(clips, key, value)
    return mask


# ---- presets -> design ---------------------------------------------------------------------------------------------
def _section(spec: dict, order: int, preset: str, plan: str, clips: pd.DataFrame, offset: int) -> SectionDesign:
    """One preset section (with the preset's plan as pool filter, as studyapp.presets.preset_sections does)."""
    where = f"preset {preset!r}, section {order - offset} ({spec['section_type']})"
    if "reuse" in spec:
        return SectionDesign(order, preset, spec["section_type"], np.zeros(0, int), 0, offset + spec["reuse"],
                             dict(spec.get("options") or {}))
    pool = dict(spec.get("pool") or {}, plan=plan)
    try:
        mask = pool_mask(clips, pool)
        subs = {k: np.flatnonzero(mask & pool_mask(clips, pool[k])) for k in SUB_POOLS if k in pool}
    except DesignError as exc:
        raise DesignError(f"{where}: {exc}") from None
    idx = np.flatnonzero(mask)
    if not len(idx):
        raise DesignError(f"{where}: no clip of plan {plan!r} matches the pool {pool}")
    return SectionDesign(order, preset, spec["section_type"], idx, int(spec.get("clips_per_participant", 0)), None,
                         dict(spec.get("options") or {}), subs)


def design_from_presets(presets: tuple[str, ...] | list[str] = PAPER_PRESETS, plans: dict | None = None,
                        name: str | None = None) -> StudyDesign:
    """The design of a study made of ``presets`` (one after the other), each drawing the clips of its plan.

    Args:
        presets: keys of study_presets.PRESETS, e.g. ("demo",) or the default :data:`PAPER_PRESETS`.
        plans: preset -> plan name or path (default study_presets.PRESET_PLANS); the plan is loaded and validated
            with generation.plans.schema.load_plan.
    Raises DesignError naming the preset or section when a preset is unknown or a pool selects no clip of the plan.
    """
    from generation.plans.schema import load_plan

    presets = tuple(presets)
    unknown = [p for p in presets if p not in PRESETS]
    if unknown or not presets:
        raise DesignError(f"unknown preset(s) {unknown}; choose among {sorted(PRESETS)}")
    chosen = {p: (plans or {}).get(p, PRESET_PLANS[p]) for p in presets}
    rows, loaded = [], {}
    for plan_ref in dict.fromkeys(chosen.values()):
        plan = load_plan(plan_ref)
        loaded[plan_ref] = plan.name
        rows += plan_clip_rows(plan)
    clips = pd.DataFrame(rows, columns=[*CLIP_COLUMNS, *EXTRA_COLUMNS])
    for c in clips.columns:
        if c not in ("clip_id", "modality", "origin", "emotion_label", "theme", *EXTRA_COLUMNS):
            clips[c] = pd.to_numeric(clips[c], errors="coerce")
    sections: list[SectionDesign] = []
    for preset in presets:
        offset = len(sections)
        for spec in PRESETS[preset]["sections"]:
            sections.append(_section(spec, len(sections) + 1, preset, loaded[chosen[preset]], clips, offset))
    return StudyDesign(name or "+".join(presets), presets, {p: loaded[chosen[p]] for p in presets}, tuple(sections),
                       clips)
