"""Realism by emotion on render-length windows: the real walks' own ranges per emotion, and where the shipped gait
weights' walks fall in them (docs/benchmarks/gait.md, "Realism by emotion on render-length windows").

A measurement, not a gate change: ``generation/quality/realism_ranges.json`` (pooled over all styles, one value per
whole take) stays the gate's; this benchmark asks what the same measures look like per emotion on windows as long as
a rendered clip.

1. Real ranges. Every real walk of an emotion is cut into render-length windows (the one window slicer,
   :func:`generation.core.windows.windows`, a window every ``hop`` seconds and one ending at the last frame) and each
   window is measured by :func:`generation.quality.realism.realism_measures`; per emotion and measure the windows'
   p5, median, p95, min and max. References: Bandai dataset 1 forward walks of the happy, sad, angry and normal
   styles (all takes, both splits; the four emotions seed 000 trains on), and as a second neutral reference dataset
   2's normal forward walks (other actors, 24 takes).
2. Generated walks. The seed000 plan's pure-emotion gait_net clips as ``plan_qa`` makes them (not rendered), with
   the shipped weights (``weights: real``), plus ``--extra-seeds`` copies of each with other seeds; the same windows;
   per emotion and measure the median over the windows, and whether it lies inside the same emotion's real p5-p95
   and min-max.
3. BML walks (Emotion-Gait): each clip is one 2.5 s stride looped, with root travel reconstructed from the stance
   foot. Render-length windows of them would repeat the same stride, so they are measured whole and reported
   beside the Bandai ranges, not as ranges (see the doc for why most measures mean nothing there).

Usage: python -m benchmarks.bench_realism_by_emotion [--windows 6:1,8:2,4:1] [--extra-seeds 4] [--out JSON]
Needs the Bandai corpus with dataset 1 walks and dataset 2 normal walks (``python -m generation.mocap dataset
bandai-namco DIR --contents walk``, docs/mocap.md) and, optionally, the BML corpus (``--bml``).
Results: docs/benchmarks/realism_by_emotion.json; the default ``--out`` also renders the ``realism_by_emotion.*``
tables of docs/benchmarks/gait.md (benchmarks/doc_tables.py).
Real capture: Bandai Namco Research Motion Dataset (Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0); BML
walks (Ma, Paterson & Pollick 2006) with Emotion-Gait labels (STEP, Bhattacharya et al. AAAI 2020), research use.
"""
from __future__ import annotations

import argparse
import datetime
import os
import shlex
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks import doc_tables
from benchmarks.bench_gait_real import _file_record, clip_kind, plan_walks
from benchmarks.bench_record import commit_label, machine_label, one_thread
from generation.core.motion import Motion
from generation.core.windows import windows
from generation.gait.weights import weights_path
from generation.mocap.real_corpus import load_real_corpus, real_corpus_path
from generation.quality.realism import MEASURES, realism_measures
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS

ROOT = Path(__file__).resolve().parents[1]
AREA = "realism_by_emotion"
DEFAULT_WINDOWS = ((6.0, 1.0), (8.0, 2.0), (4.0, 1.0))
"""(length, hop) in seconds: 6 s is the demo plan's render length and the longest window the real happy and
neutral dataset-1 takes hold; 8 s (hop 2 s) lies inside seed000's 10 s clips; 4 s is shorter than any render but
lets both dataset-1 takes of happy and angry in (the render-length references rest on one take)."""
RANGE_PCTS = (5, 50, 95)
NEUTRAL_D2 = "neutral (dataset 2)"
"""The second neutral reference: dataset 2's normal walks (other actors than dataset 1)."""
DEFAULT_BML = ROOT / "var" / "mocap" / "emotion-gait-bml.npz"


# ---- ranges --------------------------------------------------------------------------------------
def measure_range(values) -> dict:
    """{n, p5, p50, p95, min, max} of the finite values (None entries dropped); {"n": 0} when none is left."""
    v = np.asarray([x for x in values if x is not None], dtype=float)
    v = v[np.isfinite(v)]
    if not v.size:
        return {"n": 0}
    return {"n": int(v.size), **{f"p{p}": float(np.percentile(v, p)) for p in RANGE_PCTS},
            "min": float(v.min()), "max": float(v.max())}


