"""Readers and validators for the public study exports (DESIGN.md "Interchange formats").

Every reader takes a path or an open text file, reads all cells as strings (nothing is converted or dropped
silently), checks each row and raises :class:`ValidationError` listing every problem with file, row and column.
Row numbers are file line numbers: the header is line 1, the first data row line 2.

The checks are vectorised (one boolean mask per rule), so a 1.7-million-row responses.csv validates in seconds.
"""

from __future__ import annotations

import io
import os
import re
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from protocol.section_types import registered
from protocol.section_types.registry import LiveTuple
from protocol.vocabulary import (
    ANSWER_QUESTIONS,
    ATTENTION_CHECK,
    ATTENTION_COLUMNS,
    CLIP_BODY_COLUMNS,
    CLIP_COLUMNS,
    CLIP_MODALITIES,
    CLIP_PROVENANCE_COLUMNS,
    CLIP_THEMES,
    FINAL_EMOTION_COLUMNS,
    GAIT_EMOTIONS,
    GAIT_MULTI,
    GESTURE_EMOTIONS,
    INTEGER_RANGES,
    LABEL_CHOICES,
    MULTI_SELECT_KINDS,
    ORIGINS,
    PARTICIPANT_COLUMNS,
    QA_COLUMNS,
    QA_FLOAT_COLUMNS,
    RESPONSE_COLUMNS,
    VAD_DIMENSIONS,
    VIEWING_COLUMNS,
    VIEWING_COLUMNS_V1,
    VIEWING_FIELDS,
    VIEWING_RECORDS,
    VIEWING_SERVER_FIELDS,
)

ANSWER_KINDS = LiveTuple(lambda: tuple(dict.fromkeys(kind for questions in ANSWER_QUESTIONS.values()
                                                     for kind in questions.values())))
"""Every answer kind the sections use (:data:`protocol.vocabulary.ANSWER_QUESTIONS`: each section's own questions and
the norming questions), in first-use order."""

MAX_LISTED = 20


@dataclass(frozen=True)
class Problem:
    """One invalid cell: file name, line number (header = 1; 0 = whole file), column, message. A problem of several
    cells of one line (shares that do not sum to one) names its columns joined by ", "."""

    file: str
    line: int
    column: str
    message: str

    def __str__(self) -> str:
        where = f"line {self.line}" if self.line else "header"
        columns = self.column.split(", ")
        named = f"column '{self.column}'" if len(columns) == 1 else "columns " + ", ".join(f"'{c}'" for c in columns)
        return f"{self.file} {where}, {named}: {self.message}"


class ValidationError(ValueError):
    """Raised when an export is invalid. ``problems`` holds the first problems, ``total`` counts all of them."""

    def __init__(self, problems: list[Problem], total: int | None = None):
        self.problems = list(problems)
        self.total = len(self.problems) if total is None else total
        shown = "\n".join(f"  {p}" for p in self.problems[:MAX_LISTED])
        more = f"\n  ... and {self.total - MAX_LISTED} more" if self.total > MAX_LISTED else ""
        super().__init__(f"{self.total} problem(s) in the study exports:\n{shown}{more}")


@dataclass
class _Collector:
    """Collects problems from boolean masks; keeps the first few per rule and the total count."""

    file: str
    problems: list[Problem] = field(default_factory=list)
    total: int = 0

    def add_mask(self, df: pd.DataFrame, mask, column: str, message) -> None:
        """Record every row where ``mask`` is True. ``message`` is a str or a function of the offending cell."""
        mask = np.asarray(mask, dtype=bool)
        n = int(mask.sum())
        if not n:
            return
        self.total += n
        idx = np.flatnonzero(mask)[:MAX_LISTED]
        values = df[column].to_numpy()[idx] if column in df.columns else [None] * len(idx)
        lines = df["_line"].to_numpy()[idx]
        for line, value in zip(lines, values):
            text = message(value) if callable(message) else message
            self.problems.append(Problem(self.file, int(line), column, text))

    def add(self, line: int, column: str, message: str) -> None:
        self.total += 1
        self.problems.append(Problem(self.file, line, column, message))


