"""Contact sheets of seed 004's themes as a participant would see them (the mannequin renderer, tracking camera).

One PNG per theme, ``docs/img/rbf_manip_<theme>.png``: rows = the neutral base walk, a held-out real take of the
style (Bandai Namco, CC BY-NC 4.0), the calibrated edit at w = 0.7 and 1.0, the visual edit at w = 1.0; columns = 5
moments 0.25 s apart (about one stride). With ``--extended``, ``docs/img/rbf_extended_<theme>.png``: the base, the
real take, the extended edit (the default) at w = 0.7 and 1.0 and the calibrated edit (the old default) at w = 1.0.
With ``--actors``, ``docs/img/rbf_actors_<theme>.png``: the base and the extended edit at w = 1.0 (for happy and sad
also the pooled edit, sized on Bandai and BML together) beside real walks of the style by several actors: Bandai
takes of the style from both datasets (held-out first) and, for happy and sad,
BML actors' walks of that emotion (``--bml``; research use with citation, docs/mocap.md).

    OMP_NUM_THREADS=1 python -m benchmarks.rbf_manipulation_sheets [--corpus var/mocap/bandai-namco.npz] \
        [--out docs/img] [--themes happy sad] [--extended | --actors [--bml var/mocap/emotion-gait-bml.npz]]

About 40 s per theme on the 2-core machine (25 offscreen renders).
"""
from __future__ import annotations

import argparse
import tempfile
import warnings
from pathlib import Path

from generation.mocap.real_corpus import DEFAULT_BML_PATH, DEFAULT_PATH, load_real_corpus
from generation.rbf.calibrate import theme_styles
from generation.rbf.real_neutral import load_cycle
from generation.rbf.stylise import neutral_walk, stylise
from generation.rbf.themes import POOLED_PATH, THEME_NAMES, extended_sources
from generation.render.offscreen import prepare_render_process

TIMES = [0.5 + 0.25 * k for k in range(5)]


def theme_rows(base, clips, theme: str, extended: bool = False) -> list[tuple[str, object]]:
    """(label, motion) rows of one theme's sheet (``extended``: the extended set's sheet)."""
    real = next(c for c in sorted(clips, key=lambda c: (c.dataset, c.take))
                if c.split != "train" and c.style in theme_styles(theme) and c.motion.num_frames >= 60)
    kw = {"n_cycles": 3, "fps": 30.0}
    if extended:
        return [("base (real average)", neutral_walk(base, **kw)),
                (f"REAL {real.style} {real.dataset[-1]}/{real.take}", real.motion),
                (f"{theme} extended w0.7", stylise(base, theme, 0.7, 10, intensities="extended", **kw)),
                (f"{theme} extended w1.0", stylise(base, theme, 1.0, 10, intensities="extended", **kw)),
                (f"{theme} calibrated w1.0", stylise(base, theme, 1.0, 10, intensities="calibrated", **kw))]
    return [("base (real average)", neutral_walk(base, **kw)),
            (f"REAL {real.style} {real.dataset[-1]}/{real.take}", real.motion),
            (f"{theme} calibrated w0.7", stylise(base, theme, 0.7, 10, intensities="calibrated", **kw)),
            (f"{theme} calibrated w1.0", stylise(base, theme, 1.0, 10, intensities="calibrated", **kw)),
            (f"{theme} visual w1.0", stylise(base, theme, 1.0, 10, intensities="visual", **kw))]


def actor_rows(base, clips, bml, theme: str, n_real: int = 4) -> list[tuple[str, object]]:
    """(label, motion) rows of one theme's sheet beside several actors: the base, the extended edit at w = 1.0 (and
    the pooled one where the pooled set sizes the theme on more than one source), then up to ``n_real`` real walks
    of the style: for happy and sad, BML actors (every seventh performer, so the
    rows are different people) and one Bandai take; otherwise Bandai takes alternating between the datasets."""
    kw = {"n_cycles": 3, "fps": 30.0}
    rows = [("base (real average)", neutral_walk(base, **kw)),
            (f"{theme} extended w1.0", stylise(base, theme, 1.0, 10, **kw))]
    if extended_sources(theme, POOLED_PATH):
        rows.append((f"{theme} pooled w1.0", stylise(base, theme, 1.0, 10, intensities="pooled", **kw)))
    takes = sorted((c for c in clips if c.style in theme_styles(theme) and c.motion.num_frames >= 60),
                   key=lambda c: (c.split == "train", c.take, c.dataset))
    by_dataset = [[c for c in takes if c.dataset == d] for d in sorted({c.dataset for c in takes})]
    bandai = [c for group in zip(*by_dataset) for c in group] if len(by_dataset) > 1 else takes
    bandai += [c for c in takes if c not in bandai]
    emotion = [c for c in bml if c.style == theme]
    actors = sorted(emotion, key=lambda c: c.motion.metadata.get("performer", c.name))[::7]
    real = [(f"REAL BML {c.motion.metadata.get('performer', c.name).removeprefix('BML_')} {theme}", c.motion)
            for c in actors]
    real = real[:n_real - 1] if bandai else real[:n_real]
    real += [(f"REAL {c.style} {c.dataset[-1]}/{c.take}", c.motion) for c in bandai[:n_real - len(real)]]
    return rows + real


def write_sheet(rows, path: Path) -> Path:
    from PIL import Image

    from generation.render.clip import render_frames_at
    from generation.render.contact_sheet import contact_sheet
    from generation.render.settings import RenderSettings

    settings = RenderSettings(width=320, height=400, fps=30, duration_s=TIMES[-1] + 0.2, camera="tracking")
    wanted = [int(round(t * settings.fps)) for t in TIMES]
    posters, labels = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for label, motion in rows:
            for k, img in render_frames_at(motion, settings, wanted):
                p = Path(tmp) / f"{len(posters):03d}.png"
                Image.fromarray(img).save(p)
                posters.append(p)
                labels.append(f"{label}, {k / settings.fps:.2f} s")
        contact_sheet(posters, labels, path, columns=len(TIMES), thumb_width=170)
    Image.open(path).quantize(96).save(path, optimize=True)
    return path


def main(argv=None) -> int:
    prepare_render_process()
    warnings.filterwarnings("ignore", message="The given NumPy array is not writable")
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", type=Path, default=DEFAULT_PATH)
    ap.add_argument("--out", type=Path, default=Path("docs/img"))
    ap.add_argument("--themes", nargs="*", default=list(THEME_NAMES), choices=list(THEME_NAMES))
    kind = ap.add_mutually_exclusive_group()
    kind.add_argument("--extended", action="store_true", help="the extended set's sheets (rbf_extended_<theme>.png)")
    kind.add_argument("--actors", action="store_true",
                      help="the extended edit beside real walks by several actors (rbf_actors_<theme>.png)")
    ap.add_argument("--bml", type=Path, default=DEFAULT_BML_PATH,
                    help="the BML walks for happy and sad with --actors (skipped when the file is missing)")
    a = ap.parse_args(argv)
    clips = load_real_corpus(a.corpus, skeleton="gait", contents=["walk"])
    base = load_cycle()
    if a.actors:
        bml = load_real_corpus(a.bml, skeleton="gait") if a.bml.is_file() else []
        for theme in a.themes:
            print("wrote", write_sheet(actor_rows(base, clips, bml, theme), a.out / f"rbf_actors_{theme}.png"))
        return 0
    for theme in a.themes:
        name = f"rbf_extended_{theme}.png" if a.extended else f"rbf_manip_{theme}.png"
        print("wrote", write_sheet(theme_rows(base, clips, theme, a.extended), a.out / name))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
