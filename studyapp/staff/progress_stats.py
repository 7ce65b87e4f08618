"""The progress page's numbers (pilot participants left out; they have their own count): the completion funnel
(consented, started, completed, excluded by each rule of the analysis), the median time per participant and per
section, and the answers per day.

Exclusions need the analysis (pandas) and the whole export: they are read from the study's finished report of
its current data (exclusion_counts.csv in report.zip) instead of being computed in the request; without one the
page says to build it.
"""
from __future__ import annotations

import csv
import io
import statistics
import zipfile
from dataclasses import dataclass, field
from datetime import date, timedelta

from django.db.models import Count, Max, Min
from django.db.models.functions import TruncDate

from ..models import Assignment, Participant, Response, Study
from .reports import ReportState


@dataclass
class Funnel:
    """Participants at each stage, and the exclusions of the current report: ``excluded`` rule -> participants
    (``None``: no report of the current data yet)."""

    consented: int
    started: int
    completed: int
    withdrawn: int
    excluded: dict[str, int] | None = None

    @property
    def steps(self) -> list[tuple[str, int]]:
        """The funnel's rows for the progress page: (label, participants) for consented, started and completed, then one
        "excluded: <rule>" row per exclusion rule of the current report."""
        out = [("consented", self.consented), ("started", self.started), ("completed", self.completed)]
        if self.excluded:
            out += [(f"excluded: {rule.replace('_', ' ')}", n) for rule, n in self.excluded.items()]
        return out


@dataclass
class SectionTime:
    """One section's row of the progress page: the median time a participant spent in it (s; None when nobody finished
    it) over ``n`` timed participants."""

    section_id: int
    label: str
    median_s: float | None
    n: int


@dataclass
class ProgressStats:
    """Everything the progress page charts: the funnel, the median time per participant (s) over ``n_timed``
    participants, the time per section and (date, answers) per day."""

    funnel: Funnel
    median_participant_s: float | None
    n_timed: int
    sections: list[SectionTime] = field(default_factory=list)
    per_day: list[tuple[date, int]] = field(default_factory=list)

    @property
    def max_per_day(self) -> int:
        """The most answers on one day (0 without any), the scale of the per-day chart."""
        return max((n for _, n in self.per_day), default=0)


def report_exclusions(report: ReportState) -> dict[str, int] | None:
    """rule -> participants excluded, from exclusion_counts.csv of a ready report (None when there is none)."""
    if report.status != "ready" or report.zip_path is None:
        return None
    try:
        with zipfile.ZipFile(report.zip_path) as zf:
            name = next((n for n in zf.namelist() if n.rsplit("/", 1)[-1] == "exclusion_counts.csv"), None)
            if name is None:
                return {}
            text = zf.read(name).decode("utf-8")
    except (OSError, zipfile.BadZipFile, KeyError, UnicodeDecodeError):
        return None
    out = {}
    for row in csv.DictReader(io.StringIO(text)):
        try:
            out[row["rule"]] = int(float(row["participants"]))
        except (KeyError, ValueError):
            continue
    return out


def _median(values: list[float]) -> float | None:
    return round(statistics.median(values), 1) if values else None


def progress_stats(study: Study, report: ReportState | None = None, days: int = 60) -> ProgressStats:
    """The numbers of the progress page (queries: participants, assignments per participant and section,
    answers per day); ``days``: how many recent days of answers are listed."""
    people = Participant.objects.filter(study=study, pilot=False)
    statuses = dict(people.values_list("status").annotate(n=Count("id")))
    funnel = Funnel(consented=people.count(), started=people.filter(started_at__isnull=False).count(),
                    completed=statuses.get(Participant.Status.COMPLETED, 0),
                    withdrawn=statuses.get(Participant.Status.WITHDRAWN, 0),
                    excluded=report_exclusions(report) if report is not None else None)
    durations = [(done - start).total_seconds() for start, done in
                 people.filter(status=Participant.Status.COMPLETED, started_at__isnull=False,
                               completed_at__isnull=False).values_list("started_at", "completed_at")]
    spans: dict[int, list[float]] = {}
    rows = (Assignment.objects.filter(section__study=study, participant__pilot=False, answered_at__isnull=False,
                                      shown_at__isnull=False)
            .values("participant_id", "section_id").annotate(first=Min("shown_at"), last=Max("answered_at")))
    for row in rows:
        spans.setdefault(row["section_id"], []).append((row["last"] - row["first"]).total_seconds())
    sections = [SectionTime(s.pk, f"{s.order}. {s.title or s.section_type}", _median(spans.get(s.pk, [])),
                            len(spans.get(s.pk, []))) for s in study.sections.order_by("order", "id")]
    since = date.today() - timedelta(days=days)
    per_day = list(Response.objects.filter(section__study=study, participant__pilot=False,
                                           created_at__date__gte=since)
                   .annotate(day=TruncDate("created_at")).values_list("day").annotate(n=Count("id")).order_by("day"))
    return ProgressStats(funnel, _median(durations), len(durations), sections, per_day)
