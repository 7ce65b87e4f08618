"""Seed 004 on real capture: the averaged neutral walk checked against real normal walks, expert vs data-driven
RBF features per theme, what the real-capture observers read, and a contact sheet per theme.

Run:  OMP_NUM_THREADS=1 python -m benchmarks.bench_rbf_real [--corpus var/mocap/bandai-namco.npz]
          [--out docs/benchmarks/rbf_real.json] [--doc docs/benchmarks/rbf.md] [--sheets docs/img]

Writes its figures to the JSON (--out); with --doc it renders them into that page's ``rbf_real.*`` tables
(benchmarks/doc_tables.py; the narrative there is written by hand).

Needs the real-capture corpus (``python -m generation.mocap dataset bandai-namco DIR --out CORPUS``). Real data:
Bandai Namco Research Motion Dataset 1 and 2 (Kobayashi et al. 2023, arXiv:2306.08861; CC BY-NC 4.0).

- Neutral: the shipped averaged cycle (``generation.rbf.real_neutral.load_cycle``) walked for 4 cycles at 30 fps
  (``neutral_walk``), beside the procedural base; measures: walking speed (median over 1 s windows of the root's
  ground-plane speed), cadence (steps/min: two steps per mean steady cycle), stance knee flexion and
  pelvis bounce (``generation.quality.realism``), compared with every real normal walk (both datasets, all splits).
- Expert vs data (``generation.rbf.compare.compare_theme``): per theme the top DOFs by amplitude.
- Observers (``generation.quality.real_observer``): the four-emotion classifier and the theme-pair classifiers,
  their held-out accuracy on the test split's takes (take level: mean window probability > 0.5), and their reading
  of the neutral walk, of each theme styled with expert and with data features (w = 0.7 and 1.0, all ten
  features) and of the real themed test takes.
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

from benchmarks import doc_tables
from generation.mocap.real_corpus import load_real_corpus, real_corpus_path
from generation.quality.observers import OBSERVERS
from generation.quality.real_observer import THEME_PAIRS
from generation.quality.realism import realism_measures
from generation.rbf.compare import compare_theme
from generation.rbf.data_features import PART_OF
from generation.rbf.neutral_base import neutral_cycle
from generation.rbf.real_neutral import load_cycle, steady_cycles
from generation.rbf.stylise import neutral_walk, stylise
from generation.rbf.themes import THEME_NAMES, theme_features
from generation.render.offscreen import prepare_render_process
from protocol.vocabulary import CAPTURE_THEMES, GAIT_EMOTIONS

CHECKED = ("speed_m_s", "cadence_steps_min", "stance_knee_deg", "pelvis_bounce_cm")
WEIGHTS = (0.7, 1.0)
PAIR_OF = {theme: (pair, side) for pair, sides in THEME_PAIRS.items()
           for side, styles in enumerate(sides) for theme in {CAPTURE_THEMES[s] for s in styles}}


def walk_measures(motion) -> dict:
    """Speed (m/s), cadence (steps/min), stance knee flexion (deg) and pelvis bounce (cm) of a walk."""
    P = motion.positions()
    fps = motion.fps
    w = max(1, int(round(fps)))
    root = P[:, 0, [0, 2]]
    speeds = np.linalg.norm(root[w:] - root[:-w], axis=-1) * fps / w
    cycles = steady_cycles(motion)
    cadence = 120.0 / float(np.mean([c.duration_s for c in cycles])) if cycles else float("nan")
    r = realism_measures(motion)
    return {"speed_m_s": float(np.median(speeds)), "cadence_steps_min": cadence,
            "stance_knee_deg": r["stance_knee_deg"], "pelvis_bounce_cm": r["pelvis_bounce_cm"]}


def neutral_section(corpus: Path, observer) -> dict:
    real = load_real_corpus(corpus, skeleton="gait", contents=["walk"], styles=["normal"])
    real_rows = [dict(walk_measures(c.motion), name=c.name, split=c.split) for c in real]
    base = load_cycle()
    bases = {"real (averaged)": base, "procedural (averaged, synthetic)": neutral_cycle()}
    rows = {}
    for name, cyc in bases.items():
        walk = neutral_walk(cyc, n_cycles=4, fps=30.0)
        row = walk_measures(walk)
        row["observer"] = dict(zip(GAIT_EMOTIONS, observer.proba(walk).round(3).tolist()))
        rows[name] = row
    ranges = {k: (float(np.nanmin([r[k] for r in real_rows])), float(np.nanmax([r[k] for r in real_rows])))
              for k in CHECKED}
    for row in rows.values():
        row["inside"] = {k: bool(ranges[k][0] <= row[k] <= ranges[k][1]) for k in CHECKED}
    test = [c for c in real if c.split == "test"]
    real_read = np.mean([observer.proba(c.motion) for c in test], axis=0)
    md = base.metadata
    return {"metadata": {k: md[k] for k in ("n_cycles", "n_takes", "time_warping", "dtw_spread", "stride_m",
                                            "cycle_duration_s", "ik_error_max_m", "captured_sources")},
            "bases": rows, "real_ranges": ranges, "real_takes": len(real_rows),
            "real_test_normal_read": dict(zip(GAIT_EMOTIONS, real_read.round(3).tolist()))}


def pair_accuracy(observer, corpus: Path) -> dict:
    """Held-out (test split) take-level accuracy of each theme-pair classifier and of the emotion classifier."""
    out = {}
    test = load_real_corpus(corpus, skeleton="gait", split="test", contents=["walk"])
    for pair, (first, second) in THEME_PAIRS.items():
        takes = [c for c in test if c.style in first + second]
        hits = [(observer.theme_proba(c.motion, pair) > 0.5) == (c.style in second) for c in takes]
        out[pair] = {"takes": len(takes), "accuracy": float(np.mean(hits)) if hits else None}
    style_to_emotion = {"happy": "happy", "sad": "sad", "angry": "angry", "normal": "neutral"}
    emo = [c for c in test if c.dataset == "bandai-namco-1" and c.style in style_to_emotion]
    hits = [observer.observe(c.motion)[0] == style_to_emotion[c.style] for c in emo]
    out["emotions (dataset 1)"] = {"takes": len(emo), "accuracy": float(np.mean(hits)) if hits else None}
    return out


def intended_p(observer, motion, theme: str) -> float:
    """The theme-pair classifier's probability of ``theme`` for a motion."""
    pair, side = PAIR_OF[theme]
    p = observer.theme_proba(motion, pair)
    return p if side == 1 else 1.0 - p