def emotion_ranges(rows: list[dict]) -> dict:
    """Per emotion, per realism measure: :func:`measure_range` of the rows of that emotion.

    Args:
        rows: one dict per window: ``emotion`` and the :data:`MEASURES` values (None where undefined).
    Returns:
        {emotion: {measure: {n, p5, p50, p95, min, max}}}, emotions in first-seen order.
    """
    by: dict[str, list[dict]] = {}
    for r in rows:
        by.setdefault(r["emotion"], []).append(r)
    return {e: {m: measure_range([r.get(m) for r in rs]) for m in MEASURES} for e, rs in by.items()}


def inside(value: float | None, ref: dict) -> dict:
    """Whether ``value`` lies in the reference's [p5, p95] and [min, max] (None for both when either side is
    missing)."""
    if value is None or not ref.get("n"):
        return {"p5_p95": None, "min_max": None}
    return {"p5_p95": bool(ref["p5"] <= value <= ref["p95"]), "min_max": bool(ref["min"] <= value <= ref["max"])}


# ---- windows -------------------------------------------------------------------------------------
def window_measures(motion: Motion, length_s: float, hop_s: float) -> list[dict]:
    """The realism measures of every ``length_s`` window of ``motion`` (a window every ``hop_s`` seconds and one
    ending at the last frame; none when the motion is shorter than a window)."""
    length, hop = int(round(length_s * motion.fps)), max(1, int(round(hop_s * motion.fps)))
    return [realism_measures(motion.slice(s.start, s.stop)) for s in windows(motion.num_frames, length, hop)]


def windowed_rows(items: list[tuple[str, str, Motion]], length_s: float, hop_s: float) -> list[dict]:
    """One row per window of each (emotion, source name, motion): emotion, source and the measures."""
    return [{"emotion": emotion, "source": name, **m} for emotion, name, motion in items
            for m in window_measures(motion, length_s, hop_s)]


def sources(rows: list[dict]) -> dict:
    """Per emotion: the sources that gave at least one window, and the window count."""
    out: dict[str, dict] = {}
    for r in rows:
        e = out.setdefault(r["emotion"], {"sources": [], "windows": 0})
        e["windows"] += 1
        if r["source"] not in e["sources"]:
            e["sources"].append(r["source"])
    return out


# ---- data ----------------------------------------------------------------------------------------
def real_walks(corpus: Path) -> list[tuple[str, str, Motion]]:
    """(emotion, take name, motion) of the real forward walks: dataset 1 happy/sad/angry/normal (every take, both
    splits) and dataset 2 normal, the latter under :data:`NEUTRAL_D2`."""
    clips = load_real_corpus(corpus, skeleton="gait", contents="walk", styles=tuple(CAPTURE_GAIT_EMOTIONS))
    out = []
    for c in clips:
        if c.dataset == "bandai-namco-1":
            out.append((CAPTURE_GAIT_EMOTIONS[c.style], c.name, c.motion))
        elif c.dataset == "bandai-namco-2" and c.style == "normal":
            out.append((NEUTRAL_D2, c.name, c.motion))
    return out


def _is_pure(entry: dict) -> bool:
    return "emotion" in entry and "transition" not in entry and clip_kind([entry["emotion"]]) == "pure"


def generated_walks(extra_seeds: int) -> list[tuple[str, str, Motion]]:
    """(emotion, clip id, motion) of the seed000 plan's pure-emotion gait_net clips with the shipped weights, as
    plan_qa makes them, then ``extra_seeds`` copies of each with the plan seed + 1000 k (k = 1..extra_seeds)."""
    out = []
    for k in range(extra_seeds + 1):
        suffix = f" (seed + {1000 * k})" if k else ""
        out += [(r["asked"], r["seed"] + suffix, r["motion"])
                for r in plan_walks("real", keep=_is_pure, seed_offset=1000 * k)]
    return out


def bml_single_strides(path: Path) -> dict | None:
    """Per acted emotion: :func:`measure_range` of each measure over the BML walks measured whole (one looped
    2.5 s stride each); None when the BML corpus is not built."""
    if not path.is_file():
        return None
    rows = [{"emotion": c.label, **realism_measures(c.motion)} for c in load_real_corpus(path, skeleton="gait")]
    return {"corpus": _file_record(path), "walks": len(rows), "per_emotion": emotion_ranges(rows)}


# ---- comparison ----------------------------------------------------------------------------------
REFERENCE_OF = {NEUTRAL_D2: "neutral"}
"""A real reference -> the generated emotion judged against it (the others are their own emotion)."""


