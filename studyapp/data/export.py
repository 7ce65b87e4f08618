"""Export a study's data in the public DESIGN.md formats: responses.csv, clips.csv, participants.csv (columns:
protocol.vocabulary), plus assignments.csv (what each participant was shown, for audits).

Rows are produced by generators over `.iterator()` queries, so a large study streams in constant memory (an
HTTP StreamingHttpResponse or a file on disk); no export builds the whole file as one string.
Preview runs record nothing, so every participant row is a real participant; pilot participants (Study.pilot) are
marked by their id (``pilot-...``) in every file, and left out of the analysis report unless the study says.
viewing.csv (VIEWING_COLUMNS) has one row per answered clip page: how the clip was watched
(studyapp.participant.viewing), blank fields where the browser sent no record.

Spreadsheet formula injection: participants type some of these cells (external_id, feedback). Every text cell
that starts with =, +, -, @, a tab or a carriage return is written with a leading single quote (') so Excel,
LibreOffice and Google Sheets show it as text instead of running it; plain numbers (e.g. an inversion rating of
-7 or a response time) are written unchanged. docs/study.md tells researchers.

Privacy (studyapp.data.privacy): participants.csv's ``external_id`` is a pseudonym (the same for one participant in
every export of the study) unless the study asks for the ids themselves (``Study.export_external_ids``); the ids
for payment are a separate download. Withdrawn participants are left out of every file (their rows, answers,
assignments and viewing records); deleted ones are gone from the database.

Practice items and attention checks (studyapp.participant.trial_extras): practice answers are never stored, and practice
items are left out of assignments.csv. Attention checks are rows of responses.csv and assignments.csv with
section_type ``attention_check`` (protocol.vocabulary.ATTENTION_CHECK) and question ``<key>=<instructed answer>``;
participants.csv counts them per participant (``attention_passed``, ``attention_total``). Its ``section_order``
column lists the ``order`` numbers (Section.order, as in assignments.csv's section_order) of the sections in the
order the participant took them, joined by ';' (empty for a participant who has not started).

pages.csv (PAGE_COLUMNS) has one row per instruction or break page a participant was given
(studyapp.data.section_pages): when it was first shown, when the participant continued and the seconds between (blank:
not yet).
"""
from __future__ import annotations

import csv
import json
import re
import unicodedata
from collections.abc import Iterable, Iterator
from pathlib import Path

from django.db.models import Case, F, Q, When

from protocol.dictionary import DICTIONARY_COLUMNS, dataset_description, dictionary_rows
from protocol.pools import NORMS_RULE
from protocol.vocabulary import (
    ASSIGNMENT_COLUMNS,
    ATTENTION_CHECK,
    CLIP_BODY_COLUMNS,
    CLIP_COLUMNS,
    CLIP_PROVENANCE_COLUMNS,
    PAGE_COLUMNS,
    PARTICIPANT_COLUMNS,
    RESPONSE_COLUMNS,
    VIEWING_COLUMNS,
    VIEWING_FIELDS,
    VIEWING_SERVER_FIELDS,
    attention_passed,
)

from ..models import Assignment, Clip, Participant, Response, Study
from .pool_filters import filtered_clips
from .privacy import pseudonym
from .section_pages import when

WITHDRAWN = Participant.Status.WITHDRAWN

__all__ = ["ASSIGNMENT_COLUMNS", "CLIP_COLUMNS", "EXPORT_CLIP_COLUMNS", "EXPORT_KINDS", "PAGE_COLUMNS",
           "PARTICIPANT_COLUMNS", "RESPONSE_COLUMNS", "VIEWING_COLUMNS", "run_report", "stream_csv", "write_study_csvs"]

EXPORT_KINDS = ("responses", "clips", "participants", "assignments", "viewing", "pages")
"""The CSV exports, each written as ``<kind>.csv``."""

CHUNK = 2000


