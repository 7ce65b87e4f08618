"""Contact sheet: a real captured walk of each gait emotion beside the generated walk of the same emotion.

Real: the Bandai Namco Research Motion Dataset's dataset-1 walks (real optical capture by professional actors,
CC BY-NC 4.0, Kobayashi et al. 2023, arXiv:2306.08861), styles happy, sad, angry and normal (= neutral), imported
onto our gait skeleton (``generation.mocap.import_file``). Generated: the ``gait_net`` generator of the stimulus
plans (falling back to the SYNTHETIC procedural walk when no weights are shipped), a straight 10 m walk per emotion,
same render settings. One row per motion, frames every ``--step`` seconds from 0.5 s.

Usage: python -m benchmarks.real_vs_generated_sheet [--takes DIR] [--out docs/img/real_vs_generated_gait.png]
DIR holds ``dataset-1_walk_<style>_<take>.bvh`` files (default: the shipped real subset).
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from generation.mocap.importer import ImportOptions, import_file
from generation.plans.clipgen import make_motion, resolve
from generation.plans.schema import validate_plan
from generation.render.clip import render_frames_at
from generation.render.contact_sheet import contact_sheet
from generation.render.offscreen import prepare_render_process
from generation.render.settings import RenderSettings

ROOT = Path(__file__).resolve().parents[1]

EMOTIONS = (("happy", "happy", [1, 0, 0, 0]), ("sad", "sad", [0, 1, 0, 0]), ("angry", "angry", [0, 0, 1, 0]),
            ("neutral", "normal", [0, 0, 0, 1]))


def generated_walks(seconds: float, weights: str | None = None) -> dict[str, object]:
    """emotion -> generated Motion (plan entries resolved as generate_clips resolves them; ``weights`` names the
    gait network's weights, None the default)."""
    chosen = {} if weights is None else {"weights": weights}
    plan = validate_plan({"name": "sheet", "render": {"fps": 30, "duration_s": seconds}, "clips": [
        {"id": f"gen_{emotion}", "generator": "gait_net", "fallback": "procedural_walk", "origin": "generated",
         "emotion": vector, "trajectory": {"kind": "straight", "length_m": 10}, "seed": 7, **chosen}
        for emotion, _, vector in EMOTIONS]})
    out = {}
    for entry, (emotion, _, _) in zip(plan.entries, EMOTIONS):
        run_entry, reason = resolve(entry)
        motion = make_motion(run_entry, requested=entry.generator if reason else None, fallback_reason=reason)
        out[emotion] = motion
    return out


def add_frames(rows, settings: RenderSettings, times: list[float], folder: Path, posters: list, labels: list) -> None:
    """Render each (label, Motion) of ``rows`` at ``times`` (s) into PNGs in ``folder``, appending their paths to
    ``posters`` and their captions to ``labels`` (one contact-sheet row per motion)."""
    from PIL import Image

    for label, motion in rows:
        frames = [round(t * settings.fps) for t in times]
        for t, (_, img) in zip(times, render_frames_at(motion, settings, frames)):
            p = folder / f"{len(posters):03d}.png"
            Image.fromarray(img).save(p)
            posters.append(p)
            labels.append(f"{label}, {t:.1f} s")


def main() -> None:
    prepare_render_process()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--takes", type=Path, default=ROOT / "generation" / "data" / "mocap" / "bandai-namco"
                    / "Bandai-Namco-Research-Motiondataset-1" / "data")
    ap.add_argument("--take", default="001", help="take number of the real files (default 001)")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "img" / "real_vs_generated_gait.png")
    ap.add_argument("--step", type=float, default=0.4)
    ap.add_argument("--columns", type=int, default=6)
    ap.add_argument("--weights", choices=("real", "procedural"), default=None,
                    help="gait network weights of the generated walks (default: the plans' default, real)")
    a = ap.parse_args()

    times = [0.5 + a.step * k for k in range(a.columns)]
    settings = RenderSettings(width=320, height=400, fps=30, duration_s=times[-1] + 0.2, camera="tracking")
    generated = generated_walks(settings.duration_s, a.weights)
    posters, labels = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for emotion, style, _ in EMOTIONS:
            path = a.takes / f"dataset-1_walk_{style}_{a.take}.bvh"
            real = import_file(path, ImportOptions(skeleton="gait", fps=30))
            if real.motion is None:
                raise SystemExit(f"{path}: {real.row['message']}")
            gen = generated[emotion]
            name = f"{gen.metadata.get('generator', '?')} ({gen.metadata.get('weights_name', '?')})"
            rows = ((f"REAL {style} t{a.take[-1]}", real.motion), (f"{name} {emotion}", gen))
            add_frames(rows, settings, times, Path(tmp), posters, labels)
        contact_sheet(posters, labels, a.out, columns=a.columns, thumb_width=200)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
