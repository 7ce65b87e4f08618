"""SELECTs of the participant pages compiled to SQL once per process instead of on every request (issue 16).

Django compiles a queryset to SQL each time it runs it; for the two reads of every clip page and answer (the
participant with its study, its next unanswered assignments with section and clip) that compilation was about half
of the request's ORM CPU time (docs/benchmarks/study.md). A `PrecompiledSelect` builds its queryset once with
sentinel arguments, keeps the SQL, and on each call only swaps the sentinels in the parameter list for the real
values, then turns the rows into model instances the way QuerySet iteration does (the same converters,
select_related objects included). The SQL sent is exactly the queryset's, so query counts and plans are unchanged.

Limits: the arguments may only appear as query parameters (filter values), never in the SQL text (LIMIT, field
names): build one PrecompiledSelect per shape, e.g. per slice size.
"""
from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

from django.db import connections
from django.db.models import QuerySet
from django.db.models.query import get_related_populators


@dataclass(frozen=True)
class _Compiled:
    sql: str
    params: tuple
    slots: tuple[int, ...]          # index in params of each argument
    compiler: object                # the SQLCompiler that compiled sql (its klass_info)
    converters: dict
    init_list: list[str]
    fields_start: int
    fields_end: int
    populators: list


class PrecompiledSelect:
    """A model SELECT compiled once per database connection alias.

    build(*args) -> QuerySet of model instances (filter/select_related/only/order_by/slice); sentinels: one
    placeholder value per argument, of the argument's type and not equal to any other parameter of the query.
    Calling the object with real arguments returns the list of instances the queryset would return."""

    def __init__(self, build: Callable[..., QuerySet], *sentinels):
        if not sentinels:
            raise ValueError("PrecompiledSelect needs one sentinel per argument of build")
        self._build = build
        self._sentinels = sentinels
        self._compiled: dict[str, _Compiled] = {}
        self._lock = threading.Lock()

    def _compile(self, alias: str) -> _Compiled:
        queryset = self._build(*self._sentinels)
        compiler = queryset.query.get_compiler(using=alias)
        sql, params = compiler.as_sql()
        params = tuple(params)
        slots = []
        for sentinel in self._sentinels:
            hits = [i for i, p in enumerate(params) if type(p) is type(sentinel) and p == sentinel]
            if len(hits) != 1:
                raise ValueError(f"sentinel {sentinel!r} appears {len(hits)} times in the parameters of {sql!r}: "
                                 "each argument must be exactly one query parameter")
            slots.append(hits[0])
        select, klass_info = compiler.select, compiler.klass_info
        start, end = klass_info["select_fields"][0], klass_info["select_fields"][-1] + 1
        return _Compiled(
            sql=sql, params=params, slots=tuple(slots), compiler=compiler,
            converters=compiler.get_converters([s[0] for s in select[:compiler.col_count]]),
            init_list=[f[0].target.attname for f in select[start:end]], fields_start=start, fields_end=end,
            populators=get_related_populators(klass_info, select, alias))

    def __call__(self, *args, using: str = "default") -> list:
        if len(args) != len(self._sentinels):
            raise TypeError(f"expected {len(self._sentinels)} arguments, got {len(args)}")
        compiled = self._compiled.get(using)
        if compiled is None:
            with self._lock:
                compiled = self._compiled.get(using) or self._compile(using)
                self._compiled[using] = compiled
        params = list(compiled.params)
        for slot, value in zip(compiled.slots, args):
            params[slot] = value
        connection = connections[using]          # this thread's (the compiler's may be another thread's)
        with connection.cursor() as cursor:
            cursor.execute(compiled.sql, params)
            rows = cursor.fetchall()
        if compiled.converters:
            rows = [_converted(row, compiled.converters, connection) for row in rows]
        model = compiled.compiler.klass_info["model"]
        objects = []
        for row in rows:
            obj = model.from_db(using, compiled.init_list, row[compiled.fields_start:compiled.fields_end])
            for populator in compiled.populators:
                populator.populate(row, obj)
            objects.append(obj)
        return objects


def _converted(row, converters: dict, connection) -> list:
    """A row with the field and backend converters applied (as SQLCompiler.apply_converters does)."""
    row = list(row)
    for pos, (convs, expression) in converters.items():
        value = row[pos]
        for converter in convs:
            value = converter(value, expression, connection)
        row[pos] = value
    return row