class _Echo:
    """A write-only file object: csv.writer writes a row, we hand the string on."""

    def write(self, value: str) -> str:
        return value


FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")
PLAIN_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?", re.ASCII)


def safe_cell(value):
    """A CSV cell a spreadsheet will not run as a formula: text whose NFKC form starts with one of FORMULA_STARTS
    (so also the full-width ＝ ＋ － ＠, which spreadsheets read as = + - @) gets a leading single quote; numbers
    and text that is a plain ASCII number ("-7", "-0.25") are left as they are."""
    if value is None:
        return ""
    if (isinstance(value, str) and unicodedata.normalize("NFKC", value).startswith(FORMULA_STARTS)
            and not PLAIN_NUMBER.fullmatch(value)):
        return "'" + value
    return value


def csv_lines(header: Iterable[str], rows: Iterable[list]) -> Iterator[str]:
    writer = csv.writer(_Echo(), lineterminator="\n")
    yield writer.writerow([safe_cell(h) for h in header])
    for row in rows:
        yield writer.writerow([safe_cell(v) for v in row])


def _iso(dt) -> str:
    return dt.isoformat() if dt else ""


def _exported_type():
    """The section_type cell: the row's kind (attention check) when it has one, else its section's type."""
    return Case(When(kind="", then=F("section__section_type")), default=F("kind"))


def _without_pilots(qs, include_pilot: bool, lookup: str = "participant__pilot"):
    """``qs`` without the pilot participants' rows unless ``include_pilot``."""
    return qs if include_pilot else qs.filter(**{lookup: False})


def response_rows(study: Study, include_pilot: bool = True) -> Iterator[list]:
    qs = (_without_pilots(Response.objects.filter(section__study=study), include_pilot)
          .exclude(participant__status=WITHDRAWN)
          .annotate(exported_type=_exported_type())
          .order_by("participant_id", "section__order", "id")
          .values_list("participant__public_id", "exported_type", "clip__clip_id", "question", "answer",
                       "response_ms"))
    for row in qs.iterator(chunk_size=CHUNK):
        yield list(row)


def study_clips(study: Study):
    """Clips assigned in the study plus those in its sections' pools (a pool's norms rule left out: the export never
    depends on another study's answers or a norms file, and a study normed from itself cannot recurse)."""
    q = Q(assignments__section__study=study)
    for section in study.sections.all():
        if section.pool:
            pool = {k: v for k, v in section.pool.items() if k != NORMS_RULE} if isinstance(section.pool, dict) \
                else section.pool
            q |= Q(pk__in=filtered_clips(pool).values("pk"))
    return Clip.objects.filter(q).distinct().order_by("clip_id")


#: The study's clips.csv: the public columns, then the clip's readable title (protocol.titles) and the licence and
#: citation of what it was made from (blank where the catalogue has none), which travel with the clips into every
#: report and reuse.
EXPORT_CLIP_COLUMNS = (*CLIP_COLUMNS, *CLIP_PROVENANCE_COLUMNS, *CLIP_BODY_COLUMNS)


def clip_rows(study: Study) -> Iterator[list]:
    for clip in study_clips(study).iterator(chunk_size=CHUNK):
        yield [getattr(clip, c) for c in EXPORT_CLIP_COLUMNS]


def feedback_keys(study: Study) -> list[str]:
    return [str(q["key"]) for q in study.feedback_questions or []]


def attention_counts(study: Study) -> dict[int, tuple[int, int]]:
    """Participant pk -> (attention checks passed, answered), from the study's attention-check responses."""
    counts: dict[int, tuple[int, int]] = {}
    rows = (Response.objects.filter(section__study=study, kind=ATTENTION_CHECK)
            .exclude(participant__status=WITHDRAWN).values_list("participant_id", "question", "answer"))
    for pk, question, answer in rows.iterator(chunk_size=CHUNK):
        passed, total = counts.get(pk, (0, 0))
        counts[pk] = (passed + attention_passed(question, answer), total + 1)
    return counts


