"""Render + encode speed, and wall time of the built-in plans.

    python benchmarks/bench_render.py speed [--frames 300] [--aa none fxaa msaa ssaa2] [--procs 1 2]
                                            [--motion walk gesture] [--patches 1 0]
                                            [--body mannequin stick points] [--width 1280 --height 720]
    python benchmarks/bench_render.py sheet [--out docs/img/render_mannequin_sheet.png]
    python benchmarks/bench_render.py plans [--plans demo seed000 seed003 seed004] [--sample 12] [--workers 2]

``speed`` renders a 10 s procedural walk (21 joints, a loop of 3 m radius) and/or a seated procedural gesture
(23 joints, on a chair) at 1280x720 (``--width/--height``) with each ``--body`` to H.264 and reports
frames per second of wall time and per CPU-second (the process, its llvmpipe threads and its ffmpeg child
together). With ``--procs 2`` two processes render at once; fps is their total.

``sheet`` renders eight procedural clips (male and female, short and tall, walking and seated) as
mannequin, stick figure and point-lights and writes one contact sheet of their middle frames (two rows per
look: walks, then seated gestures) with each clip's camera rule and projected figure height range in the
labels.

``plans`` renders every k-th entry of
each plan (``--sample`` entries, or all with 0) into a temporary media folder with ``--workers`` processes
and extrapolates to the whole plan by the entry count; it says so in its output.

CPU-seconds are reported beside wall time because the benchmark machine is shared: wall time measures
the machine's load as much as the renderer. Writes a JSON summary to ``--json`` when given.
"""
from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))


def _cpu() -> float:
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def _motion(kind: str, frames: int, fps: float):
    """A 'walk' (procedural, 21 joints, a 3 m radius loop) or a seated 'gesture' (procedural, 23 joints)."""
    import numpy as np

    from generation.procedural.emotion import gait_params_for_emotion, gesture_params_for_vad
    from study_protocol import GESTURE_VAD
    if kind == "walk":
        from generation.core.paths import curved
        from generation.procedural.walk import walk

        return walk(gait_params_for_emotion([0.2, 0.0, 0.0, 0.8]), curved(3.0, np.radians(330), 14.0), frames, fps)
    from generation.procedural.gesture import seated_gesture

    v, a, d = GESTURE_VAD["proud"]
    return seated_gesture(gesture_params_for_vad(v, a, d, np.random.default_rng(0)), frames, fps, seed=0)


def render_once(args: tuple) -> dict:
    """Render one clip; returns frames, wall and CPU seconds (run in this process or a spawned one)."""
    aa, frames, width, height, lp_threads, out_dir, kind, patches, body = args
    if lp_threads:
        os.environ["LP_NUM_THREADS"] = str(lp_threads)
    import torch

    torch.set_num_threads(1)
    from generation.render import RenderSettings, clip, render_clip

    motion = _motion(kind, frames, 30.0)
    settings = RenderSettings(width=width, height=height, fps=30.0, duration_s=frames / 30.0, anti_aliasing=aa,
                              body=body)
    original = clip._frames
    if not patches:  # whole frames every time (the plain PyVista loop), for comparison
        clip._frames = lambda c, p, s, patches=True, info=None: original(c, p, s, False, info)
    try:
        c0, t0 = _cpu(), time.perf_counter()
        result = render_clip(motion, out_dir, f"bench_{aa}_{os.getpid()}", settings)
        wall, cpu = time.perf_counter() - t0, _cpu() - c0
    finally:
        clip._frames = original
    return {"frames": result.n_frames, "wall_s": wall, "cpu_s": cpu, "bytes": result.mp4.stat().st_size,
            "camera": result.camera.get("rule"), "min_fraction": result.camera.get("min_figure_fraction")}


