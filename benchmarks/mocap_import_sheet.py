"""Contact sheet: a motion re-exported under other rigs' conventions, imported back, beside the original.

The original is a captured walk on our gait skeleton (DeepMimic's CMU/SFU-derived ``0walk_forward``, two cycles).
It is written as a Mixamo BVH and as a CMU BVH (:func:`tests.mocap_conventions.export_as`: their joint
names and extra joints, a T-pose rest pose, centimetres, their rotation orders), each file is imported back with
``generation.mocap.import_file`` (rig auto-mapping, units and up axis guessed), and the three motions are
rendered with the study's mannequin at the same frames. Each caption gives the largest joint-position difference
to the original in that frame.

Writes docs/img/mocap_import_sheet.png (one row per motion, one column per frame) and prints the errors.

Usage: python -m benchmarks.mocap_import_sheet [--out docs/img/mocap_import_sheet.png]
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from benchmarks.bench_record import one_thread
from generation.mocap import ImportOptions, import_file
from generation.mocap.captured import WALK_FILES, captured_walks, chain_clip_repeats
from generation.render.clip import render_frames_at
from generation.render.contact_sheet import contact_sheet
from generation.render.offscreen import prepare_render_process
from generation.render.settings import RenderSettings
from tests.mocap_conventions import export_as

ROOT = Path(__file__).resolve().parents[1]

CONVENTIONS = (("mixamo", "Mixamo"), ("cmu", "CMU"))
FRAMES = (0, 12, 24, 36, 48, 60)
CLIP = "0walk_forward.txt"


def original_motion():
    """The captured walk on our gait skeleton, two cycles."""
    names = [name for name, _ in WALK_FILES]
    return chain_clip_repeats(captured_walks()[names.index(CLIP)], 2)


def imported_motions(motion, folder: Path) -> list[tuple[str, object]]:
    """(label, Motion) of the motion exported under each convention and imported back."""
    out = []
    for key, name in CONVENTIONS:
        path = export_as(motion, key, folder / f"walk_{key}.bvh", centimetres=True, tpose=True)
        result = import_file(path, ImportOptions(skeleton="gait"))
        if result.motion is None:
            raise SystemExit(f"import of the {name} file failed: {result.row['message']}")
        print(f"{name}: {result.row['mapped_joints']} joints mapped, unit {result.motion.metadata['unit_guess']}, "
              f"up axis {result.motion.metadata['up_axis']}")
        out.append((f"{name} BVH (T-pose, cm) -> import", result.motion))
    return out


def main() -> None:
    one_thread()
    prepare_render_process()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "img" / "mocap_import_sheet.png")
    a = ap.parse_args()
    from PIL import Image

    original = original_motion()
    settings = RenderSettings(width=320, height=400, fps=original.fps, duration_s=original.duration,
                              camera="tracking")
    with tempfile.TemporaryDirectory() as tmp:
        rows = [("original, gait skeleton", original)] + imported_motions(original, Path(tmp))
        P0 = original.positions()
        posters, labels = [], []
        for label, motion in rows:
            P = motion.resample(original.fps).positions()
            for t, img in zip(FRAMES, (img for _, img in render_frames_at(motion, settings, FRAMES))):
                path = Path(tmp) / f"{len(posters):03d}.png"
                Image.fromarray(img).save(path)
                posters.append(path)
                err = np.linalg.norm(P[t] - P0[t], axis=-1).max() * 1000
                labels.append(f"{label}, frame {t}" + ("" if motion is original else f", diff {err:.2f} mm"))
            if motion is not original:
                n = min(len(P), len(P0))
                print(f"{label}: max joint-position difference over {n} frames "
                      f"{np.linalg.norm(P[:n] - P0[:n], axis=-1).max() * 1000:.2f} mm")
        contact_sheet(posters, labels, a.out, columns=len(FRAMES), thumb_width=240)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