def participant_rows(study: Study, include_pilot: bool = True) -> Iterator[list]:
    keys = feedback_keys(study)
    attention = attention_counts(study)
    orders = dict(study.sections.values_list("pk", "order"))
    people = _without_pilots(study.participants.exclude(status=WITHDRAWN), include_pilot, "pilot")
    for p in people.order_by("id").iterator(chunk_size=CHUNK):
        passed, total = attention.get(p.pk, (0, 0))
        order = ";".join(str(orders[pk]) for pk in p.section_order or [] if pk in orders)
        external = p.external_id if study.export_external_ids else pseudonym(study.pk, p.external_id)
        yield [p.public_id, p.gender, p.age_group, _iso(p.started_at), _iso(p.completed_at), p.status,
               external, passed, total, order] + [p.feedback.get(k, "") for k in keys]


def assignment_rows(study: Study, include_pilot: bool = True) -> Iterator[list]:
    qs = (_without_pilots(Assignment.objects.filter(section__study=study), include_pilot)
          .exclude(kind=Assignment.Kind.PRACTICE).exclude(participant__status=WITHDRAWN)
          .annotate(exported_type=_exported_type())
          .order_by("participant_id", "seq")
          .values_list("participant__public_id", "exported_type", "section__order", "position",
                       "clip__clip_id", "options", "shown_at", "answered_at"))
    for pid, stype, order, pos, clip_id, options, shown, answered in qs.iterator(chunk_size=CHUNK):
        yield [pid, stype, order, pos, clip_id, ";".join(options or []), _iso(shown), _iso(answered)]


def viewing_rows(study: Study, include_pilot: bool = True) -> Iterator[list]:
    """One row per answered clip page (practice items left out): participant, clip, section type, then
    VIEWING_FIELDS (blank where unknown or when the browser sent none) and VIEWING_SERVER_FIELDS (blank for an
    answer stored before the server kept them)."""
    qs = (_without_pilots(Assignment.objects.filter(section__study=study, answered_at__isnull=False), include_pilot)
          .exclude(kind=Assignment.Kind.PRACTICE).exclude(participant__status=WITHDRAWN)
          .annotate(exported_type=_exported_type())
          .order_by("participant_id", "seq")
          .values_list("participant__public_id", "clip__clip_id", "exported_type", "viewing"))
    for pid, clip_id, stype, viewing in qs.iterator(chunk_size=CHUNK):
        record = viewing if isinstance(viewing, dict) else {}
        yield [pid, clip_id, stype, *(record.get(f) for f in VIEWING_FIELDS),
               *(record.get(f) for f in VIEWING_SERVER_FIELDS)]


def page_rows(study: Study, include_pilot: bool = True) -> Iterator[list]:
    """One row per instruction or break page of each participant (Participant.pages, in the order taken): id, page
    number, section type and order, first display, Continue and the seconds between (blank where not yet)."""
    sections = {pk: (stype, order) for pk, stype, order in study.sections.values_list("pk", "section_type", "order")}
    people = _without_pilots(study.participants.exclude(status=WITHDRAWN), include_pilot, "pilot")
    for pid, pages in people.order_by("id").values_list("public_id", "pages").iterator(chunk_size=CHUNK):
        for n, record in enumerate(pages or [], start=1):
            stype, order = sections.get(record.get("section"), ("", ""))
            shown, continued = when(record.get("shown_at")), when(record.get("continued_at"))
            seconds = round((continued - shown).total_seconds(), 3) if shown and continued else ""
            yield [pid, n, stype, order, _iso(shown), _iso(continued), seconds]


