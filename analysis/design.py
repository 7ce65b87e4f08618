"""The design of a simulated study, read from study presets and the planned clips of their plans. No Django.

A real study is a preset (``protocol.presets.PRESETS``: its sections, clips per participant, options, pools) filled
with the clips of a plan (``protocol.presets.PRESET_PLANS``). The simulator (:mod:`analysis.simulate`) takes the same
two inputs, so a simulated study has the structure of a real export of that preset: the same sections in the same
order, the same number of clips per participant, the same questions and answer options, and a clips.csv whose rows
are the plan's entries.

The plans' clips come as a planned clips table: clips.csv rows (the public columns,
``protocol.vocabulary.CLIP_COLUMNS``)
plus :data:`EXTRA_COLUMNS`, one SYNTHETIC row ``sim-<plan>-<entry id>`` per plan entry. The table of the preset
plans ships as :data:`PLANNED_CLIPS`; ``python -m generation.plans.planned PLAN --out FILE`` writes one for any plan
(the analysis reads the file and never imports the generation library).

Pools are matched as ``protocol.pools`` defines them (field, ``field__lookup``, lists, the ``transition`` and ``rbf``
shorthands, naturalness sub-pools), on the clip rows plus their ``plan``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from protocol.pools import DEFAULT_GESTURE_OPTIONS, FLAGS, NORMS_RULE, SUB_POOLS, SWITCHES, pool_errors
from protocol.presets import PRESET_PLANS, PRESETS
from protocol.section_types import get_section_type
from protocol.vocabulary import CLIP_COLUMNS, FINAL_EMOTION_COLUMNS, SECTION_QUESTIONS, answer_values

PAPER_PRESETS = ("gait_ismar2020", "gestures_ieeevr2021", "rbf_thms2016")
"""The three papers' studies; simulated one after the other as one SYNTHETIC study by default."""
EXTRA_COLUMNS = ("plan", "entry_id", "source_clip_id", "sections")
"""Columns of a planned clips table and of :attr:`StudyDesign.clips` after CLIP_COLUMNS (not clips.csv's)."""
PLANNED_CLIPS = Path(__file__).resolve().parent / "data" / "planned_clips.csv"
"""The planned clips of every preset's plan (written by ``python -m generation.plans.planned``)."""
TEXT_COLUMNS = ("clip_id", "modality", "origin", "emotion_label", "theme", *EXTRA_COLUMNS)


class DesignError(ValueError):
    """A preset or plan that cannot be simulated; the message names the preset, section or plan."""