def speed(args) -> list[dict]:
    rows = []
    out_dir = tempfile.mkdtemp(prefix="bench_render_")
    cases = [(k, b, a, pt, pr) for k in args.motion for b in args.body for a in args.aa for pt in args.patches
             for pr in args.procs]
    for kind, body, aa, patches, procs in cases:
        lp = 1 if procs > 1 else 0  # one llvmpipe thread per process when several run at once
        job = (aa, args.frames, args.width, args.height, lp, out_dir, kind, bool(patches), body)
        load = os.getloadavg()[0]
        if procs == 1:
            r = [render_once(job)]
            wall = r[0]["wall_s"]
        else:
            ctx = mp.get_context("spawn")
            with ctx.Pool(procs) as pool:
                pool.map(render_once, [(aa, 10, 160, 120, lp, out_dir, kind, True, body)] * procs)  # warm imports
                t0 = time.perf_counter()
                r = pool.map(render_once, [job] * procs)
                wall = time.perf_counter() - t0
        frames = sum(x["frames"] for x in r)
        cpu = sum(x["cpu_s"] for x in r)
        row = {"motion": kind, "body": body, "camera": r[0]["camera"], "min_fraction": r[0]["min_fraction"],
               "size": f"{args.width}x{args.height}", "aa": aa, "patches": bool(patches), "procs": procs,
               "frames": frames,
               "wall_s": round(wall, 2), "fps_wall": round(frames / wall, 1), "cpu_s": round(cpu, 2),
               "fps_per_cpu_s": round(frames / cpu, 1),
               "kib_per_10s": round(sum(x["bytes"] for x in r) / len(r) / 1024 * 300 / args.frames),
               "load_before": round(load, 2)}
        rows.append(row)
        print(json.dumps(row), flush=True)
    return rows


SHEET_CLIPS = [  # (label, modality, build, height m, emotion or gesture label)
    ("male 1.65 m walk happy", "walk", "male", 1.65, [1.0, 0, 0, 0]),
    ("male 1.95 m walk sad", "walk", "male", 1.95, [0, 1.0, 0, 0]),
    ("female 1.52 m walk angry", "walk", "female", 1.52, [0, 0, 1.0, 0]),
    ("female 1.82 m walk neutral", "walk", "female", 1.82, [0, 0, 0, 1.0]),
    ("male 1.65 m seated proud", "gesture", "male", 1.65, "proud"),
    ("male 1.95 m seated angry", "gesture", "male", 1.95, "angry"),
    ("female 1.52 m seated joyous", "gesture", "female", 1.52, "joyous"),
    ("female 1.82 m seated sad", "gesture", "female", 1.82, "sad"),
]


def sheet_motion(modality: str, build: str, height: float, what, frames: int = 90, fps: float = 30.0):
    import numpy as np

    from generation.core.skeleton import gait_skeleton, gesture_skeleton
    from generation.procedural.emotion import gait_params_for_emotion, gesture_params_for_vad
    from study_protocol import GESTURE_VAD
    if modality == "walk":
        from generation.core.paths import curved
        from generation.procedural.walk import walk

        return walk(gait_params_for_emotion(what), curved(4.0, np.radians(90), 8.0), frames, fps,
                    skeleton=gait_skeleton(height, build))
    from generation.procedural.gesture import seated_gesture

    v, a, d = GESTURE_VAD[what]
    return seated_gesture(gesture_params_for_vad(v, a, d, np.random.default_rng(0)), frames, fps,
                          gesture_skeleton(height, build), seed=0)


