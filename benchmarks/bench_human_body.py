"""The human body against the mannequin: render time per frame, walk and seated, in one run; skinning time.

    python -m benchmarks.bench_human_body [--frames 300] [--width 1280 --height 720] [--repeat 2] [--json out.json]

For a procedural 10 s walk (a 3 m radius loop, follow camera) and a seated procedural gesture (fixed camera, patch
rendering), renders the clip to H.264 with each look, alternating human and mannequin ``--repeat`` times, and
reports milliseconds of wall time and of CPU time (the process, its llvmpipe threads and its ffmpeg child) per
frame, the fastest repeat of each. Beside that: the human body's per-clip preparation (retargeting with the legs'
IK and the outline for the camera, ``generation.render.human.human_figure``) and its skinning per frame (points
and normals of the 13,718-vertex mesh, ``Skinner.__call__``).
"""
from __future__ import annotations

import argparse
import json
import tempfile
import time

from benchmarks.bench_render import _cpu, _motion, render_once


def skinning(kind: str, frames: int) -> dict:
    import numpy as np

    from generation.render import RenderSettings
    from generation.render.bodies.skinning import Skinner
    from generation.render.clip import prepare
    from generation.render.human import human_figure

    clip, _ = prepare(_motion(kind, frames, 30.0), RenderSettings(duration_s=frames / 30.0))
    t0 = time.perf_counter()
    fig = human_figure(clip, "male")
    prep = time.perf_counter() - t0
    sk = Skinner(fig.body, fig.points, np.ones_like(fig.points) / np.sqrt(3))
    t0 = time.perf_counter()
    for t in range(len(fig.transforms)):
        sk(fig.transforms[t])
    per = (time.perf_counter() - t0) / len(fig.transforms)
    return {"motion": kind, "prepare_s": round(prep, 3), "skin_ms_per_frame": round(1000 * per, 2),
            "vertices": int(len(fig.points))}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--frames", type=int, default=300)
    p.add_argument("--width", type=int, default=1280)
    p.add_argument("--height", type=int, default=720)
    p.add_argument("--repeat", type=int, default=2)
    p.add_argument("--json", default=None)
    args = p.parse_args()
    out_dir = tempfile.mkdtemp(prefix="bench_human_")
    render_once(("auto", 10, 160, 120, 0, out_dir, "walk", True, "human"))       # warm imports and caches
    rows = []
    for kind in ("walk", "gesture"):
        best: dict[str, dict] = {}
        for _ in range(args.repeat):
            for body in ("human", "mannequin"):
                c0 = _cpu()
                r = render_once(("auto", args.frames, args.width, args.height, 0, out_dir, kind, True, body))
                r["cpu_s"] = _cpu() - c0
                if body not in best or r["wall_s"] < best[body]["wall_s"]:
                    best[body] = r
        for body, r in best.items():
            row = {"motion": kind, "body": body, "camera": r["camera"], "frames": r["frames"],
                   "ms_per_frame": round(1000 * r["wall_s"] / r["frames"], 1),
                   "cpu_ms_per_frame": round(1000 * r["cpu_s"] / r["frames"], 1),
                   "min_figure_fraction": r["min_fraction"]}
            rows.append(row)
            print(json.dumps(row), flush=True)
        ratio = best["human"]["wall_s"] / best["mannequin"]["wall_s"]
        print(json.dumps({"motion": kind, "human_over_mannequin_wall": round(ratio, 2),
                          "human_over_mannequin_cpu": round(best["human"]["cpu_s"] / best["mannequin"]["cpu_s"],
                                                            2)}), flush=True)
    for kind in ("walk", "gesture"):
        row = skinning(kind, args.frames)
        rows.append(row)
        print(json.dumps(row), flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
