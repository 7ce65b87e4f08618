"""Contact sheets of seed 004's themes as a participant would see them (the mannequin renderer, tracking camera).

One PNG per theme, ``docs/img/rbf_manip_<theme>.png``: rows = the neutral base walk, a held-out real take of the
style (Bandai Namco, CC BY-NC 4.0), the calibrated edit at w = 0.7 and 1.0, the visual edit at w = 1.0; columns = 5
moments 0.25 s apart (about one stride). With ``--extended``, ``docs/img/rbf_extended_<theme>.png``: the base, the
real take, the extended edit (the default) at w = 0.7 and 1.0 and the calibrated edit (the old default) at w = 1.0.

    OMP_NUM_THREADS=1 python -m benchmarks.rbf_manipulation_sheets [--corpus var/mocap/bandai-namco.npz] \
        [--out docs/img] [--themes happy sad] [--extended]

About 40 s per theme on the 2-core machine (25 offscreen renders).
"""
from __future__ import annotations

import argparse
import tempfile
import warnings
from pathlib import Path

from generation.mocap.real_corpus import DEFAULT_PATH, load_real_corpus
from generation.rbf.calibrate import theme_styles
from generation.rbf.real_neutral import load_cycle
from generation.rbf.stylise import neutral_walk, stylise
from generation.rbf.themes import THEME_NAMES
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
    ap.add_argument("--extended", action="store_true", help="the extended set's sheets (rbf_extended_<theme>.png)")
    a = ap.parse_args(argv)
    clips = load_real_corpus(a.corpus, skeleton="gait", contents=["walk"])
    base = load_cycle()
    for theme in a.themes:
        name = f"rbf_extended_{theme}.png" if a.extended else f"rbf_manip_{theme}.png"
        print("wrote", write_sheet(theme_rows(base, clips, theme, a.extended), a.out / name))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
