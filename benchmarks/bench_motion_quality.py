"""Motion quality of the seed 000 plan's generated gaits before and after the foot clean-up.

For every ``gait_net`` entry of the built-in ``seed000`` plan (made as the study makes it:
``generation.plans.clipgen.resolve`` + ``make_motion``, no video), the raw network output
(``generate_gaits(..., foot_cleanup=False)``) and the cleaned motion (the default) are measured:

- foot skate: :func:`generation.core.features.foot_skate` with contacts detected by
  :func:`generation.core.features.detect_foot_contacts` on the measured motion (cm/s, mean over clips);
- penetration: how far the lowest foot joint goes below the floor y = 0 (cm, max over clips);
- stance knee flexion: 180 degrees minus the hip-knee-heel angle, mean over detected contact frames, per intended
  emotion, against procedural corpus walks of the same emotion (``gait_params_for_emotion`` + ``walk``, the
  generator of the training corpus): one per single-emotion entry, on its path and with its duration;
- bone length error (max, mm) and the largest joint speed (m/s; a pop would raise it).

Usage: ``python -m benchmarks.bench_motion_quality [--json var/motion_quality.json]``

``--qa seed000 seed003 seed004`` instead runs the per-clip quality checks (:mod:`generation.quality`, the record
``generate_clips`` keeps per clip) over every entry of the plans without rendering video, and prints per plan the
clips flagged by each check and the range of every measure.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import platform
import time
from pathlib import Path

import numpy as np

from generation.core.features import detect_foot_contacts, foot_joints, foot_skate
from generation.core.motion import Motion
from generation.plans import clipgen
from generation.plans.schema import load_plan
from protocol.vocabulary import GAIT_EMOTIONS


def stance_knee_flexion(motion: Motion) -> np.ndarray:
    """Knee flexion in degrees (180 - hip-knee-ankle angle) at every detected contact frame of either leg."""
    from generation.core.foot_contact import legs

    P = motion.positions()
    contacts = detect_foot_contacts(P, motion.fps, motion.skeleton)
    out = []
    for s, leg in enumerate(legs(motion.skeleton)):
        u = P[:, leg.hip] - P[:, leg.knee]
        v = P[:, leg.ankle] - P[:, leg.knee]
        cos = (u * v).sum(-1) / (np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1))
        out.append(180.0 - np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))[contacts[:, s]])
    return np.concatenate(out)


def measure(motion: Motion) -> dict:
    P = motion.positions()
    sk = motion.skeleton
    left, right = foot_joints(sk)
    skate = foot_skate(P, motion.fps, sk)
    parents = list(sk.parents[1:])
    bone_err = np.abs(np.linalg.norm(P[:, 1:] - P[:, parents], axis=-1) - sk.bone_lengths()[1:]).max()
    return {"skate_cm_s": 100 * skate["mean_m_s"],
            "penetration_cm": max(0.0, -100 * float(P[:, left + right, 1].min())),
            "knee_deg": float(stance_knee_flexion(motion).mean()), "bone_err_mm": 1000 * float(bone_err),
            "max_joint_speed_m_s": float(np.linalg.norm(np.diff(P, axis=0), axis=-1).max() * motion.fps),
            "root_height_m": float(motion.root_positions[:, 1].mean())}


def _dominant(entry) -> str:
    inp = entry.inputs
    if "transition" in inp:
        return "transition"
    return GAIT_EMOTIONS[int(np.argmax(inp["emotion"]))]


def corpus_walk(entry, seed: int) -> Motion:
    """A procedural walk (the training corpus generator) for the entry's emotion and path."""
    return clipgen.make_motion(dataclasses.replace(entry.with_generator("procedural_walk"), seed=seed))


def run(plan_name: str = "seed000") -> dict:
    from generation.gait import generate as gen

    plan = load_plan(plan_name)
    entries = [e for e in plan.entries if e.generator == "gait_net"]
    rows = []
    original = gen.generate_gaits
    t0 = time.time()
    for e in entries:
        entry, reason = clipgen.resolve(e)
        if reason:
            raise SystemExit(f"{e.id}: gait_net unavailable ({reason})")
        out = {"id": e.id, "emotion": _dominant(e)}
        for label, cleanup in (("before", False), ("after", True)):
            gen.generate_gaits = lambda *a, _c=cleanup, **k: original(*a, foot_cleanup=_c, **k)
            try:
                out[label] = measure(clipgen.make_motion(entry))
            finally:
                gen.generate_gaits = original
        rows.append(out)
    gen_s = time.time() - t0
    corpus = {}
    for emo in GAIT_EMOTIONS:
        single = [e for e in entries if _dominant(e) == emo]
        vals = [measure(corpus_walk(e, 1000 + e.seed)) for e in single]
        corpus[emo] = {k: float(np.mean([v[k] for v in vals])) for k in vals[0]} | {"n": len(vals)}
    return {"plan": plan_name, "rows": rows, "corpus": corpus, "seconds": round(gen_s, 1),
            "machine": f"{platform.machine()} {platform.system()}, {platform.python_version()}",
            "date": time.strftime("%Y-%m-%d")}


