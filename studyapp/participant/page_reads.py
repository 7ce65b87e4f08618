"""The two reads of every participant page as plain SQL: the participant by token with its study, and the next
unanswered assignments with their section and clip.

Django compiles a queryset to SQL on every run, and for these two reads (about 85 columns each, on every clip page
and answer) that compilation cost about a quarter of the answer's CPU (docs/benchmarks/study.md, "Reads in plain
SQL"). Here the SQL text is written once per process from the models' field lists, run through
``connection.cursor()``, and the rows become model instances through ``Model.from_db`` (the public constructor
QuerySet iteration uses), with related objects set through their foreign-key attributes. Only documented model
APIs are used (``_meta.concrete_fields``, ``Field.column``/``attname``, ``JSONField.from_db_value``), so a Django
upgrade cannot change what these functions return without tests/studyapp/participant/test_page_reads.py noticing.

Values come back as the ORM gives them on PostgreSQL and SQLite: JSON decoded, booleans as bool, datetimes aware
(SQLite returns text and integers for those, PostgreSQL native types).
"""
from __future__ import annotations

import functools
from collections.abc import Callable
from datetime import UTC

from django.conf import settings
from django.db import connections, models
from django.utils import timezone
from django.utils.dateparse import parse_datetime

from ..models import Assignment, Clip, Participant, Section, Study

ASSIGNMENT_FIELDS = ("id", "participant_id", "section_id", "position", "clip_id", "options", "shown_at",
                     "answered_at", "seq", "kind", "instructed", "plays", "play_ended_ms", "shows",
                     "carried", "fetched_at")
"""What a clip page reads of an assignment (its other fields stay deferred)."""
CLIP_FIELDS = ("id", "clip_id", "theme", "duration_s", "media_key", "video", "webm", "poster", "loop")
"""What a clip page reads of a clip (the rest stays deferred)."""


def _q(name: str) -> str:
    return f'"{name}"'


def _fields(model, names=None) -> list[models.Field]:
    fields = list(model._meta.concrete_fields)
    return fields if names is None else [f for f in fields if f.attname in names]


def _columns(table_alias: str, fields: list[models.Field]) -> str:
    return ", ".join(f"{table_alias}.{_q(f.column)}" for f in fields)


def _datetime(value, connection):
    if isinstance(value, str):
        value = parse_datetime(value)
    if value is not None and settings.USE_TZ and timezone.is_naive(value):
        value = timezone.make_aware(value, UTC)
    return value


def _converter(field: models.Field, connection) -> Callable | None:
    """How a column's database value becomes the model value (None: unchanged)."""
    if isinstance(field, models.JSONField):
        return lambda v, c: field.from_db_value(v, None, c)
    if isinstance(field, models.DateTimeField):
        return _datetime
    if isinstance(field, models.BooleanField):
        return lambda v, c: v if v is None else bool(v)
    return None


class _Part:
    """One model's columns in a row: its fields, their slice of the row and their converters."""

    def __init__(self, model, fields: list[models.Field], start: int, connection):
        self.model = model
        self.names = [f.attname for f in fields]
        self.start, self.end = start, start + len(fields)
        self.converters = [(i, conv) for i, f in enumerate(fields) if (conv := _converter(f, connection))]

    def build(self, row, alias: str, connection):
        values = list(row[self.start:self.end])
        for i, conv in self.converters:
            values[i] = conv(values[i], connection)
        return self.model.from_db(alias, self.names, values)


@functools.cache
def _participant_read(alias: str) -> tuple[str, _Part, _Part]:
    connection = connections[alias]
    pf, sf = _fields(Participant), _fields(Study)
    sql = (f"SELECT {_columns('p', pf)}, {_columns('s', sf)} FROM {_q(Participant._meta.db_table)} p "
           f"INNER JOIN {_q(Study._meta.db_table)} s ON s.{_q('id')} = p.{_q('study_id')} "
           f"WHERE p.{_q('token')} = %s")
    return sql, _Part(Participant, pf, 0, connection), _Part(Study, sf, len(pf), connection)


@functools.cache
def _assignments_read(alias: str) -> tuple[str, _Part, _Part, _Part]:
    connection = connections[alias]
    af, sf, cf = _fields(Assignment, ASSIGNMENT_FIELDS), _fields(Section), _fields(Clip, CLIP_FIELDS)
    sql = (f"SELECT {_columns('a', af)}, {_columns('s', sf)}, {_columns('c', cf)} "
           f"FROM {_q(Assignment._meta.db_table)} a "
           f"INNER JOIN {_q(Section._meta.db_table)} s ON s.{_q('id')} = a.{_q('section_id')} "
           f"INNER JOIN {_q(Clip._meta.db_table)} c ON c.{_q('id')} = a.{_q('clip_id')} "
           f"WHERE a.{_q('participant_id')} = %s AND a.{_q('answered_at')} IS NULL "
           f"ORDER BY a.{_q('seq')} ASC LIMIT %s")
    return (sql, _Part(Assignment, af, 0, connection), _Part(Section, sf, len(af), connection),
            _Part(Clip, cf, len(af) + len(sf), connection))


def participant_by_token(token: str, using: str = "default") -> Participant | None:
    """The participant with this URL token and its study (``participant.study`` loaded), or None: one query."""
    sql, participant, study = _participant_read(using)
    connection = connections[using]
    with connection.cursor() as cursor:
        cursor.execute(sql, [token])
        row = cursor.fetchone()
    if row is None:
        return None
    obj = participant.build(row, using, connection)
    obj.study = study.build(row, using, connection)
    return obj


def open_assignments(participant_id: int, n: int, using: str = "default") -> list[Assignment]:
    """The participant's first ``n`` (>= 1) unanswered assignments by seq, each with ``section`` and ``clip``
    loaded (the clip's :data:`CLIP_FIELDS` only): one query, on the partial index of unanswered assignments."""
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    sql, assignment, section, clip = _assignments_read(using)
    connection = connections[using]
    with connection.cursor() as cursor:
        cursor.execute(sql, [participant_id, n])
        rows = cursor.fetchall()
    out = []
    for row in rows:
        obj = assignment.build(row, using, connection)
        obj.section = section.build(row, using, connection)
        obj.clip = clip.build(row, using, connection)
        out.append(obj)
    return out
