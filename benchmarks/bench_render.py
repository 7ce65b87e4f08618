"""Render + encode speed, and wall time of the built-in plans.

    python -m benchmarks.bench_render speed [--frames 300] [--aa auto none fxaa msaa ssaa2] [--procs 1 2]
                                            [--motion walk gesture] [--patches 1 0]
                                            [--body human mannequin stick points] [--width 1280 --height 720]
    python -m benchmarks.bench_render sheet [--out docs/img/render_contact_sheet.png]
    python -m benchmarks.bench_render plans [--plans seed000 seed003 seed004] [--sample 6 10 12] [--workers 2]
                                            [--body human|mannequin]

``speed`` renders a 10 s procedural walk (21 joints, a loop of 3 m radius) and/or a seated procedural gesture
(23 joints, on a chair) at 1280x720 (``--width/--height``) with each ``--body`` to H.264 and reports
frames per second of wall time and per CPU-second (the process, its llvmpipe threads and its ffmpeg child
together). With ``--procs 2`` two processes render at once; fps is their total.

``sheet`` makes ten motions as plan entries make them (the gait network's happy, sad, angry and neutral walks, two
RBF themes at w = 1.3 and -0.7, four gesture-network seated gestures), scaled to male and female bodies 1.52-1.95 m
tall, and writes one contact sheet of the same frame (40 % into each clip) as mannequin, stick figure and
point-lights, each captioned with its camera rule, anti-aliasing and projected figure height range.

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

from generation.render.offscreen import prepare_render_process

prepare_render_process()  # here, not in main(): the spawned render processes import this module too


def _cpu() -> float:
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def _motion(kind: str, frames: int, fps: float):
    """A 'walk' (procedural, 21 joints, a 3 m radius loop) or a seated 'gesture' (procedural, 23 joints)."""
    import numpy as np

    from generation.procedural.emotion import gait_params_for_emotion, gesture_params_for_vad
    from protocol.vocabulary import GESTURE_VAD
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


SHEET_CLIPS = [  # (label, build, height m, plan entry of the generator that makes the motion)
    ("gait_net happy, male 1.65 m", "male", 1.65, {"generator": "gait_net", "emotion": "happy"}),
    ("gait_net sad, male 1.95 m", "male", 1.95, {"generator": "gait_net", "emotion": "sad"}),
    ("gait_net angry, female 1.52 m", "female", 1.52, {"generator": "gait_net", "emotion": "angry"}),
    ("gait_net neutral, female 1.82 m", "female", 1.82, {"generator": "gait_net", "emotion": "neutral"}),
    ("rbf {t0} w=1.3, male 1.95 m", "male", 1.95, {"generator": "rbf", "theme": 0, "weight": 1.3}),
    ("rbf {t1} w=-0.7, female 1.52 m", "female", 1.52, {"generator": "rbf", "theme": 1, "weight": -0.7}),
    ("gesture_net proud, male 1.65 m", "male", 1.65, {"generator": "gesture_net", "emotion_label": "proud"}),
    ("gesture_net angry, male 1.95 m", "male", 1.95, {"generator": "gesture_net", "emotion_label": "angry"}),
    ("gesture_net joyous, female 1.52 m", "female", 1.52, {"generator": "gesture_net", "emotion_label": "joyous"}),
    ("gesture_net sad, female 1.82 m", "female", 1.82, {"generator": "gesture_net", "emotion_label": "sad"}),
]


def _sentence(emotion: str) -> str:
    import csv

    path = Path(__file__).resolve().parent.parent / "generation" / "data" / "sentences_synthetic.csv"
    return next(r["sentence"] for r in csv.DictReader(path.open(encoding="utf-8")) if r["emotion"] == emotion)


def scaled_motion(motion, height: float, build: str):
    """The motion on a uniformly scaled skeleton ``height`` metres tall (root path scaled too), labelled ``build``."""
    import dataclasses

    k = height / motion.skeleton.height
    skel = dataclasses.replace(motion.skeleton, offsets=motion.skeleton.offsets * k, height=height, build=build)
    meta = {**motion.metadata, "build": build}
    return dataclasses.replace(motion, skeleton=skel, root_positions=motion.root_positions * k, metadata=meta)


def sheet_motion(build: str, height: float, spec: dict, fps: float = 25.0, seconds: float = 4.0):
    """A motion made as a plan entry makes it (network gait, RBF theme, network gesture), scaled and labelled."""
    from generation.plans.clipgen import make_motion, resolve
    from generation.plans.schema import validate_plan
    from protocol.vocabulary import THEMES

    entry = {"id": "x", **spec, "seed": 1}
    if spec["generator"] == "gait_net":
        entry.update(trajectory={"kind": "curved", "radius_m": 4.0, "angle_deg": 60, "length_m": 8},
                     duration_s=seconds)
    elif spec["generator"] == "rbf":
        entry.update(theme=THEMES[spec["theme"]], n_features=10, n_cycles=3)
    else:
        entry.update(sentence=_sentence(spec["emotion_label"]), gender=build)
    plan = validate_plan({"name": "sheet", "render": {"fps": fps, "duration_s": seconds}, "clips": [entry]})
    run_entry, reason = resolve(plan.entries[0])
    if reason:
        raise SystemExit(f"{spec['generator']} unavailable: {reason}")
    return scaled_motion(make_motion(run_entry), height, build)


def sheet(args) -> list[dict]:
    """One contact sheet: every SHEET_CLIPS motion at the same frame (40 % into the clip) as mannequin, stick figure
    and point-lights (rows of five: walks and themes, then seated gestures, per look)."""
    from PIL import Image

    from generation.render import RenderSettings, contact_sheet
    from generation.render import clip as clip_mod
    from protocol.vocabulary import THEMES

    rows, paths, labels = [], [], []
    tmp = Path(tempfile.mkdtemp(prefix="render_sheet_"))
    motions = [sheet_motion(build, height, spec) for _, build, height, spec in SHEET_CLIPS]
    for body in ("mannequin", "stick", "points"):
        for (label, *_), motion in zip(SHEET_CLIPS, motions):
            label = label.format(t0=THEMES[0], t1=THEMES[1])
            settings = RenderSettings(width=args.width, height=args.height, fps=25.0, duration_s=4.0, body=body)
            clip, pos = clip_mod.prepare(motion, settings)
            info: dict = {}
            t_show = int(0.4 * (len(pos) - 1))
            frames = clip_mod._frames(clip, pos, settings, info=info)
            img = next(f for t, f in enumerate(frames) if t == t_show)
            frames.close()
            p = tmp / f"{body}_{len(paths)}.png"
            Image.fromarray(img).save(p)
            paths.append(p)
            labels.append(f"{body}: {label}; {info['rule']} camera, {info['anti_aliasing']}, figure "
                          f"{info['min_figure_fraction']:.2f}-{info['max_figure_fraction']:.2f}")
            rows.append({"body": body, "clip": label, "frame": t_show, **info})
            print(json.dumps(rows[-1]), flush=True)
    contact_sheet(paths, labels, args.out, columns=5, thumb_width=args.thumb)
    return rows


def plans(args) -> list[dict]:
    from dataclasses import replace

    from generation.pipeline.runner import run_plan
    from generation.plans.schema import load_plan

    rows = []
    samples = args.sample * len(args.plans) if len(args.sample) == 1 else args.sample
    for name, sample in zip(args.plans, samples):
        plan = load_plan(name)
        n = len(plan.entries)
        k = n if not sample or sample >= n else sample
        step = n / k
        picked = tuple(plan.entries[int(i * step)] for i in range(k))
        if args.body:  # every entry in this look (the plan's own otherwise)
            picked = tuple(replace(e, render=replace(e.render, body=args.body)) for e in picked)
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
    s.add_argument("--body", nargs="+", default=["human", "mannequin"],
                   choices=["human", "mannequin", "stick", "points"])
    s.add_argument("--aa", nargs="+", default=["auto"])
    s.add_argument("--procs", nargs="+", type=int, default=[1])
    s.add_argument("--motion", nargs="+", default=["walk", "gesture"], choices=["walk", "gesture"])
    s.add_argument("--patches", nargs="+", type=int, default=[1], help="1 = patch rendering, 0 = whole frames")
    c = sub.add_parser("sheet")
    c.add_argument("--out", default="docs/img/render_contact_sheet.png")
    c.add_argument("--width", type=int, default=640)
    c.add_argument("--height", type=int, default=360)
    c.add_argument("--thumb", type=int, default=400)
    q = sub.add_parser("plans")
    q.add_argument("--plans", nargs="+", default=["demo", "seed000", "seed003", "seed004"])
    q.add_argument("--sample", type=int, nargs="+", default=[12],
                   help="entries rendered per plan (0 = all), one number for all plans or one per plan")
    q.add_argument("--workers", type=int, default=2)
    q.add_argument("--body", default=None, choices=["human", "mannequin", "stick", "points"],
                   help="render every entry in this look (default: the plan's own)")
    for x in (s, c, q):
        x.add_argument("--json", default=None)
    args = p.parse_args()
    rows = {"speed": speed, "sheet": sheet, "plans": plans}[args.cmd](args)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
