"""Quality records of a plan's clips without rendering video (the motion part, the realism measures of gait clips,
the projected figure height and an observer's reading: for gait clips the real-capture observer, or the synthetic
one when the plan's ``qa: {observer: synthetic}`` asks or, for a plan that names none, ``gait_observer`` (the
command line's ``--observer``, default ``$QA_GAIT_OBSERVER`` or real); for gesture clips the synthetic gesture
observer), and the per-flag summary that ``generate_clips`` prints. The real gait observers are trained on the
real-capture corpora that ``$REAL_CORPUS`` and ``$BML_CORPUS`` name (default: the built ones under var/mocap/).

    python -m generation.pipeline.plan_qa --plan seed000 [--limit K] [--modality gesture] [--no-figure-height]
        [--observer real|real-perceived|synthetic] [--json out.json]

The video render computes the same record for every clip it makes (:func:`generation.pipeline.runner.render_job`).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections import Counter
from collections.abc import Iterable

from generation.core.motion import Motion
from generation.mocap.real_corpus import DEFAULT_CORPORA, RealCorpora
from generation.plans.clipgen import make_motion
from generation.plans.schema import load_plan
from generation.quality.checks import QAResult, evaluate, gait_observer_kind, resolve_thresholds
from generation.quality.observers import OBSERVERS
from generation.quality.realism_ranges import out_of_range
from generation.render.clip import plan_cameras, prepare
from protocol.vocabulary import QA_CHECKS, QA_OBSERVERS

from .jobs import plan_jobs

PASSED = "passed"


def intended_emotion(inputs: dict):
    """What the observer check compares with: the gait emotion vector an entry asks for, else its gesture emotion
    label (``emotion_label``); None for transitions, themes, source walks and gestures given by VAD values."""
    if inputs.get("emotion") is not None:
        return inputs["emotion"]
    return inputs.get("emotion_label")


def clip_qa(motion: Motion, settings, thresholds: dict, intended=None, observer=None,
            camera_info: dict | None = None) -> tuple[QAResult, dict]:
    """The quality record of ``motion`` as the renderer shows it (resampled to ``settings.fps`` and cut to its
    duration); the figure height comes from ``camera_info`` (a render's) or is projected here without rendering.
    Returns (result, camera info)."""
    clip, positions = prepare(motion, settings)
    if camera_info is None:
        _, camera_info, _ = plan_cameras(clip, positions, settings)
        camera_info.pop("extent", None)
    seated = bool(camera_info.get("seated", False))
    result = evaluate(clip, thresholds, camera_info.get("min_figure_fraction"), seated, intended, observer)
    return result, camera_info


def observer_for(modality: str, kind: str = "real", corpora: RealCorpora = DEFAULT_CORPORA):
    """The observer that reads clips of ``modality`` (:data:`generation.quality.observers.OBSERVERS`): "gait" with
    ``kind`` real, real-perceived (trained on the real corpora ``corpora``) or synthetic; "gesture": the synthetic
    gesture observer. None for other modalities or when it cannot be built (:func:`unread_line` then says why)."""
    return OBSERVERS.for_modality(modality, kind, corpora)


def summary_counts(flags: Iterable[str]) -> Counter:
    """Clips per flag: ``passed`` for an empty flag, else one count per failed check (a clip failing two checks
    counts under both), plus ``flagged`` (clips with any flag)."""
    counts: Counter = Counter()
    for flag in flags:
        if not flag:
            counts[PASSED] += 1
            continue
        counts["flagged"] += 1
        for check in flag.split(";"):
            counts[check] += 1
    return counts


def summary_line(flags: Iterable[str]) -> str:
    """'QA: 40 passed, 3 flagged (foot_skate 2, penetration 1)'."""
    c = summary_counts(list(flags))
    per = ", ".join(f"{k} {c[k]}" for k in QA_CHECKS if c[k])
    return f"QA: {c[PASSED]} passed, {c['flagged']} flagged" + (f" ({per})" if per else "")


def observer_line(kind: str, observer) -> str:
    """Which gait observer reads the clips and from what data (the real one names its corpus, or says that it fell
    back to the shipped takes), or that none is available."""
    if observer is None:
        return f"QA: gait observer {kind}: not available"
    source = getattr(observer, "source", "")
    return f"QA: gait observer {kind}" + (f" ({source})" if source else "")


def unread_line(records: Iterable[dict], gait_kind: str = "real") -> str:
    """'' when every gait and gesture clip got an observer's reading, else a line saying how many did not and why
    that usually happens, so that a switched-off observer check is never silent. ``records``: render records
    (``modality``, ``qa``); ``gait_kind``: the gait observer asked (real, real-perceived or synthetic)."""
    missing = Counter(r.get("modality") for r in records
                      if r.get("modality") in ("gait", "gesture") and not (r.get("qa") or {}).get("observed"))
    if not missing:
        return ""
    parts = []
    if missing["gait"] and gait_kind == "real":
        parts.append(f"{missing['gait']} gait clip(s) (no real-capture observer: no corpus at var/mocap/ "
                     "(`python -m generation.mocap dataset bandai-namco DIR`), and the shipped real takes in "
                     "generation/data/mocap/bandai-namco/ are missing or do not import)")
    elif missing["gait"] and gait_kind == "real-perceived":
        parts.append(f"{missing['gait']} gait clip(s) (the perceived-label observer needs both real corpora: "
                     "var/mocap/bandai-namco.npz and var/mocap/emotion-gait-bml.npz, "
                     "`python -m generation.mocap dataset bandai-namco|emotion-gait-bml DIR`)")
    elif missing["gait"]:
        parts.append(f"{missing['gait']} gait clip(s) (no synthetic gait corpus at var/corpus/: "
                     "`manage.py build_corpus` builds it in about a minute, then render again)")
    if missing["gesture"]:
        parts.append(f"{missing['gesture']} gesture clip(s) (shorter than 2.5 s, or the gesture corpus could not "
                     "be built: see the warnings above)")
    return "QA: no observer reading, so no observer check, for " + "; ".join(parts)


def run(plan_name: str, limit: int | None = None, log=print, modality: str | None = None,
        figure_height: bool = True, gait_observer: str = "real", corpora: RealCorpora = DEFAULT_CORPORA) -> list[dict]:
    """Make every entry's motion and compute its quality record (no video). Returns one row per entry.

    ``modality``: only the entries of that modality ("gait" or "gesture"; None: all). ``figure_height=False``
    skips the camera projection (no ``figure_height`` check, faster). ``gait_observer``: the gait observer when
    the plan names none (real, real-perceived or synthetic); ``corpora``: the real corpora of the real ones."""
    plan = load_plan(plan_name)
    thresholds = resolve_thresholds(plan.qa)
    kind = gait_observer_kind(plan.qa, gait_observer)
    jobs, failures = plan_jobs(plan, limit, gait_observer=kind, corpora=corpora)
    if modality is not None:
        jobs = [j for j in jobs if j.run_entry.modality == modality]
    observers = {m: observer_for(m, kind, corpora) for m in sorted({j.run_entry.modality for j in jobs})}
    if "gait" in observers:
        log(observer_line(kind, observers["gait"]))
    rows = []
    for job in jobs:
        t0 = time.perf_counter()
        entry = job.run_entry
        motion = make_motion(entry, requested=job.entry.generator, fallback_reason=job.fallback_reason)
        intended = intended_emotion(entry.inputs)
        camera = None if figure_height else {"rule": None, "seated": entry.modality == "gesture"}
        result, cam = clip_qa(motion, entry.render, thresholds, intended, observers[entry.modality], camera)
        rows.append({"entry": job.entry.id, "clip_id": job.clip_id, "modality": entry.modality,
                     "generator": entry.generator, "intended": intended if isinstance(intended, str) else None,
                     "camera": cam.get("rule"), **result.as_dict(),
                     "realism_out": ";".join(out_of_range(result.values, thresholds)),
                     "seconds": round(time.perf_counter() - t0, 2)})
        log(json.dumps(rows[-1]))
    for where, msg in failures:
        log(f"FAILED {where}: {msg}")
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plan", required=True)
    ap.add_argument("--limit", type=int, default=None)
    ap.add_argument("--modality", choices=("gait", "gesture"), default=None, help="only the entries of this modality")
    ap.add_argument("--no-figure-height", action="store_true", help="skip the camera projection (figure_height)")
    ap.add_argument("--observer", choices=QA_OBSERVERS, default=os.environ.get("QA_GAIT_OBSERVER") or "real",
                    help="the gait observer for a plan that names none (default $QA_GAIT_OBSERVER, else real)")
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    rows = run(args.plan, args.limit, modality=args.modality, figure_height=not args.no_figure_height,
               gait_observer=args.observer, corpora=RealCorpora.from_environ(os.environ))
    print(f"plan {args.plan}: {len(rows)} clips; " + summary_line(r["flag"] for r in rows))
    # which study section is short after the gate is the study side's question: python -m analysis.coverage
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(rows, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