def _name(src, default: str) -> str:
    if isinstance(src, (str, os.PathLike)):
        return os.path.basename(os.fspath(src))
    return os.path.basename(getattr(src, "name", default) or default)


def _read_raw(src, default_name: str) -> tuple[pd.DataFrame, str]:
    """Read a CSV as strings (no NA conversion). Adds ``_line`` (file line number of each row)."""
    name = _name(src, default_name)
    if isinstance(src, bytes):
        src = io.BytesIO(src)
    try:
        df = pd.read_csv(src, dtype=str, keep_default_na=False, na_filter=False, skipinitialspace=False)
    except pd.errors.EmptyDataError as exc:
        raise ValidationError([Problem(name, 0, "*", "file is empty (no header row)")]) from exc
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise ValidationError([Problem(name, 0, "*", f"not a readable CSV file: {exc}")]) from exc
    df.columns = [str(c).strip() for c in df.columns]
    df["_line"] = np.arange(2, len(df) + 2)
    return df, name


def _check_columns(df: pd.DataFrame, required, col: _Collector) -> None:
    missing = [c for c in required if c not in df.columns]
    for c in missing:
        col.add(0, c, f"required column is missing (expected columns: {', '.join(required)})")
    if missing:
        raise ValidationError(col.problems, col.total)


def _numeric(s: pd.Series) -> pd.Series:
    return pd.to_numeric(s.str.strip(), errors="coerce")


def _blank(s: pd.Series) -> np.ndarray:
    return (s.str.strip() == "").to_numpy()