def sheet(args) -> list[dict]:
    from PIL import Image

    from generation.render import RenderSettings, contact_sheet
    from generation.render import clip as clip_mod

    rows, paths, labels = [], [], []
    tmp = Path(tempfile.mkdtemp(prefix="render_sheet_"))
    for body in ("mannequin", "stick", "points"):
        for label, modality, build, height, what in SHEET_CLIPS:
            motion = sheet_motion(modality, build, height, what)
            settings = RenderSettings(width=args.width, height=args.height, fps=10.0, duration_s=3.0, body=body)
            clip, pos = clip_mod.prepare(motion, settings)
            info: dict = {}
            frames = list(clip_mod._frames(clip, pos, settings, info=info))
            p = tmp / f"{body}_{len(paths)}.png"
            Image.fromarray(frames[len(frames) // 2]).save(p)
            paths.append(p)
            labels.append(f"{body}, {label}, {info['rule']} camera, height "
                          f"{info['min_figure_fraction']:.2f}-{info['max_figure_fraction']:.2f}")
            rows.append({"body": body, "clip": label, **info})
            print(json.dumps(rows[-1]), flush=True)
    contact_sheet(paths, labels, args.out, columns=4, thumb_width=args.thumb)
    return rows


def plans(args) -> list[dict]:
    from dataclasses import replace

    from generation.plans.schema import load_plan
    from generation.render.batch import run_plan

    rows = []
    for name in args.plans:
        plan = load_plan(name)
        n = len(plan.entries)
        k = n if not args.sample or args.sample >= n else args.sample
        step = n / k
        picked = tuple(plan.entries[int(i * step)] for i in range(k))
        sub = replace(plan, entries=picked)
        with tempfile.TemporaryDirectory(prefix="bench_plan_") as tmp:
            c0, t0, load = _cpu(), time.perf_counter(), os.getloadavg()[0]
            result = run_plan(sub, Path(tmp) / "clips", Path(tmp) / "records", workers=args.workers)
            wall, cpu = time.perf_counter() - t0, _cpu() - c0
        frames = sum(r["metadata"].get("n_frames", 0) for r in result.records)
        gen_s = sum(r["metadata"].get("timing_s", {}).get("generate", 0.0) for r in result.records)
        row = {"plan": name, "entries": n, "rendered": len(result.rendered), "failed": len(result.failed),
               "workers": args.workers, "frames": frames, "wall_s": round(wall, 1), "cpu_s": round(cpu, 1),
               "generate_s": round(gen_s, 1), "extrapolated": k < n,
               "plan_wall_s": round(wall * n / k, 1), "plan_cpu_s": round(cpu * n / k, 1),
               "plan_frames": round(frames * n / k), "load_before": round(load, 2),
               "generators": sorted({r["metadata"]["generator"] for r in result.records})}
        for _where, msg in result.failed:
            print("FAILED", msg, file=sys.stderr)
        rows.append(row)
        print(json.dumps(row), flush=True)
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("speed")
    s.add_argument("--frames", type=int, default=300)
    s.add_argument("--width", type=int, default=1280)
    s.add_argument("--height", type=int, default=720)
    s.add_argument("--body", nargs="+", default=["mannequin", "stick"], choices=["mannequin", "stick", "points"])
    s.add_argument("--aa", nargs="+", default=["fxaa"])
    s.add_argument("--procs", nargs="+", type=int, default=[1])
    s.add_argument("--motion", nargs="+", default=["walk", "gesture"], choices=["walk", "gesture"])
    s.add_argument("--patches", nargs="+", type=int, default=[1], help="1 = patch rendering, 0 = whole frames")
    c = sub.add_parser("sheet")
    c.add_argument("--out", default="docs/img/render_mannequin_sheet.png")
    c.add_argument("--width", type=int, default=640)
    c.add_argument("--height", type=int, default=360)
    c.add_argument("--thumb", type=int, default=480)
    q = sub.add_parser("plans")
    q.add_argument("--plans", nargs="+", default=["demo", "seed000", "seed003", "seed004"])
    q.add_argument("--sample", type=int, default=12, help="entries rendered per plan (0 = all)")
    q.add_argument("--workers", type=int, default=2)
    for x in (s, c, q):
        x.add_argument("--json", default=None)
    args = p.parse_args()
    rows = {"speed": speed, "sheet": sheet, "plans": plans}[args.cmd](args)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
