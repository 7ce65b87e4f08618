"""What the participant pages' two reads in plain SQL (studyapp.participant.page_reads) save on the answer path's CPU.

Same set-up as ``bench_study_load.py --in-process-only`` (scratch PostgreSQL database or SQLite, synthetic catalogue,
demo study, Django test client, url-encoded POSTs): participants are taken through the study in-process, and each
request's thread CPU time is recorded by kind. The modes alternate in one process, ``--rounds`` times each:

- ``plain_sql``: the shipped code (participant by token with its study, and the next unanswered assignments with
  section and clip, as SQL written once per process, run through ``connection.cursor()``);
- ``queryset``: the same two reads as ORM querysets, compiled to SQL on every request.

Prints and (``--json``) writes the median over rounds of each mode's per-round median CPU ms for the answer POST
(which brings the next clip page) and the clip page GET, and the saving of each mode against ``queryset``.

    python -m benchmarks.bench_page_reads [--db-url postgres://postgres@127.0.0.1:5432/postgres | --sqlite]
        [--participants 6] [--rounds 5] [--json docs/benchmarks/page_reads.json]
"""
from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

from benchmarks import bench_study_load as load
from benchmarks.bench_record import record

KINDS = ("answer POST", "clip page")      # take_study's names of the answer POST and the clip page GET


def queryset_reads() -> tuple:
    """(participant_by_token, open_assignments) as ORM querysets, compiled to SQL on each call."""
    from studyapp.models import Assignment, Participant
    from studyapp.participant.page_reads import ASSIGNMENT_FIELDS, CLIP_FIELDS

    only = (*ASSIGNMENT_FIELDS, "section", "clip", *(f"clip__{f}" for f in CLIP_FIELDS))

    def participant_by_token(token):
        return Participant.objects.select_related("study").filter(token=token).first()

    def open_assignments(pk, n):
        return list(Assignment.objects.filter(participant_id=pk, answered_at__isnull=True)
                    .select_related("section", "clip").only(*only).order_by("seq")[:n])

    return participant_by_token, open_assignments


def shipped_reads() -> tuple:
    from studyapp.participant.page_reads import open_assignments, participant_by_token

    return participant_by_token, open_assignments


MODES = {"plain_sql": shipped_reads, "queryset": queryset_reads}
"""Mode name -> function returning its (participant_by_token, open_assignments)."""


def use(reads: tuple) -> None:
    """Make the study app's views and assignment code call these two reads."""
    from studyapp.participant import assignment, views

    views.participant_by_token, assignment.open_assignments = reads


def measure(slug: str, participants: int, rounds: int, modes=MODES) -> dict:
    """{mode: {kind: [per-round median CPU ms]}}, the modes alternating round by round."""
    reads = {mode: build() for mode, build in modes.items()}
    load.take_study(load.DjangoClientHttp(), "http://testserver", slug, 799_999, time.time() + 300)   # warm-up
    out = {mode: {k: [] for k in KINDS} for mode in reads}
    index = 800_000
    try:
        for _ in range(rounds):
            for mode in out:
                use(reads[mode])
                http = load.DjangoClientHttp()
                for _ in range(participants):
                    load.take_study(http, "http://testserver", slug, index, time.time() + 300)
                    index += 1
                for kind in KINDS:
                    out[mode][kind].append(statistics.median(c[2] for c in http.costs[kind]))
    finally:
        use(shipped_reads())
    return out


def summary(runs: dict) -> dict:
    """Median over rounds per mode and kind, and each mode's CPU saving against ``queryset`` in percent."""
    med = {mode: {k: round(statistics.median(v), 3) for k, v in kinds.items()} for mode, kinds in runs.items()}
    saving = {mode: {k: round(100 * (1 - med[mode][k] / med["queryset"][k]), 1) for k in KINDS}
              for mode in med if mode != "queryset"}
    return {"cpu_ms_median": med, "saving_vs_queryset_percent": saving,
            "rounds_cpu_ms": {m: {k: [round(x, 3) for x in v] for k, v in kinds.items()} for m, kinds in runs.items()}}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db-url", default=os.environ.get("DATABASE_URL") or "postgres://postgres@127.0.0.1:5432/postgres")
    ap.add_argument("--sqlite", action="store_true", help="a scratch SQLite file instead of PostgreSQL")
    ap.add_argument("--participants", type=int, default=6, help="participants per mode and round")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--json", default="", help="also write the result to this JSON file")
    args = ap.parse_args(argv)
    out = Path(tempfile.mkdtemp(prefix="page-reads-bench-"))
    name = None
    if args.sqlite:
        db_url = f"sqlite:///{out / 'db.sqlite3'}"
    else:
        db_url, name = load.scratch_db_url(args.db_url)
        load.recreate_db(args.db_url, name)
    try:
        study = load.setup_django(db_url, out / "media")
        runs = measure(study.slug, args.participants, args.rounds)
    finally:
        if name:
            load.drop_db(args.db_url, name)
    return record({"benchmark": "bench_page_reads", "database": "sqlite" if args.sqlite else "postgresql",
                   "participants_per_round": args.participants, "rounds": args.rounds, **summary(runs)}, args.json)


if __name__ == "__main__":
    main()