def read_clips(src) -> pd.DataFrame:
    """Read and validate clips.csv (one row per clip).

    Returns a DataFrame indexed by ``clip_id`` with typed columns: intended vector ``happy..neutral`` and
    ``final_*`` as float (NaN where blank, vectors l1-normalised), ``valence, arousal, dominance`` float in 0..1,
    ``weight`` float, ``n_features`` float (integral), ``duration_s`` float seconds, text columns lower-cased.
    """
    df, name = _read_raw(src, "clips.csv")
    col = _Collector(name)
    _check_columns(df, CLIP_COLUMNS, col)
    for c in ("modality", "origin", "emotion_label", "theme"):
        df[c] = df[c].str.strip().str.lower()
    df["clip_id"] = df["clip_id"].str.strip()
    col.add_mask(df, _blank(df["clip_id"]), "clip_id", "clip_id is empty")
    dup = df["clip_id"].duplicated(keep="first").to_numpy() & ~_blank(df["clip_id"])
    col.add_mask(df, dup, "clip_id", lambda v: f"duplicate clip_id {v!r}")
    col.add_mask(df, ~df["modality"].isin(CLIP_MODALITIES), "modality",
                 lambda v: f"{v!r} is not one of {', '.join(CLIP_MODALITIES)}")
    col.add_mask(df, ~df["origin"].isin(ORIGINS), "origin",
                 lambda v: f"{v!r} is not one of {', '.join(ORIGINS)}")

    out = pd.DataFrame({"clip_id": df["clip_id"], "modality": df["modality"], "origin": df["origin"],
                        "emotion_label": df["emotion_label"], "theme": df["theme"], "_line": df["_line"]})
    for group in (GAIT_EMOTIONS, FINAL_EMOTION_COLUMNS):
        blank = np.column_stack([_blank(df[c]) for c in group])
        values = np.column_stack([_numeric(df[c]).to_numpy() for c in group])
        partial = blank.any(axis=1) & ~blank.all(axis=1)
        for j, c in enumerate(group):
            col.add_mask(df, partial & blank[:, j], c, f"blank while other {group[0]}.. cells of the vector are set")
            bad = ~blank[:, j] & ~(values[:, j] >= 0)
            col.add_mask(df, bad, c, lambda v: f"{v!r} is not a number >= 0")
        total = np.nansum(values, axis=1)
        given = ~blank.any(axis=1)
        col.add_mask(df, given & ~(total > 0), group[0], "emotion vector sums to 0")
        with np.errstate(invalid="ignore", divide="ignore"):
            normed = values / total[:, None]
        normed[~given] = np.nan
        for j, c in enumerate(group):
            out[c] = normed[:, j]
    for c in VAD_DIMENSIONS:
        v = _numeric(df[c])
        col.add_mask(df, ~_blank(df[c]) & ~((v >= 0) & (v <= 1)).to_numpy(), c, lambda x: f"{x!r} is not in 0..1")
        out[c] = v.to_numpy()
    for c in ("weight", "n_features", "duration_s"):
        v = _numeric(df[c])
        col.add_mask(df, ~_blank(df[c]) & v.isna().to_numpy(), c, lambda x: f"{x!r} is not a number")
        out[c] = v.to_numpy()
    nf = out["n_features"]
    col.add_mask(df, (nf.notna() & ((nf < 0) | (nf != nf.round()))).to_numpy(), "n_features",
                 lambda x: f"{x!r} is not an integer >= 0")
    col.add_mask(df, (out["duration_s"] < 0).to_numpy(), "duration_s", lambda x: f"{x!r} is negative")
    has_theme = ~_blank(df["theme"])
    # "neutral" marks the unstyled input walk of seed 004 (weight 0, no features; Table I).
    col.add_mask(df, has_theme & ~df["theme"].isin(CLIP_THEMES).to_numpy(), "theme",
                 lambda v: f"{v!r} is not one of {', '.join(CLIP_THEMES)}")
    col.add_mask(df, has_theme & out["weight"].isna().to_numpy(), "weight", "a theme clip needs a weight")
    label = df["emotion_label"]
    bad_label = (df["modality"] == "gesture").to_numpy() & ~_blank(label) & ~label.isin(GESTURE_EMOTIONS).to_numpy()
    col.add_mask(df, bad_label, "emotion_label",
                 lambda v: f"{v!r} is not an NRC-VAD category ({', '.join(GESTURE_EMOTIONS)})")
    _read_qa_columns(df, out, col)
    for c in CLIP_BODY_COLUMNS:  # the human body preset a clip shows (blank for the other looks)
        if c in df.columns:
            out[c] = df[c].fillna("").astype(str).str.strip().to_numpy()
    if col.total:
        raise ValidationError(col.problems, col.total)
    out = out.set_index("clip_id", drop=False)
    out.attrs["ignored_columns"] = [c for c in df.columns if c not in CLIP_COLUMNS and c not in QA_COLUMNS
                                    and c not in CLIP_PROVENANCE_COLUMNS and c not in CLIP_BODY_COLUMNS
                                    and c != "_line"]
    return out


def _read_qa_columns(df: pd.DataFrame, out: pd.DataFrame, col: _Collector) -> None:
    """The optional quality columns (QA_COLUMNS) into ``out``: numbers as float (NaN where blank), text
    stripped; a clips.csv without them simply has none."""
    for c in QA_COLUMNS:
        if c not in df.columns:
            continue
        if c in QA_FLOAT_COLUMNS:
            v = _numeric(df[c])
            col.add_mask(df, ~_blank(df[c]) & v.isna().to_numpy(), c, lambda x: f"{x!r} is not a number")
            out[c] = v.to_numpy()
        else:
            out[c] = df[c].str.strip().to_numpy()


def _parse_datetime(s: pd.Series) -> pd.Series:
    return pd.to_datetime(s.str.strip().replace("", None), format="ISO8601", utc=True, errors="coerce")


REQUIRED_PARTICIPANT_COLUMNS = PARTICIPANT_COLUMNS[:PARTICIPANT_COLUMNS.index(ATTENTION_COLUMNS[0])]
"""participants.csv columns every export has; the later ones of PARTICIPANT_COLUMNS (attention checks, section
order) are read when present (older exports lack them)."""


