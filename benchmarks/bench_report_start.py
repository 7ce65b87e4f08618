"""How long ``studyapp.staff.reports.start_build`` takes to return (the staff page's "build the report" click), while
the detached ``manage.py build_report`` it spawns runs on.

A scratch SQLite database in a temporary DATA_DIR (synthetic catalogue, the demo study with a few finished
synthetic participants); each round starts a build of a new data version (one more answer each time), records the
wall time of ``start_build`` and waits for the build to end before the next round.

    python -m benchmarks.bench_report_start [--rounds 5] [--json FILE]
"""
from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--json", default="", help="also write the result to this JSON file")
    args = ap.parse_args(argv)
    data = Path(tempfile.mkdtemp(prefix="report-start-bench-"))
    os.environ.update(DATA_DIR=str(data), REPORTS_DIR=str(data / "reports"))
    os.environ.pop("DATABASE_URL", None)
    from benchmarks import bench_study_load as load
    from benchmarks.bench_record import record

    study = load.setup_django(f"sqlite:///{data / 'db.sqlite3'}", data / "media")
    from studyapp.staff import reports

    start_ms, build_s = [], []
    for i in range(args.rounds):
        load.take_study(load.DjangoClientHttp(), "http://testserver", study.slug, 700_000 + i, time.time() + 300)
        t = time.perf_counter()
        state = reports.start_build(study)
        start_ms.append(1000 * (time.perf_counter() - t))
        while reports.report_state(study, state.version).status == "running":
            time.sleep(0.2)
        build_s.append(time.perf_counter() - t)
    result = {"benchmark": "bench_report_start", "rounds": args.rounds,
              "start_build_ms": {"median": round(statistics.median(start_ms), 1), "max": round(max(start_ms), 1)},
              "whole_build_s_median": round(statistics.median(build_s), 1)}
    return record(result, args.json)


if __name__ == "__main__":
    main()