def observer_section(observer, corpus: Path, base) -> dict:
    test = load_real_corpus(corpus, skeleton="gait", split="test", contents=["walk"])
    neutral = neutral_walk(base, n_cycles=4, fps=30.0)
    out = {}
    for theme in THEME_NAMES:
        styles = [s for s, t in CAPTURE_THEMES.items() if t == theme]
        real = [c for c in test if c.style in styles]
        row = {"pair": PAIR_OF[theme][0], "neutral": intended_p(observer, neutral, theme),
               "real_test": float(np.mean([intended_p(observer, c.motion, theme) for c in real])),
               "real_test_takes": len(real)}
        for w in WEIGHTS:
            for features in ("expert", "data"):
                clip = stylise(base, theme, w, 10, n_cycles=4, fps=30.0, features=features)
                row[f"{features}_{w}"] = intended_p(observer, clip, theme)
                if theme in ("happy", "sad"):
                    row[f"{features}_{w}_emotion_p"] = float(observer.proba(clip)[GAIT_EMOTIONS.index(theme)])
        if theme in ("happy", "sad"):
            row["real_test_emotion_p"] = float(np.mean([observer.proba(c.motion)[GAIT_EMOTIONS.index(theme)]
                                                        for c in real if c.dataset == "bandai-namco-1"]))
        out[theme] = row
    return out


def disputed_rows(compare: dict, theme: str) -> list[tuple]:
    """Expert features the data dispute: (rank, wording, why) for Table III rows outside the data's first ten rows or
    holding a shared DOF whose sign the data reverse."""
    reversed_rows = {(PART_OF[r["joint"]], r["axis"]) for r in compare["rows"] if r["sign_agree"] is False}
    data_rows = set(compare["data_features"])
    out = []
    for f in theme_features(theme):
        key = (f.part, f.axis)
        if key in reversed_rows:
            out.append((f.rank, f.describe(), "data reverse its sign"))
        elif key not in data_rows:
            out.append((f.rank, f.describe(), "not in the data's first ten rows"))
    return out


def ablation_section(observer, base, compare: dict, weight: float = 1.0, tie: float = 0.02) -> dict:
    """Per theme and disputed expert feature: the theme observer's p(intended) with all ten expert features and
    without that one; removing it raising p by more than ``tie`` means the observer sides with the data."""
    out = {}
    for theme in THEME_NAMES:
        full = intended_p(observer, stylise(base, theme, weight, 10, n_cycles=4, fps=30.0), theme)
        rows = []
        for rank, wording, why in disputed_rows(compare[theme], theme):
            clip = stylise(base, theme, weight, 10, n_cycles=4, fps=30.0, exclude=(rank,))
            p = intended_p(observer, clip, theme)
            side = "data" if p > full + tie else "expert" if p < full - tie else "neither"
            rows.append({"rank": rank, "feature": wording, "why": why, "p_without": p, "sides_with": side})
        out[theme] = {"p_full": full, "rows": rows}
    return out