def read_participants(src) -> pd.DataFrame:
    """Read and validate participants.csv. Extra columns (e.g. feedback) are kept; the columns after
    :data:`REQUIRED_PARTICIPANT_COLUMNS` may be missing.

    Returns a DataFrame indexed by ``participant_id``; ``started_at``/``completed_at`` become UTC timestamps
    (NaT when blank), blank ``gender``/``age_group`` become ``"undisclosed"``, ``duration_s`` is added (float
    seconds, NaN unless both timestamps are set) and ``completed`` (bool: completed_at set or status
    ``completed``).
    """
    df, name = _read_raw(src, "participants.csv")
    col = _Collector(name)
    _check_columns(df, REQUIRED_PARTICIPANT_COLUMNS, col)
    df["participant_id"] = df["participant_id"].str.strip()
    col.add_mask(df, _blank(df["participant_id"]), "participant_id", "participant_id is empty")
    dup = df["participant_id"].duplicated().to_numpy() & ~_blank(df["participant_id"])
    col.add_mask(df, dup, "participant_id", lambda v: f"duplicate participant_id {v!r}")
    for c in ("started_at", "completed_at"):
        parsed = _parse_datetime(df[c])
        col.add_mask(df, ~_blank(df[c]) & parsed.isna().to_numpy(), c,
                     lambda v: f"{v!r} is not an ISO-8601 date-time")
        df[c] = parsed
    dur = (df["completed_at"] - df["started_at"]).dt.total_seconds()
    col.add_mask(df, (dur < 0).to_numpy(), "completed_at", "completed_at is before started_at")
    if col.total:
        raise ValidationError(col.problems, col.total)
    for c in ("gender", "age_group"):
        df[c] = df[c].str.strip().str.lower().replace("", "undisclosed")
    df["status"] = df["status"].str.strip().str.lower()
    df["duration_s"] = dur
    df["completed"] = df["completed_at"].notna() | (df["status"] == "completed")
    return df.set_index("participant_id", drop=False)


def read_viewing(src, participants: pd.DataFrame | None = None) -> pd.DataFrame:
    """Read and validate viewing.csv (:data:`protocol.vocabulary.VIEWING_COLUMNS`, one row per answered clip page).

    ``participant_id`` and ``clip_id`` must be set; every field of :data:`protocol.vocabulary.VIEWING_FIELDS`, and
    ``page_ms`` and ``shows``, is blank (unknown, or no record) or a non-negative integer (times in ms, counts);
    ``record`` is blank or one of :data:`protocol.vocabulary.VIEWING_RECORDS`. The columns of the first version
    (:data:`protocol.vocabulary.VIEWING_COLUMNS_V1`) are required; a later one that is absent (an older export) reads
    as blank. With ``participants`` (as from :func:`read_participants`) every participant_id must be one of them.
    Returns the rows with the numeric fields as floats (NaN where blank) and ``record`` as a string; extra columns
    are kept."""
    df, name = _read_raw(src, "viewing.csv")
    col = _Collector(name)
    _check_columns(df, VIEWING_COLUMNS_V1, col)
    for c in VIEWING_COLUMNS:
        if c not in df.columns:
            df[c] = ""
    for c in ("participant_id", "clip_id", "section_type"):
        df[c] = df[c].str.strip()
    for c in ("participant_id", "clip_id"):
        col.add_mask(df, _blank(df[c]), c, f"{c} is empty")
    if participants is not None:
        known = set(participants["participant_id"].astype(str))
        col.add_mask(df, ~df["participant_id"].isin(known).to_numpy() & ~_blank(df["participant_id"]),
                     "participant_id", lambda v: f"unknown participant {v!r} (not in participants.csv)")
    df["record"] = df["record"].str.strip().str.lower()
    col.add_mask(df, ~_blank(df["record"]) & ~df["record"].isin(VIEWING_RECORDS).to_numpy(), "record",
                 lambda v: f"{v!r} is not blank or one of {', '.join(VIEWING_RECORDS)}")
    for c in (*VIEWING_FIELDS, *(f for f in VIEWING_SERVER_FIELDS if f != "record")):
        value = _numeric(df[c])
        bad = ~_blank(df[c]) & ~(value.notna() & (value >= 0) & (value == value.round())).to_numpy()
        col.add_mask(df, bad, c, lambda v: f"{v!r} is not blank or a non-negative integer")
        df[c] = value.astype(float)
    if col.total:
        raise ValidationError(col.problems, col.total)
    return df.drop(columns="_line").reset_index(drop=True)