def compare(real: dict, generated: dict) -> dict:
    """Per real reference and measure: the generated emotion's median over its windows, and whether it lies inside
    the reference's p5-p95 and min-max."""
    out = {}
    for ref, per in real.items():
        gen = generated.get(REFERENCE_OF.get(ref, ref), {})
        out[ref] = {m: {"generated_median": gen.get(m, {}).get("p50"), "generated_n": gen.get(m, {}).get("n", 0),
                        **inside(gen.get(m, {}).get("p50"), per[m])} for m in MEASURES}
    return out


def outside(comparison: dict) -> list[dict]:
    """Every (reference, measure) whose generated median lies outside the real p5-p95, and whether also outside
    the min-max."""
    return [{"reference": ref, "measure": m, "outside_min_max": c["min_max"] is False}
            for ref, per in comparison.items() for m, c in per.items() if c["p5_p95"] is False]


def run_window(real_items, gen_items, length_s: float, hop_s: float) -> dict:
    real_rows = windowed_rows(real_items, length_s, hop_s)
    gen_rows = windowed_rows(gen_items, length_s, hop_s)
    real, gen = emotion_ranges(real_rows), emotion_ranges(gen_rows)
    order = [*GAIT_EMOTIONS, NEUTRAL_D2]
    real = {e: real[e] for e in order if e in real}
    comparison = compare(real, gen)
    return {"length_s": length_s, "hop_s": hop_s, "real_sources": sources(real_rows),
            "generated_sources": sources(gen_rows), "real": real, "generated": gen, "comparison": comparison,
            "generated_emotion_of": {ref: REFERENCE_OF.get(ref, ref) for ref in real},
            "outside_p5_p95": outside(comparison),
            "no_real_window": [e for e in order if e not in real]}


# ---- run -----------------------------------------------------------------------------------------
def _windows_arg(text: str) -> tuple[tuple[float, float], ...]:
    try:
        pairs = tuple(tuple(float(x) for x in part.split(":")) for part in text.split(","))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"windows: LENGTH:HOP[,LENGTH:HOP...] in seconds, got {text!r}") from exc
    if not pairs or any(len(p) != 2 or p[0] <= 0 or p[1] <= 0 for p in pairs):
        raise argparse.ArgumentTypeError(f"windows: LENGTH:HOP[,LENGTH:HOP...] in seconds, got {text!r}")
    return pairs


def _args(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--windows", type=_windows_arg, default=DEFAULT_WINDOWS,
                    help="LENGTH:HOP[,...] seconds (default 6:1,8:2,4:1)")
    ap.add_argument("--extra-seeds", type=int, default=4,
                    help="copies of each pure plan clip with other seeds (default 4)")
    ap.add_argument("--corpus", type=Path, default=None, help="Bandai corpus (default $REAL_CORPUS or var/mocap/)")
    ap.add_argument("--bml", type=Path, default=DEFAULT_BML, help="BML corpus (skipped when missing)")
    ap.add_argument("--out", type=Path, default=doc_tables.area_files(AREA)[0],
                    help="JSON results; the default also renders the tables into docs/benchmarks/gait.md")
    return ap.parse_args(argv)


def run(a, argv) -> dict:
    t0 = time.time()
    corpus = a.corpus or real_corpus_path(os.environ)
    real_items = real_walks(corpus)
    gen_items = generated_walks(a.extra_seeds)
    res = {"date": datetime.date.today().isoformat(), "commit": commit_label(),
           "command": shlex.join(["python", "-m", f"benchmarks.bench_{AREA}", *argv]),
           "machine": machine_label("1 thread"), "corpus": _file_record(corpus),
           "weights": {"real": _file_record(weights_path("real"))},
           "real_takes": len(real_items), "generated_clips": len(gen_items), "extra_seeds": a.extra_seeds,
           "windows": [run_window(real_items, gen_items, length, hop) for length, hop in a.windows],
           "bml_single_stride": bml_single_strides(a.bml)}
    res["seconds"] = time.time() - t0
    return res


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    a = _args(argv)
    one_thread()
    res = run(a, argv)
    for name, lines in doc_tables.render_tables(AREA, res).items():
        print(f"\n{name}\n" + "\n".join(lines))
    doc_tables.write_results(AREA, a.out, res, res["seconds"])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