def contact_sheets(base, corpus: Path, out_dir: Path, weight: float = 1.0) -> list[Path]:
    """docs/img/rbf_real_<theme>.png: neutral, expert-styled, data-styled, a real themed test take; 5 frames each."""
    from PIL import Image

    from generation.render.clip import render_frames_at
    from generation.render.contact_sheet import contact_sheet
    from generation.render.settings import RenderSettings

    times = [0.5 + 0.25 * k for k in range(5)]
    settings = RenderSettings(width=320, height=400, fps=30, duration_s=times[-1] + 0.2, camera="tracking")
    test = load_real_corpus(corpus, skeleton="gait", split="test", contents=["walk"])
    neutral = neutral_walk(base, n_cycles=3, fps=30.0)
    written = []
    for theme in THEME_NAMES:
        styles = [s for s, t in CAPTURE_THEMES.items() if t == theme]
        real = next(c for c in sorted(test, key=lambda c: (c.dataset, c.take)) if c.style in styles)
        rows = [("neutral (real avg)", neutral),
                (f"{theme} expert w{weight}", stylise(base, theme, weight, 10, n_cycles=3, fps=30.0)),
                (f"{theme} data w{weight}", stylise(base, theme, weight, 10, n_cycles=3, fps=30.0, features="data")),
                (f"REAL {real.style} {real.dataset[-1]}/{real.take}", real.motion)]
        posters, labels = [], []
        with tempfile.TemporaryDirectory() as tmp:
            for label, motion in rows:
                wanted = [int(round(t * settings.fps)) for t in times]
                for k, img in render_frames_at(motion, settings, wanted):
                    p = Path(tmp) / f"{len(posters):03d}.png"
                    Image.fromarray(img).save(p)
                    posters.append(p)
                    labels.append(f"{label}, {k / settings.fps:.2f} s")
            path = out_dir / f"rbf_real_{theme}.png"
            contact_sheet(posters, labels, path, columns=len(times), thumb_width=170)
        Image.open(path).quantize(96).save(path, optimize=True)  # a 96-colour palette: a third of the bytes
        written.append(path)
    return written


def main(argv=None) -> int:
    import datetime
    import os
    import platform
    import shlex

    prepare_render_process()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", type=Path, default=None)
    ap.add_argument("--out", type=Path, default=doc_tables.area_files("rbf_real")[0])
    ap.add_argument("--doc", type=Path, default=None, help="render the rbf_real tables marked in this page")
    ap.add_argument("--sheets", type=Path, default=None, help="write rbf_real_<theme>.png into this folder")
    a = ap.parse_args(argv)
    warnings.filterwarnings("ignore", message="The given NumPy array is not writable")
    corpus = a.corpus or real_corpus_path(os.environ)
    if not Path(corpus).is_file():
        raise SystemExit(f"no real-capture corpus at {corpus}; build it with python -m generation.mocap dataset ...")
    observer = OBSERVERS.gait("real", corpus)
    base = load_cycle()
    threads = f"OMP_NUM_THREADS={os.environ['OMP_NUM_THREADS']} " if "OMP_NUM_THREADS" in os.environ else ""
    result = {"machine": f"{platform.machine()} {platform.system()}, {os.cpu_count()} CPUs (shared), no GPU",
              "date": datetime.date.today().isoformat(),
              "command": threads + shlex.join(["python", "-m", "benchmarks.bench_rbf_real",
                                               *(sys.argv[1:] if argv is None else argv)]),
              "neutral": neutral_section(corpus, observer), "accuracy": pair_accuracy(observer, corpus),
              "compare": {t: compare_theme(base, t) for t in THEME_NAMES},
              "observers": observer_section(observer, corpus, base)}
    result["ablation"] = ablation_section(observer, base, result["compare"])
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(result, indent=1, default=float) + "\n", encoding="utf-8")
    print(f"wrote {a.out}")
    if a.doc:
        print(f"{a.doc} tables:", ", ".join(doc_tables.update_doc("rbf_real", a.out, a.doc)) or "none marked")
    if a.sheets:
        for p in contact_sheets(base, corpus, a.sheets):
            print(f"wrote {p}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