class _CodedColumn:
    """A column as integer codes into its distinct cleaned values, so checks run once per distinct value.

    ``codes`` (N,) int, -1 never occurs; ``values`` (U,) object array of distinct cleaned strings.
    """

    def __init__(self, raw: pd.Series, lower: bool = False):
        cat = raw.astype("category") if not isinstance(raw.dtype, pd.CategoricalDtype) else raw
        cleaned = pd.Index(cat.cat.categories.astype(object)).map(lambda v: str(v).strip())
        if lower:
            cleaned = cleaned.map(str.lower)
        new_codes, uniques = pd.factorize(np.asarray(cleaned, dtype=object))
        old = cat.cat.codes.to_numpy()
        self.codes = new_codes[old] if len(new_codes) else old
        self.values = np.asarray(uniques, dtype=object)

    def mask(self, per_value) -> np.ndarray:
        """Broadcast a per-distinct-value boolean (U,) to rows (N,)."""
        return np.asarray(per_value, dtype=bool)[self.codes]

    def rows(self) -> np.ndarray:
        return self.values[self.codes]

    def categorical(self) -> pd.Categorical:
        cats, inv = np.unique(self.values.astype(str), return_inverse=True)
        return pd.Categorical.from_codes(inv[self.codes], cats)


class _RowProblems:
    """Problems of coded columns: each offending cell is decoded only for the first few rows of a rule."""

    def __init__(self, name: str, lines: pd.Series):
        self.col = _Collector(name)
        self.shown = pd.DataFrame({"_line": lines})

    def add(self, mask, column: str, message, coded: _CodedColumn) -> None:
        mask = np.asarray(mask, dtype=bool)
        if mask.any():
            idx = np.flatnonzero(mask)[:MAX_LISTED]
            self.shown.loc[self.shown.index[idx], column] = coded.values[coded.codes[idx]]
            self.col.add_mask(self.shown, mask, column, message)


_LOWERED = ("section_type", "question")
"""responses.csv columns compared case-insensitively."""

_MULTI_NOUN = {GAIT_MULTI: "gait emotions"}
"""What the labels of a multi-select answer kind are called in messages."""


def _multi_pattern(choices) -> re.Pattern:
    alt = "|".join(choices)
    return re.compile(rf"\s*(?:{alt})\s*(?:;\s*(?:{alt})\s*)*")


_MULTI_PATTERNS = {kind: _multi_pattern(LABEL_CHOICES[kind]) for kind in MULTI_SELECT_KINDS}


def _read_categorical(src, name: str) -> pd.DataFrame:
    """Read a CSV with every column categorical (no NA conversion). Adds ``_line`` (file line number of each row)."""
    if isinstance(src, bytes):
        src = io.BytesIO(src)
    try:
        raw = pd.read_csv(src, dtype="category", keep_default_na=False, na_filter=False)
    except pd.errors.EmptyDataError as exc:
        raise ValidationError([Problem(name, 0, "*", "file is empty (no header row)")]) from exc
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise ValidationError([Problem(name, 0, "*", f"not a readable CSV file: {exc}")]) from exc
    raw.columns = [str(c).strip() for c in raw.columns]
    if raw.empty and not len(raw.columns):
        raise ValidationError([Problem(name, 0, "*", "file is empty (no header row)")])
    raw["_line"] = np.arange(2, len(raw) + 2)
    return raw


def _check_participants(pid: _CodedColumn, participants: pd.DataFrame | None, rows: _RowProblems) -> None:
    """participant_id set, and known when ``participants`` is given."""
    rows.add(pid.mask(pid.values == ""), "participant_id", "participant_id is empty", pid)
    if participants is not None:
        unknown = (pid.values != "") & ~pd.Index(pid.values).isin(participants.index)
        rows.add(pid.mask(unknown), "participant_id",
                 lambda v: f"unknown participant {v!r} (not in participants.csv)", pid)


