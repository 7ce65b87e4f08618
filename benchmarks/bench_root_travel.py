"""Root travel reconstructed from the stance foot, checked on real walks whose travel is known.

    python -m benchmarks.bench_root_travel BANDAI_DIR [--json docs/benchmarks/root_travel.json]

Every dataset-1 forward ``walk`` take of the Bandai Namco Research Motion Dataset under BANDAI_DIR (unpacked
``../shared/mocap/bandai-namco/dataset-1.tar.xz``) is imported onto our gait skeleton (as the corpus does), its
root travel removed (the walk seen on a treadmill, root fixed in all three axes, as in the BML walks), then
reconstructed by :func:`generation.mocap.root_travel.reconstruct_root_travel` with the BML import's settings, and
compared with the true root path (:func:`generation.mocap.root_travel.compare_travel`). Prints a Markdown table per
take (pasted into docs/benchmarks/mocap.md) and writes the JSON.
Real capture: Bandai Namco Research Motion Dataset (Kobayashi et al. 2023, arXiv:2306.08861), CC BY-NC 4.0.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from benchmarks.bench_record import one_thread
from generation.mocap import bandai_namco as bn
from generation.mocap.dataset_import import import_take
from generation.mocap.emotion_gait_bml import ANKLE_SPEED_GAIN, BLEND_M, SMOOTH_FRAMES, SPEED_BLEND_M_S
from generation.mocap.root_travel import compare_travel, reconstruct_root_travel, strip_root_travel

ROOT = Path(__file__).resolve().parents[1]


def check_take(motion, toes: bool = False, gain: float = 1.0) -> dict:
    """Strip and reconstruct one Motion's root travel; the comparison in metres (and the stance weights' switches).
    The feet are the ankles only (what the BML walks have), or with ``toes`` the lower of ankle and toe."""
    P = motion.positions()
    sk = motion.skeleton
    ends = ("heel", "toe") if toes else ("heel",)
    feet = tuple([sk.index(f"{s}_{e}") for e in ends] for s in ("left", "right"))
    flat = strip_root_travel(P)
    travel, w = reconstruct_root_travel(flat, motion.fps, feet, blend=BLEND_M * sk.height / 1.75,
                                        smooth_frames=SMOOTH_FRAMES, hips=(sk.index("left_hip"), sk.index("right_hip")),
                                        speed_blend=SPEED_BLEND_M_S * sk.height / 1.75)
    travel[:, [0, 2]] *= gain
    rec = flat[:, 0] + travel
    out = compare_travel(P[:, 0], rec, motion.fps)
    out["frames"] = int(motion.num_frames)
    out["stance_switches"] = int((np.diff(w[:, 0] > 0.5) != 0).sum())
    return out


def main(argv=None) -> int:
    one_thread()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("root", type=Path)
    ap.add_argument("--json", type=Path, default=ROOT / "docs" / "benchmarks" / "root_travel.json")
    args = ap.parse_args(argv)
    takes, _ = bn.find_takes(args.root)
    takes = [t for t in takes if t.dataset == "bandai-namco-1" and t.content == "walk"]
    rows = []
    for t in takes:
        clip, row = import_take(t)
        if clip is None:
            print(f"skip {t.name}: {row['message']}", file=sys.stderr)
            continue
        raw = check_take(clip.motion)
        r = check_take(clip.motion, gain=ANKLE_SPEED_GAIN)
        r_toes = check_take(clip.motion, toes=True)
        rows.append({"take": t.name, "style": t.style, **{k: round(v, 4) if isinstance(v, float) else v
                                                          for k, v in r.items()},
                     "raw_speed_ratio": round(raw["speed_true"] / raw["speed_rec"], 4),
                     "with_toes": {k: round(v, 4) if isinstance(v, float) else v for k, v in r_toes.items()}})
    print("| take | s | true speed m/s | reconstructed | speed error % | path RMS m | path RMS % of distance | "
          "end error % | heading error deg | bounce true / rec cm |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['take'].removeprefix('dataset-1_')} | {r['frames'] / 30:.1f} | {r['speed_true']:.2f} | "
              f"{r['speed_rec']:.2f} | {r['speed_error_pct']:+.1f} | {r['path_rms']:.2f} | {r['path_rms_pct']:.1f} | "
              f"{r['end_error_pct']:.1f} | {r['heading_error_deg']:.1f} | "
              f"{100 * r['bounce_true']:.1f} / {100 * r['bounce_rec']:.1f} |")
    keys = ("speed_error_pct", "path_rms_pct", "end_error_pct", "heading_error_deg")
    summary = {k: {"median_abs": round(float(np.median(np.abs([r[k] for r in rows]))), 2),
                   "max_abs": round(float(np.max(np.abs([r[k] for r in rows]))), 2),
                   "with_toes_median_abs": round(float(np.median(np.abs([r["with_toes"][k] for r in rows]))), 2)}
               for k in keys}
    first = [r["raw_speed_ratio"] for r in rows if r["take"].endswith("_001")]
    second = [abs(r["speed_error_pct"]) for r in rows if r["take"].endswith("_002")]
    summary["gain"] = {"used": ANKLE_SPEED_GAIN, "fitted_on_first_takes": round(float(np.mean(first)), 4),
                       "second_takes_speed_error_median_abs": round(float(np.median(second)), 2),
                       "second_takes_speed_error_max_abs": round(float(np.max(second)), 2)}
    print(json.dumps(summary))
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps({"takes": rows, "summary": summary}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
