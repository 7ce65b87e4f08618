"""The data dictionary of a study's exports: every file, every column, its meaning, type and allowed values or
units; ``answer`` of responses.csv per section type and question. Written from this package's own definitions
(the column tuples, SECTION_QUESTIONS / ANSWER_QUESTIONS and the answer domains of vocabulary.py), so an export
column without an entry here is an error (:class:`DictionaryError`), not a silent gap.

``dictionary_rows(files)`` -> one dict per row with :data:`DICTIONARY_COLUMNS`; ``files`` maps each exported file
name to its header. Feedback columns of participants.csv (a study's own questions) are described from the study's
feedback questions, given as ``feedback``.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

from .section_types import page_types
from .vocabulary import (
    ANSWER_QUESTIONS,
    ATTENTION_CHECK,
    CLIP_MODALITIES,
    CLIP_THEMES,
    FINAL_EMOTION_COLUMNS,
    GAIT_EMOTIONS,
    GESTURE_EMOTIONS,
    INTEGER_RANGES,
    LIKERT_LEVELS,
    MULTI_SELECT_KINDS,
    ORIGINS,
    SECTION_TYPES,
    VAD_DIMENSIONS,
    VIEWING_RECORDS,
    answer_values,
)

DICTIONARY_COLUMNS = ("file", "column", "applies_to", "meaning", "type", "allowed_values", "units")
"""Columns of data_dictionary.csv."""

PARTICIPANT_STATUSES = ("consented", "started", "completed", "withdrawn")
"""Values of participants.csv ``status`` (the study app's participant states)."""

PILOT_PREFIX = "pilot-"
"""The start of a pilot participant's id (a participant who took part while the study was in pilot mode)."""

_TIME = ("datetime", "", "ISO 8601 with time zone")
_MS = ("integer", "", "milliseconds")
_COUNT = ("integer", "", "count")

PARTICIPANT_ID = ("The participant's opaque id in this export (not a recruitment id); ids starting with "
                  f"'{PILOT_PREFIX}' are pilot participants")
SECTION_TYPE = "The type of the section the row belongs to; attention checks have their own type"
CLIP_ID = "The clip's id: a content hash of how it was made (clips.csv has one row per clip)"

# column -> (meaning, type, allowed values (a tuple) or "", units)
_SHARED = {
    "participant_id": (PARTICIPANT_ID, "string", "", ""),
    "clip_id": (CLIP_ID, "string", "", ""),
    "section_type": (SECTION_TYPE, "string", (*SECTION_TYPES, ATTENTION_CHECK), ""),
}

_CLIPS = {
    "modality": ("What the clip shows: a walk, a gesture, or another imported video", "string", CLIP_MODALITIES,
                 ""),
    "origin": ("How the clip was made: by a generator, the source motion a generator started from, or imported by "
               "the researcher", "string", ORIGINS, ""),
    **{e: (f"Intended share of '{e}' in the gait emotion vector (at the start of a transition)", "number", "",
           "share 0..1; the four sum to 1") for e in GAIT_EMOTIONS},
    **{c: (f"Intended share of '{c.removeprefix('final_')}' at the end of a transition (blank: no transition)",
           "number", "", "share 0..1") for c in FINAL_EMOTION_COLUMNS},
    "emotion_label": ("Intended emotion of a gesture", "string", GESTURE_EMOTIONS, ""),
    **{d: (f"Intended {d} of a gesture (NRC-VAD lexicon)", "number", "", "0..1") for d in VAD_DIMENSIONS},
    "theme": ("Style theme of an RBF-styled walk (neutral: the unstyled input walk)", "string", CLIP_THEMES, ""),
    "weight": ("Strength of the style theme (negative: inverted towards the opposite theme)", "number", "",
               "weight, -3..3"),
    "n_features": ("Number of style features applied", "integer", "", "count"),
    "duration_s": ("Length of the clip", "number", "", "seconds"),
    "title": ("A readable label: generator, condition, variant (for researchers; never shown to participants)",
              "string", "", ""),
    "licence": ("Licence of what the clip was made from (captured or imported material)", "string", "", ""),
    "citation": ("How to cite what the clip was made from", "string", "", ""),
    "body": ("The human body preset the clip shows (generation/data/bodies; blank: another figure or an imported "
             "video); a study may vary it as a factor", "string", "", ""),
}

_RESPONSES = {
    "question": ("The question answered: its key within the section type; for an attention check "
                 "'<key>=<instructed answer>'", "string", "", ""),
    "answer": ("The answer (see the rows per section type and question)", "string", "", ""),
    "response_ms": ("Time from the clip page's display to the answer", "integer", "", "milliseconds"),
}

_PARTICIPANTS = {
    "gender": ("Gender the participant gave (blank: not asked or not given)", "string", "", ""),
    "age_group": ("Age group the participant gave", "string", "", ""),
    "started_at": ("When the participant started the first clip", *_TIME),
    "completed_at": ("When the participant finished the study", *_TIME),
    "status": ("Where the participant got to", "string", PARTICIPANT_STATUSES, ""),
    "external_id": ("The recruitment platform's id (Prolific PROLIFIC_PID); personal data: keep it apart",
                    "string", "", ""),
    "attention_passed": ("Attention checks answered as instructed", *_COUNT),
    "attention_total": ("Attention checks answered", *_COUNT),
    "section_order": ("The sections' order numbers in the order this participant took them, ';'-separated",
                      "list of integers", "", ""),
}

_ASSIGNMENTS = {
    "section_order": ("The section's order number in the study", "integer", "", ""),
    "position": ("The clip's position within the section for this participant (0-based)", "integer", "", ""),
    "options": ("The answer options shown, in order, ';'-separated (blank: the section's fixed options)",
                "list of strings", "", ""),
    "shown_at": ("When the clip page was first shown", *_TIME),
    "answered_at": ("When the clip was answered (blank: not yet)", *_TIME),
}

_VIEWING = {
    "first_play_ms": ("From the page's display to the clip's first playing frame (blank: never played)", *_MS),
    "ended_ms": ("From the page's display to the clip's first end (blank: never reached)", *_MS),
    "plays": ("Plays from the start, replays and reloads included", *_COUNT),
    "pauses": ("Pauses by the participant", *_COUNT),
    "seeks": ("Seek attempts (blocked or not)", *_COUNT),
    "stalls": ("Times playback waited for data after the first frame", *_COUNT),
    "stall_ms": ("Total time playback waited for data after the first frame", *_MS),
    "hidden": ("Times the page was hidden while the clip played", *_COUNT),
    "startup_ms": ("From the first request to play to the first frame", *_MS),
    "hidden_ms": ("Total time the page was hidden while the clip played or was held", *_MS),
    "record": ("What the server made of the browser's viewing record", "string", VIEWING_RECORDS, ""),
    "page_ms": ("From the page's first display to the answer, measured by the server", *_MS),
    "shows": ("How often the page was displayed (1 + reloads)", *_COUNT),
}

_PAGES = {
    "page": ("The page's number among this participant's instruction and break pages, in the order taken",
             "integer", "", "1-based"),
    "section_type": ("The kind of page: an instruction page or a break", "string",
                     tuple(t.name for t in page_types()), ""),
    "section_order": ("The page's order number in the study (Section.order)", "integer", "", ""),
    "shown_at": ("When the page was first shown (blank: not yet)", *_TIME),
    "continued_at": ("When the participant pressed Continue (blank: not yet)", *_TIME),
    "seconds": ("From the page's first display to Continue (blank: not yet)", "number", "", "seconds"),
}

FILE_DOCS: dict[str, tuple[str, dict]] = {
    "responses.csv": ("One row per answer: participant, section type, clip, question", _RESPONSES),
    "clips.csv": ("One row per clip the study shows or may show: what it is meant to express", _CLIPS),
    "participants.csv": ("One row per participant who consented; the study's feedback questions follow",
                         _PARTICIPANTS),
    "assignments.csv": ("One row per clip page a participant was given (practice items left out)", _ASSIGNMENTS),
    "viewing.csv": ("One row per answered clip page: how the clip was watched", _VIEWING),
    "pages.csv": ("One row per instruction or break page a participant was given: when it was shown and left",
                  _PAGES),
}
"""File name -> (what one row is, its own columns' entries); participant_id, clip_id and section_type are shared."""


class DictionaryError(KeyError):
    """An exported column the dictionary has no entry for; names the file and the column."""


def _values(values) -> str:
    return " | ".join(values) if isinstance(values, tuple) else str(values)


def _row(file: str, column: str, meaning: str, kind: str, values="", units: str = "", applies_to: str = "") -> dict:
    return {"file": file, "column": column, "applies_to": applies_to, "meaning": meaning, "type": kind,
            "allowed_values": _values(values), "units": units}


def answer_rows(file: str = "responses.csv") -> list[dict]:
    """The ``answer`` column per section type and question (ANSWER_QUESTIONS), and of attention checks."""
    rows = []
    for section_type, questions in ANSWER_QUESTIONS.items():
        for question, kind in questions.items():
            if kind in INTEGER_RANGES:
                lo, hi = INTEGER_RANGES[kind]
                levels = next((lv for key, (_, lv) in LIKERT_LEVELS.items() if key == question), None)
                units = f"integer scale {lo}..{hi}" + (f" ({lo}: {levels[0]}; {hi}: {levels[-1]})" if levels else "")
                rows.append(_row(file, "answer", f"{section_type}: rating '{question}'", "integer",
                                 answer_values(kind), units, f"section_type={section_type}; question={question}"))
            else:
                multi = kind in MULTI_SELECT_KINDS
                rows.append(_row(file, "answer", f"{section_type}: '{question}'" +
                                 (" (one or more labels, ';'-separated, in this order)" if multi else ""),
                                 "list of labels" if multi else "label", answer_values(kind), "",
                                 f"section_type={section_type}; question={question}"))
    rows.append(_row(file, "answer", "attention check: passed when it equals the part of 'question' after '='",
                     "string", "", "", f"section_type={ATTENTION_CHECK}"))
    return rows


def column_entry(file: str, column: str) -> tuple:
    """(meaning, type, allowed values, units) of one column; DictionaryError when there is none."""
    own = FILE_DOCS.get(file, ("", {}))[1]
    if column in own:
        return own[column]
    if column in _SHARED:
        return _SHARED[column]
    raise DictionaryError(f"{file}: column {column!r} has no entry in the data dictionary (protocol/dictionary.py)")


def dictionary_rows(files: Mapping[str, Sequence[str]], feedback: Sequence[Mapping] = ()) -> list[dict]:
    """Rows of data_dictionary.csv for the exported ``files`` (name -> header). Feedback columns of
    participants.csv are described by ``feedback`` (the study's questions: key, text, kind); any other column
    without an entry raises DictionaryError."""
    by_key = {str(q.get("key")): q for q in feedback}
    rows = []
    for file, header in files.items():
        what = FILE_DOCS.get(file, ("", {}))[0]
        rows.append(_row(file, "", what, "file"))
        for column in header:
            if file == "participants.csv" and column in by_key:
                q = by_key[column]
                kind = q.get("kind", "text")
                rows.append(_row(file, column, f"Feedback question: {q.get('text', column)}", "string",
                                 ("yes", "no") if kind == "yesno" else "", ""))
                continue
            meaning, kind, values, units = column_entry(file, column)
            rows.append(_row(file, column, meaning, kind, values, units))
            if file == "responses.csv" and column == "answer":
                rows += answer_rows(file)
    return rows


def dataset_description(name: str, description: str, authors: Sequence[str], rows: Sequence[Mapping],
                        date_created: str = "", keywords: Sequence[str] = ()) -> dict:
    """A Psych-DS ``dataset_description.json`` (schema.org Dataset): name, description, authors, an empty
    ``license`` for the researcher to fill in, and one ``variableMeasured`` entry per distinct column of
    ``rows`` (dictionary_rows) with its meaning, type, allowed values and units."""
    variables: dict[str, dict] = {}
    for row in rows:
        column = row["column"]
        if not column or row["applies_to"] or column in variables:
            continue
        entry = {"@type": "PropertyValue", "name": column, "description": row["meaning"]}
        if row["units"]:
            entry["unitText"] = row["units"]
        if row["allowed_values"]:
            entry["value"] = row["allowed_values"]
        variables[column] = entry
    out = {"@context": "https://schema.org/", "@type": "Dataset", "name": name,
           "description": description or name,
           "author": [{"@type": "Person", "name": a} for a in authors],
           "license": "", "variableMeasured": list(variables.values())}
    if date_created:
        out["dateCreated"] = date_created
    if keywords:
        out["keywords"] = list(keywords)
    return out