def _answer_kinds(sec: _CodedColumn, qst: _CodedColumn) -> np.ndarray:
    """Row -> index into :data:`ANSWER_KINDS` of its (section_type, question) pair, -1 where the pair is not in
    ANSWER_QUESTIONS. Looked up once per distinct pair."""
    table = np.full((len(sec.values), len(qst.values)), -1, dtype=np.int8)
    kinds = tuple(ANSWER_KINDS)
    for i, section in enumerate(sec.values):
        for j, question in enumerate(qst.values):
            kind = ANSWER_QUESTIONS.get(section, {}).get(question)
            if kind is not None:
                table[i, j] = kinds.index(kind)
    return table[sec.codes, qst.codes]


def _check_sections(sec: _CodedColumn, qst: _CodedColumn, kind: np.ndarray, rows: _RowProblems) -> None:
    """A known section_type, and a question of that section."""
    sections = list(ANSWER_QUESTIONS)
    known = np.isin(sec.values, sections)
    rows.add(sec.mask(~known), "section_type", lambda v: f"{v!r} is not one of {', '.join(sections)}", sec)
    bad_q = sec.mask(known) & (kind < 0)
    if bad_q.any():
        present = set(sec.rows()[bad_q])
        listed = "; ".join(f"{s}: {', '.join(qs)}" for s, qs in ANSWER_QUESTIONS.items() if s in present)
        rows.add(bad_q, "question", lambda v: f"{v!r} is not a question of its section_type ({listed})", qst)


def _check_answer(kind: str, answer: str) -> tuple[str | None, str, float]:
    """One answer of one kind -> (problem message or None, cleaned label, value: the integer or NaN)."""
    if kind in INTEGER_RANGES:
        lo, hi = INTEGER_RANGES[kind]
        try:
            v = float(answer)
        except ValueError:
            v = np.nan
        if not (lo <= v <= hi and v == round(v)):
            return f"{answer!r} is not an integer in {lo}..{hi}", answer, np.nan
        return None, answer, v
    choices = LABEL_CHOICES[kind]
    if kind in MULTI_SELECT_KINDS:
        label = re.sub(r"\s+", "", answer.lower())
        if _MULTI_PATTERNS[kind].fullmatch(answer.lower()) is None:
            noun = _MULTI_NOUN.get(kind, "labels")
            return f"{answer!r} is not {noun} ({', '.join(choices)}) joined by ';'", label, np.nan
        return None, label, np.nan
    if answer.lower() not in choices:
        return f"{answer!r} is not one of {', '.join(choices)}", answer.lower(), np.nan
    return None, answer.lower(), np.nan


def _check_answers(kind: np.ndarray, ans: _CodedColumn, col: _Collector):
    """Validate each distinct (kind, answer) pair once (rows of unknown questions are not checked).

    Returns (per-pair cleaned label, per-pair value, row -> pair index)."""
    kinds = tuple(ANSWER_KINDS)
    pair = kind.astype(np.int64) * len(ans.values) + ans.codes
    upair, pair_inv = np.unique(pair, return_inverse=True)
    pair_value = np.full(len(upair), np.nan)
    pair_label = np.empty(len(upair), dtype=object)
    pair_msg = np.empty(len(upair), dtype=object)
    for u, code in enumerate(upair):
        k_i, a_i = divmod(int(code), len(ans.values))
        pair_label[u] = ans.values[a_i]
        if 0 <= k_i < len(kinds):
            pair_msg[u], pair_label[u], pair_value[u] = _check_answer(kinds[k_i], ans.values[a_i])
    pair_bad = np.fromiter((m is not None for m in pair_msg), dtype=bool, count=len(pair_msg))
    bad = np.flatnonzero(pair_bad[pair_inv])
    col.total += len(bad)
    for i in bad[:MAX_LISTED]:
        col.problems.append(Problem(col.file, int(i) + 2, "answer", str(pair_msg[pair_inv[i]])))
    return pair_label, pair_value, pair_inv