@dataclass(frozen=True)
class SectionDesign:
    """One section of the simulated study.

    Attributes:
        order: 1-based position in the study; preset: the preset it comes from.
        section_type: one of protocol.vocabulary.SECTION_TYPES; questions: its question keys (SECTION_QUESTIONS).
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
    def draws_choices(self) -> bool:
        """Its type draws answer choices per participant and clip (gesture_emotion)."""
        return get_section_type(self.section_type).drawn_choices

    @property
    def mixed_naturalness(self) -> bool:
        """A naturalness section that mixes given numbers of generated and source clips
        (studyapp.participant.assignment)."""
        return bool(get_section_type(self.section_type).sub_pools) and (bool(self.sub_pools)
                                                                        or "n_source" in self.options)

    def naturalness_counts(self) -> tuple[int, int]:
        """(n_generated, n_source) of a mixed naturalness section, with the study app's defaults."""
        k = self.n_per_participant
        n_source = int(self.options.get("n_source", k // 2 if k else 0))
        return int(self.options.get("n_generated", (k - n_source) if k else 0)), n_source

    def n_options(self) -> int:
        return int(self.options.get("n_options", DEFAULT_GESTURE_OPTIONS))

    def categories(self) -> tuple[str, ...]:
        """The categories a section with drawn choices offers from (its ``categories``, else its question's domain)."""
        (kind,) = get_section_type(self.section_type).question_kinds.values()
        return tuple(self.options.get("categories") or answer_values(kind))


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


# ---- planned clips ------------------------------------------------------------------------------------------------
def read_planned_clips(path: str | Path = PLANNED_CLIPS) -> pd.DataFrame:
    """A planned clips table (CSV): CLIP_COLUMNS + :data:`EXTRA_COLUMNS`, numbers as floats (blank NaN), blank
    ``emotion_label``/``theme`` None, blank ``source_clip_id``/``sections`` "". Raises DesignError naming missing
    columns."""
    try:
        raw = pd.read_csv(path, dtype=str, keep_default_na=False)
    except (OSError, pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise DesignError(f"planned clips {path}: cannot read ({exc})") from None
    missing = [c for c in (*CLIP_COLUMNS, *EXTRA_COLUMNS) if c not in raw.columns]
    if missing:
        raise DesignError(f"planned clips {path}: missing columns {missing} "
                          "(write the table with python -m generation.plans.planned)")
    return clip_table(raw[[*CLIP_COLUMNS, *EXTRA_COLUMNS]])


def clip_table(clips: pd.DataFrame) -> pd.DataFrame:
    """The design's clip table from planned clip rows: numeric columns as floats (blank NaN), text columns as
    strings with blanks missing (``source_clip_id`` and ``sections`` keep "" for none), rows renumbered from 0."""
    out = {}
    for c in clips.columns:
        if c not in TEXT_COLUMNS:
            out[c] = pd.to_numeric(clips[c], errors="coerce").to_numpy(float)
        else:
            out[c] = [v if isinstance(v, str) and (v or c in ("source_clip_id", "sections")) else None
                      for v in clips[c]]
    return pd.DataFrame(out, columns=list(clips.columns))


# ---- pool filters (protocol.pools semantics) -----------------------------------------------------------------------
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
        if key in SUB_POOLS or key in SWITCHES or key == NORMS_RULE:
            continue     # simulated clips have no quality flags and no norms
        if key not in FLAGS and key.partition("__")[0] not in clips.columns:
            raise DesignError(f"pool filter {key!r}: the simulated catalogue has no such column")
        mask &= _one_filter(clips, key, value)
    return mask


# ---- presets -> design ---------------------------------------------------------------------------------------------
def _section(spec: dict, order: int, preset: str, plan: str, clips: pd.DataFrame, offset: int) -> SectionDesign:
    """One preset section (with the preset's plan as pool filter, as studyapp.staff.presets.preset_sections does)."""
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
                        name: str | None = None, clips: pd.DataFrame | str | Path | None = None) -> StudyDesign:
    """The design of a study made of ``presets`` (one after the other), each drawing the clips of its plan.

    Args:
        presets: keys of protocol.presets.PRESETS, e.g. ("demo",) or the default :data:`PAPER_PRESETS`.
        plans: preset -> plan name (default protocol.presets.PRESET_PLANS).
        clips: the planned clips table (a DataFrame of CLIP_COLUMNS + :data:`EXTRA_COLUMNS` or a CSV path; default
            :data:`PLANNED_CLIPS`) holding the rows of every chosen plan.
    Raises DesignError naming the preset, plan or section when a preset is unknown, a plan has no rows in the
    table or a pool selects no clip of the plan.
    """
    presets = tuple(presets)
    unknown = [p for p in presets if p not in PRESETS]
    if unknown or not presets:
        raise DesignError(f"unknown preset(s) {unknown}; choose among {sorted(PRESETS)}")
    if isinstance(clips, pd.DataFrame):
        table = clip_table(clips)
    else:
        table = read_planned_clips(PLANNED_CLIPS if clips is None else clips)
    chosen = {p: str((plans or {}).get(p, PRESET_PLANS[p])) for p in presets}
    parts = []
    for plan in dict.fromkeys(chosen.values()):
        rows = table[table["plan"] == plan]
        if rows.empty:
            raise DesignError(f"plan {plan!r} has no rows in the planned clips table (known: "
                              f"{sorted(set(table['plan']))}); write them with "
                              f"python -m generation.plans.planned {plan} --out FILE and pass that file")
        parts.append(rows)
    table = clip_table(pd.concat(parts))
    sections: list[SectionDesign] = []
    for preset in presets:
        offset = len(sections)
        for spec in PRESETS[preset]["sections"]:
            sections.append(_section(spec, len(sections) + 1, preset, chosen[preset], table, offset))
    return StudyDesign(name or "+".join(presets), presets, dict(chosen), tuple(sections), table)
