"""Benchmark of reading real capture: every dataset-1 walk and ten dataset-2 walks of the Bandai Namco Research
Motion Dataset (real optical capture, CC BY-NC 4.0, Kobayashi et al. 2023, arXiv:2306.08861) imported onto the gait
skeleton, before and after the six-channel fix of the BVH reader.

"Before" reads the file as the old reader did: position channels only on the root, every other joint's translation
frozen at its first frame (this rig carries the body's motion on ``Hips``, below a static ``joint_Root``), height
from the rest pose. "After" is :func:`generation.formats.bvh.parse_bvh` and the importer's checks.
Pelvis bounce: the quality gate's measure (:func:`generation.quality.realism.pelvis_bounce_cm`) of the pelvis
(``Hips``): median over 1 s windows of its detrended height's peak-to-peak, cm.

Usage: python -m benchmarks.bench_real_bvh_import DIR [--out docs/benchmarks/real_bvh_import.json]
(DIR holds the unpacked ``dataset/Bandai-Namco-Research-Motiondataset-{1,2}`` folders). Prints a markdown table.
"""
from __future__ import annotations

import argparse
import dataclasses
import datetime
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

from generation.formats.bvh import parse_bvh
from generation.mocap.importer import ImportOptions, import_file
from generation.quality.realism import pelvis_bounce_cm


def measure(path: Path) -> dict:
    data = parse_bvh(path)
    hips = data.names.index("Hips")
    after = data.global_positions(0.01)
    frozen = data.translations.copy()
    frozen[:, 1:] = frozen[:1, 1:]
    before = dataclasses.replace(data, translations=frozen).global_positions(0.01)
    rest_extent = np.ptp(_rest_positions(data)[:, 1]) * 0.01
    t0 = time.perf_counter()
    row = import_file(path, ImportOptions(skeleton="gait")).row
    return {"file": path.name, "frames": len(after), "status": row["status"], "message": row["message"],
            "height_before_m": round(float(rest_extent), 3), "height_m": float(row["height_m"] or "nan"),
            "import_error_cm": float(row["import_error_cm"] or "nan"),
            "bounce_before_cm": round(pelvis_bounce_cm(before[:, hips:hips + 1], data.fps), 2),
            "bounce_after_cm": round(pelvis_bounce_cm(after[:, hips:hips + 1], data.fps), 2),
            "import_s": round(time.perf_counter() - t0, 2)}


def _rest_positions(data) -> np.ndarray:
    P = np.zeros((len(data.names), 3))
    for j, p in enumerate(data.parents):
        P[j] = data.offsets[j] if p < 0 else P[p] + data.offsets[j]
    return P


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", type=Path)
    ap.add_argument("--out", type=Path, default=Path("docs/benchmarks/real_bvh_import.json"))
    args = ap.parse_args(argv)
    d1 = sorted(args.dir.rglob("dataset-1_walk_*.bvh"))
    d2_all = sorted(args.dir.rglob("dataset-2_walk_*.bvh"))
    styles = sorted({p.stem.split("_")[2] for p in d2_all})
    d2 = [next(p for p in d2_all if p.stem.split("_")[2] == s) for s in styles]
    d2 += [p for p in d2_all if p not in d2][:: max(1, len(d2_all) // 3)][: 10 - len(d2)]
    rows = [measure(p) for p in d1 + d2]
    result = {"date": datetime.date.today().isoformat(), "machine": f"{platform.machine()}, {platform.node()}",
              "rows": rows}
    args.out.write_text(json.dumps(result, indent=1))
    print("| file | frames | status | height before (m) | height (m) | import error (cm) | pelvis bounce before (cm) "
          "| pelvis bounce after (cm) |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['file']} | {r['frames']} | {r['status']} | {r['height_before_m']:.2f} | {r['height_m']:.2f} | "
              f"{r['import_error_cm']:.2f} | {r['bounce_before_cm']:.2f} | {r['bounce_after_cm']:.2f} |")
    ok = [r for r in rows if r["status"] == "ok"]
    print(f"\n{len(ok)} of {len(rows)} ok; import error max {max(r['import_error_cm'] for r in rows):.2f} cm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