def stream_csv(study: Study, kind: str, include_pilot: bool = True) -> Iterator[str]:
    """Lines of `kind` in EXPORT_KINDS; ``include_pilot=False`` leaves the pilot participants out."""
    if kind == "responses":
        return csv_lines(RESPONSE_COLUMNS, response_rows(study, include_pilot))
    if kind == "clips":
        return csv_lines(EXPORT_CLIP_COLUMNS, clip_rows(study))
    if kind == "participants":
        return csv_lines([*PARTICIPANT_COLUMNS, *feedback_keys(study)], participant_rows(study, include_pilot))
    if kind == "assignments":
        return csv_lines(ASSIGNMENT_COLUMNS, assignment_rows(study, include_pilot))
    if kind == "viewing":
        return csv_lines(VIEWING_COLUMNS, viewing_rows(study, include_pilot))
    if kind == "pages":
        return csv_lines(PAGE_COLUMNS, page_rows(study, include_pilot))
    raise ValueError(f"unknown export {kind!r}; choose {', '.join(EXPORT_KINDS)}")


def write_study_csvs(study: Study, out_dir: str | Path, include_pilot: bool = True) -> dict[str, Path]:
    """Write responses.csv, clips.csv, participants.csv (DESIGN.md), assignments.csv, viewing.csv and pages.csv
    into out_dir (the pilot participants left out unless ``include_pilot``); returns their paths by kind."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {}
    for kind in EXPORT_KINDS:
        path = out / f"{kind}.csv"
        with open(path, "w", newline="", encoding="utf-8") as fh:
            for line in stream_csv(study, kind, include_pilot):
                fh.write(line)
        paths[kind] = path
    return paths


DICTIONARY_NAME = "data_dictionary.csv"
DESCRIPTION_NAME = "dataset_description.json"


def _header(path: Path) -> list[str]:
    with open(path, newline="", encoding="utf-8") as fh:
        return next(csv.reader(fh), [])


def write_data_package(study: Study, out_dir: str | Path, include_pilot: bool = True) -> dict[str, Path]:
    """write_study_csvs, then the data dictionary of exactly the headers written (protocol.dictionary: every file,
    every column, ``answer`` per section type and question) and a Psych-DS dataset_description.json (authors: the
    study's owners; the licence left for the researcher). Returns every path by kind ("dictionary",
    "description" for the two)."""
    out = Path(out_dir)
    paths = write_study_csvs(study, out, include_pilot)
    rows = dictionary_rows({p.name: _header(p) for p in paths.values()}, study.feedback_questions or [])
    with open(out / DICTIONARY_NAME, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=DICTIONARY_COLUMNS, lineterminator="\n")
        writer.writeheader()
        writer.writerows({k: safe_cell(v) for k, v in row.items()} for row in rows)
    authors = [u.get_full_name() or u.get_username() for u in study.owners.order_by("username")]
    description = dataset_description(
        study.title, (study.introduction or "").strip() or f"Perceptual study {study.slug}", authors, rows,
        study.created_at.date().isoformat() if study.created_at else "",
        keywords=["perception", "virtual agents", "emotion", *([study.preset] if study.preset else [])])
    (out / DESCRIPTION_NAME).write_text(json.dumps(description, indent=2, ensure_ascii=False) + "\n",
                                        encoding="utf-8")
    return {**paths, "dictionary": out / DICTIONARY_NAME, "description": out / DESCRIPTION_NAME}


def run_report(study: Study, out_dir: str | Path) -> dict:
    """Export the CSVs (pilot participants only when ``Study.report_includes_pilot``) and call the analysis
    library's report writer (analysis.report.write_report, viewing.csv included) with the study's
    exclusion rules (``Study.exclusion_rules``; empty = the analysis defaults), which the report states. Invalid rules
    raise ValueError naming the key (the admin form checks them with analysis.exclusion.rule_errors)."""
    out = Path(out_dir)
    paths = write_data_package(study, out / "data", include_pilot=study.report_includes_pilot)
    from analysis.report import write_report  # imported lazily: the analysis library is optional at runtime

    return write_report(paths["responses"], paths["clips"], paths["participants"], out,
                        exclusion_rules=study.exclusion_rules or None, viewing_csv=paths["viewing"])