def table(result: dict) -> str:
    rows = result["rows"]
    lines = ["| emotion | clips | skate before / after (cm/s) | max penetration before / after (cm) | "
             "stance knee flexion before / after / corpus (deg) | corpus skate (cm/s) |", "|---|---|---|---|---|---|"]
    for emo in list(GAIT_EMOTIONS) + ["transition", "all"]:
        sel = rows if emo == "all" else [r for r in rows if r["emotion"] == emo]
        if not sel:
            continue
        b = {k: [r["before"][k] for r in sel] for k in sel[0]["before"]}
        a = {k: [r["after"][k] for r in sel] for k in sel[0]["after"]}
        c = result["corpus"].get(emo)
        corpus_knee = f"{c['knee_deg']:.1f}" if c else "-"
        corpus_skate = f"{c['skate_cm_s']:.1f}" if c else "-"
        lines.append(f"| {emo} | {len(sel)} | {np.mean(b['skate_cm_s']):.1f} / **{np.mean(a['skate_cm_s']):.1f}** | "
                     f"{max(b['penetration_cm']):.1f} / {max(a['penetration_cm']):.1f} | "
                     f"{np.mean(b['knee_deg']):.1f} / {np.mean(a['knee_deg']):.1f} / {corpus_knee} | {corpus_skate} |")
    allb = [r["before"] for r in rows]
    alla = [r["after"] for r in rows]
    lines.append("")
    lines.append(f"Foot skate per clip after the clean-up: max {max(r['skate_cm_s'] for r in alla):.1f} cm/s "
                 f"(before {max(r['skate_cm_s'] for r in allb):.1f}). "
                 f"Bone length error max: before {max(r['bone_err_mm'] for r in allb):.1e} mm, after "
                 f"{max(r['bone_err_mm'] for r in alla):.1e} mm. Largest joint speed: before "
                 f"{max(r['max_joint_speed_m_s'] for r in allb):.2f} m/s, after "
                 f"{max(r['max_joint_speed_m_s'] for r in alla):.2f} m/s. Mean root height: before "
                 f"{np.mean([r['root_height_m'] for r in allb]):.3f} m, after "
                 f"{np.mean([r['root_height_m'] for r in alla]):.3f} m.")
    return "\n".join(lines)


QA_MEASURES = ("foot_skate_cm_s", "penetration_cm", "jerk", "bone_error_mm", "figure_height_frac", "observed_p")


def qa_table(plans: list[str]) -> tuple[str, dict]:
    """Per plan: clips, passed, flagged per check, and min / median / max of each measure."""
    from generation.pipeline.plan_qa import run as run_qa
    from generation.pipeline.plan_qa import summary_counts
    from protocol.vocabulary import QA_CHECKS

    out, lines = {}, ["| plan | clips | passed | " + " | ".join(QA_CHECKS) + " |",
                      "|---|---|---|" + "---|" * len(QA_CHECKS)]
    ranges = ["", "| plan | " + " | ".join(QA_MEASURES) + " |", "|---|" + "---|" * len(QA_MEASURES)]
    for name in plans:
        rows = run_qa(name, log=lambda _msg: None)
        out[name] = rows
        c = summary_counts(r["flag"] for r in rows)
        lines.append(f"| {name} | {len(rows)} | {c['passed']} | " + " | ".join(str(c[k]) for k in QA_CHECKS) + " |")
        cells = []
        for m in QA_MEASURES:
            v = np.array([r[m] for r in rows if r.get(m) is not None], dtype=float)
            cells.append(f"{v.min():.3g} / {np.median(v):.3g} / {v.max():.3g}" if v.size else "-")
        ranges.append(f"| {name} | " + " | ".join(cells) + " |")
    flagged = [f"- {name} {r['entry']} ({r['generator']}): {r['flag']}" for name, rows in out.items() for r in rows
               if r["flag"]]
    return "\n".join(lines + ranges + ["", "Flagged clips:"] + flagged), out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plan", default="seed000")
    ap.add_argument("--json", default=None, help="also write the per-clip numbers here")
    ap.add_argument("--qa", nargs="+", default=None, metavar="PLAN", help="quality checks of these plans' clips")
    args = ap.parse_args(argv)
    if args.qa:
        text, rows = qa_table(args.qa)
        print(text)
        if args.json:
            Path(args.json).write_text(json.dumps(rows, indent=1))
        return 0
    result = run(args.plan)
    print(table(result))
    print(f"\n{len(result['rows'])} clips, {result['seconds']} s (both variants), {result['machine']}, "
          f"{result['date']}")
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