CLIP_FIELD_DOMAINS = {"emotion_label": GESTURE_EMOTIONS}
"""clips.csv label columns a section's clip need counts only with a value of this vocabulary."""


def _has(cu: pd.DataFrame, column: str) -> np.ndarray:
    """Per clip of ``cu``: ``column`` holds a value (non-blank; in its vocabulary for CLIP_FIELD_DOMAINS)."""
    values = cu[column]
    if column in CLIP_FIELD_DOMAINS:
        return values.isin(CLIP_FIELD_DOMAINS[column]).to_numpy()
    return ~(values.isna().to_numpy() | values.isin([""]).to_numpy())


def _clip_needs(cu: pd.DataFrame) -> dict[str, tuple[np.ndarray, str]]:
    """section_type -> (per clip of ``cu``: lacks what the section needs, message), from the section types'
    declared clip needs (``SectionType.clip_need``: every field of one of its alternatives). A type without one
    (emotion_choice: an unlabelled real walk may be rated for norms) needs nothing beyond a known clip."""
    out = {}
    for spec in registered():
        if spec.clip_need is None:
            continue
        has = np.zeros(len(cu), bool)
        for group in spec.clip_need.any_of:
            has |= np.logical_and.reduce([_has(cu, c) for c in group])
        out[spec.name] = (~has, spec.clip_need.text)
    return out


def _check_clips(clip: _CodedColumn, section_rows: np.ndarray, clips: pd.DataFrame, rows: _RowProblems) -> None:
    """clip_id known, and the clip carries what its row's section needs."""
    known = pd.Index(clip.values).isin(clips.index)
    rows.add(clip.mask(~known), "clip_id", lambda v: f"unknown clip {v!r} (not in clips.csv)", clip)
    for section, (missing, msg) in _clip_needs(clips.reindex(clip.values)).items():
        bad = clip.mask(known & missing) & (section_rows == section)
        rows.add(bad, "clip_id", lambda v, msg=msg: f"clip {v!r} {msg}", clip)


def _check_response_ms(rms: _CodedColumn, rows: _RowProblems) -> np.ndarray:
    """response_ms blank or a number >= 0. Returns the per-distinct-value milliseconds (NaN if blank)."""
    ms = pd.to_numeric(pd.Series(rms.values, dtype=object), errors="coerce").to_numpy(float)
    bad = (rms.values != "") & ~(ms >= 0)
    rows.add(rms.mask(bad), "response_ms", lambda v: f"{v!r} is not a number of milliseconds >= 0", rms)
    return ms


