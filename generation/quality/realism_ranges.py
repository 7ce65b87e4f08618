"""The real corpus's own ranges of the realism measures: the quality gate's realism thresholds, kept in one file.

``generation/quality/realism_ranges.json`` holds, per measure of :data:`generation.quality.realism.MEASURES`, the
percentiles of the measure over the real walks of the real-capture corpus's training split (every gait-skeleton
take: dataset 1 walk, walk-left, walk-right, walk-back; dataset 2 walk, walk-turn-left, walk-turn-right; all
styles pooled, each take one value), the same per style, and the share of held-out (test) takes the thresholds
flag. The thresholds are the pooled **1st-99th percentiles**: with the 5th-95th, a third of the real walks fail at
least one of the nine bounds (the measures are not independent enough for 10 % per bound to stay small); the
1st-99th flag about one real take in ten (the file records the held-out share). Skate, skate ratio and toe skim
have only an upper bound (less sliding is never unrealistic); knee flexion, pelvis bounce and speed variability
have both.

Threshold keys (the plan's ``qa:`` block overrides them; null switches a bound off): ``<measure>_max`` for every
measure and ``<measure>_min`` for the two-sided ones, e.g. ``stance_knee_deg_max``.

Bounds listed in :data:`NOT_APPLIED` are computed and recorded but not applied (None) until their reason is gone; a
plan may still set them. None are listed now: the stance-knee bounds apply since the retargeting puts our hips on
the source's (before, the legs fell short of the feet and real knees stayed 9-12 degrees too bent).

    python -m generation.quality.realism_ranges [--corpus PATH] [--out JSON]   # recompute from the corpus
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from generation.mocap.real_corpus import load_real_corpus, read_meta, real_corpus_path

from .realism import MEASURES, UNITS, realism_measures

RANGES_PATH = Path(__file__).with_name("realism_ranges.json")
TWO_SIDED = ("stance_knee_deg", "pelvis_bounce_cm", "speed_cv")
LOW_PCT, HIGH_PCT = 1.0, 99.0
REPORT_PCTS = (1, 5, 50, 95, 99)
_CACHE: dict[str, dict] = {}
#: Bounds recorded but not applied, with the reason (kept in the ranges file's ``not_applied``).
NOT_APPLIED: dict[str, str] = {}


def threshold_keys() -> tuple[str, ...]:
    """Every realism threshold key, in MEASURES order (``_min`` before ``_max``)."""
    keys = []
    for m in MEASURES:
        if m in TWO_SIDED:
            keys.append(f"{m}_min")
        keys.append(f"{m}_max")
    return tuple(keys)


def load_ranges(path: str | Path | None = None) -> dict:
    """The ranges file as a dict (cached per path); FileNotFoundError names the command that writes it."""
    p = Path(path) if path is not None else RANGES_PATH
    key = str(p)
    if key not in _CACHE:
        if not p.is_file():
            raise FileNotFoundError(f"{p}: no realism ranges; `python -m generation.quality.realism_ranges` writes "
                                    "them from the real-capture corpus")
        _CACHE[key] = json.loads(p.read_text(encoding="utf-8"))
    return _CACHE[key]


def realism_thresholds(path: str | Path | None = None) -> dict:
    """{threshold key: float, or None for a bound in the file's ``not_applied``} from the ranges file (every key
    of :func:`threshold_keys`)."""
    data = load_ranges(path)
    off = data.get("not_applied", {})
    out = {k: None if k in off else float(v) for k, v in data["thresholds"].items()}
    missing = set(threshold_keys()) - set(out)
    if missing:
        raise ValueError(f"{path or RANGES_PATH}: thresholds lack {sorted(missing)}; recompute the file")
    return out


def out_of_range(values: dict, thresholds: dict) -> list[str]:
    """The bounds a clip's measured ``values`` break, e.g. ``["stance_knee_deg>49.1", "speed_cv<0.02"]`` (a
    measure that is None or a bound that is None is not checked)."""
    out = []
    for m in MEASURES:
        v = values.get(m)
        if v is None:
            continue
        lo, hi = thresholds.get(f"{m}_min"), thresholds.get(f"{m}_max")
        if lo is not None and v < lo:
            out.append(f"{m}<{lo:g}")
        if hi is not None and v > hi:
            out.append(f"{m}>{hi:g}")
    return out


def _percentiles(values: list[float]) -> dict:
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    if not v.size:
        return {"n": 0}
    return {"n": int(v.size), **{f"p{p:g}": round(float(np.percentile(v, p)), 4) for p in REPORT_PCTS}}


def compute_ranges(rows: list[dict]) -> dict:
    """The ranges file's content from measured takes.

    Args:
        rows: one dict per real take: ``style``, ``split`` and the :data:`MEASURES` values (None where undefined).
    Returns:
        {"rule", "units", "thresholds", "pooled": {measure: percentiles}, "per_style": {style: {measure: ...}},
        "n_train", "test_flagged_share" (held-out takes outside the applied bounds), "not_applied"} with
        percentiles over the training split.
    """
    train = [r for r in rows if r["split"] == "train"]
    if not train:
        raise ValueError("compute_ranges: no training takes")
    pooled = {m: _percentiles([r[m] for r in train]) for m in MEASURES}
    thresholds = {}
    for m in MEASURES:
        v = np.asarray([r[m] for r in train if r[m] is not None], dtype=float)
        if m in TWO_SIDED:
            thresholds[f"{m}_min"] = round(float(np.percentile(v, LOW_PCT)), 4)
        thresholds[f"{m}_max"] = round(float(np.percentile(v, HIGH_PCT)), 4)
    by_style: dict[str, list[dict]] = defaultdict(list)
    for r in train:
        by_style[r["style"]].append(r)
    test = [r for r in rows if r["split"] == "test"]
    applied = {k: None if k in NOT_APPLIED else v for k, v in thresholds.items()}
    flagged = [bool(out_of_range(r, applied)) for r in test]
    return {"rule": f"pooled percentiles {LOW_PCT:g} and {HIGH_PCT:g} over the real training takes (one value per "
                    f"take); upper bound only for {', '.join(m for m in MEASURES if m not in TWO_SIDED)}",
            "units": UNITS, "thresholds": thresholds, "not_applied": NOT_APPLIED, "pooled": pooled,
            "per_style": {s: {m: _percentiles([r[m] for r in rs]) for m in MEASURES}
                          for s, rs in sorted(by_style.items())},
            "n_train": len(train), "n_test": len(test),
            "test_flagged_share": round(float(np.mean(flagged)), 4) if flagged else None}


def measure_corpus(clips) -> list[dict]:
    """One row per CorpusClip: name, dataset, content, style, label, split and the realism measures."""
    return [{"name": c.name, "dataset": c.dataset, "content": c.content, "style": c.style, "label": c.label,
             "split": c.split, **realism_measures(c.motion)} for c in clips]


def main(argv=None) -> int:

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", type=Path, default=real_corpus_path(os.environ),
                    help="real-capture corpus (default: $REAL_CORPUS, else var/mocap/bandai-namco.npz)")
    ap.add_argument("--out", default=str(RANGES_PATH))
    args = ap.parse_args(argv)
    path = args.corpus
    rows = measure_corpus(load_real_corpus(path, skeleton="gait"))
    data = compute_ranges(rows)
    meta = read_meta(path)
    data = {"corpus": {"file": path.name, "dataset": meta.get("dataset"), "licence": meta.get("licence"),
                       "citation": meta.get("citation"), "takes": len(rows)}, **data}
    Path(args.out).write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    print(f"{args.out}: thresholds from {data['n_train']} real training takes; "
          f"{data['test_flagged_share']} of {data['n_test']} held-out takes flagged")
    return 0


if __name__ == "__main__":
    sys.exit(main())
