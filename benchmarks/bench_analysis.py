"""Benchmark: time to produce the whole report for N simulated (SYNTHETIC) participants.

    python -m benchmarks.bench_analysis --participants 10000

Writes the synthetic study to a temporary folder (not timed), then times, in this process after imports:
load + validate the three CSVs, every analysis, figures (PNG + SVG), and the whole ``write_report`` call
(which repeats all of it and also writes CSVs, JSON and HTML). Prints a Markdown table.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--participants", type=int, default=10000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=1, help="timed write_report runs (the minimum is reported)")
    a = ap.parse_args(argv)

    t0 = time.perf_counter()
    from analysis import report
    from analysis.io import load_study
    from analysis.simulate import write_study

    t_import = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        paths = write_study(os.path.join(tmp, "in"), a.participants, a.seed)
        t_sim = time.perf_counter() - t
        size_mb = os.path.getsize(paths["responses"]) / 2**20
        args = (paths["responses"], paths["clips"], paths["participants"])

        t = time.perf_counter()
        data = load_study(*args)
        t_load = time.perf_counter() - t
        t = time.perf_counter()
        _, tables, extras = report.build_report(data)
        t_analyse = time.perf_counter() - t
        t = time.perf_counter()
        figs = report.make_figures(tables, extras)
        for name, fig in figs.items():
            if fig is not None:
                report.figure_mod.save_figure(fig, tmp, name)
        t_fig = time.perf_counter() - t

        totals = []
        for i in range(a.repeat):
            t = time.perf_counter()
            report.write_report(*args, os.path.join(tmp, f"out{i}"))
            totals.append(time.perf_counter() - t)
        html_kb = os.path.getsize(os.path.join(tmp, "out0", "report.html")) / 1024

    n_rows = len(data.responses)
    print("| participants | answers (rows) | responses.csv | import | simulate+write (untimed) | load+validate | "
          "analyses | figures | whole write_report | report.html |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    print(f"| {a.participants:,} | {n_rows:,} | {size_mb:.0f} MiB | {t_import:.1f} s | {t_sim:.1f} s | {t_load:.1f} s |"
          f" {t_analyse:.1f} s | {t_fig:.1f} s | {min(totals):.1f} s | {html_kb:.0f} KiB |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