def read_responses(src, clips: pd.DataFrame, participants: pd.DataFrame | None = None) -> pd.DataFrame:
    """Read and validate responses.csv against validated ``clips`` (and ``participants`` if given).

    Checks: known section_type; question allowed for that section (:data:`protocol.vocabulary.ANSWER_QUESTIONS`: its own
    and, for a norming section type, intensity and naturalness); answer of the right kind and range; clip_id known
    and carrying what the section needs (an intended vector for emotion_choice, a final vector for
    emotion_transition, theme/weight/n_features for theme_rating, theme for theme_inversion, an NRC-VAD label or VAD
    values for gesture_emotion); participant known; response_ms a number >= 0 or blank.

    Every column is read as a categorical and each rule is evaluated once per distinct value (or distinct
    (kind, answer) pair), then broadcast to rows: 1.7 million rows validate in about two seconds.

    Returns columns participant_id, section_type, clip_id, question, answer (categoricals of cleaned strings;
    labels lower-cased, multi-select labels without spaces), value (float for integer scales, NaN otherwise),
    response_ms (float, NaN if blank) and _line (file line number). Attention-check answers (section_type
    ``protocol.vocabulary.ATTENTION_CHECK``) are not answers about clips: they are left out of the table and kept in
    ``attrs["attention_checks"]`` ({participant_id, question, answer: lists of text}) for the exclusion rules.
    """
    name = _name(src, "responses.csv")
    raw = _read_categorical(src, name)
    attention = pd.DataFrame(columns=["participant_id", "question", "answer"])
    if "section_type" in raw.columns:
        is_check = (raw["section_type"].astype(str).str.strip() == ATTENTION_CHECK).to_numpy()
        if is_check.any():
            attention = raw.loc[is_check, [c for c in attention.columns if c in raw.columns]].astype(str)
            raw = raw[~is_check].reset_index(drop=True)
            for c in raw.columns:
                if isinstance(raw[c].dtype, pd.CategoricalDtype):
                    raw[c] = raw[c].cat.remove_unused_categories()
    rows = _RowProblems(name, raw["_line"])
    _check_columns(raw, RESPONSE_COLUMNS, rows.col)
    coded = {c: _CodedColumn(raw[c], lower=c in _LOWERED) for c in RESPONSE_COLUMNS}
    sec, qst = coded["section_type"], coded["question"]
    _check_participants(coded["participant_id"], participants, rows)
    kind = _answer_kinds(sec, qst)
    _check_sections(sec, qst, kind, rows)
    pair_label, pair_value, pair_inv = _check_answers(kind, coded["answer"], rows.col)
    _check_clips(coded["clip_id"], sec.rows(), clips, rows)
    ms = _check_response_ms(coded["response_ms"], rows)
    if rows.col.total:
        raise ValidationError(sorted(rows.col.problems, key=lambda p: p.line)[:MAX_LISTED], rows.col.total)
    n = len(raw)
    out = pd.DataFrame({
        **{c: coded[c].categorical() for c in ("participant_id", "section_type", "clip_id", "question")},
        "answer": pd.Categorical.from_codes(*_recode(pair_label, pair_inv)),
        "value": pair_value[pair_inv] if n else np.empty(0),
        "response_ms": ms[coded["response_ms"].codes] if n else np.empty(0),
        "_line": raw["_line"].to_numpy(),
    })
    out.attrs["ignored_columns"] = [c for c in raw.columns if c not in RESPONSE_COLUMNS and c != "_line"]
    out.attrs["attention_checks"] = {c: attention[c].tolist() for c in attention.columns}  # plain lists: attrs
    # are compared by pandas when frames are combined, which a DataFrame value would break
    return out


def _recode(labels: np.ndarray, inv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-distinct labels + row indices into them -> (row codes, unique categories) for Categorical.from_codes."""
    cats, code = np.unique(labels.astype(str), return_inverse=True)
    return code[inv] if len(inv) else np.empty(0, dtype=int), cats


@dataclass
class StudyData:
    """The three validated exports, and viewing.csv when given (else None). ``ignored_columns`` names unknown
    columns that were not used."""

    responses: pd.DataFrame
    clips: pd.DataFrame
    participants: pd.DataFrame
    ignored_columns: dict[str, list[str]] = field(default_factory=dict)
    viewing: pd.DataFrame | None = None


def load_study(responses_src, clips_src, participants_src, viewing_src=None) -> StudyData:
    """Read and cross-validate all three exports, and viewing.csv when ``viewing_src`` is given (it is optional:
    older exports lack it). Problems of every file are gathered into one ValidationError."""
    problems: list[Problem] = []
    total = 0
    clips = participants = None
    try:
        clips = read_clips(clips_src)
    except ValidationError as exc:
        problems += exc.problems
        total += exc.total
    try:
        participants = read_participants(participants_src)
    except ValidationError as exc:
        problems += exc.problems
        total += exc.total
    if clips is None:
        raise ValidationError(problems[:MAX_LISTED], total)
    try:
        responses = read_responses(responses_src, clips, participants)
    except ValidationError as exc:
        problems += exc.problems
        total += exc.total
    viewing = None
    if viewing_src is not None:
        try:
            viewing = read_viewing(viewing_src, participants)
        except ValidationError as exc:
            problems += exc.problems
            total += exc.total
    if total:
        raise ValidationError(problems[:MAX_LISTED], total)
    ignored = {name: df.attrs.get("ignored_columns", []) for name, df in (("clips.csv", clips),
                                                                       ("responses.csv", responses))}
    return StudyData(responses, clips, participants, {k: v for k, v in ignored.items() if v}, viewing)
