"""Contact sheet: per gait emotion, two held-out BML actors' walks beside the generated walk of that emotion.

Real: the BML walks of Emotion-Gait (Ma, Paterson & Pollick 2006; labels from STEP, AAAI 2020; research use with
citation), imported by ``python -m generation.mocap dataset emotion-gait-bml`` (root travel reconstructed from the
stance foot), actors of the held-out ``test`` split, their one-cycle loops lengthened
(:func:`generation.gait.bml_data.extend_loop`); the acted emotion, the perceived label in the caption. Generated:
the plans' ``gait_net`` generator (default weights), a straight 10 m walk per emotion, same render settings. One
row per motion, frames every ``--step`` seconds from 0.5 s.

Usage: python -m benchmarks.bml_contact_sheet [--actors BML_alx BML_jen] [--out docs/img/bml_vs_generated_gait.png]
"""
from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

from benchmarks.real_vs_generated_sheet import EMOTIONS, add_frames, generated_walks
from generation.gait.bml_data import bml_clips
from generation.mocap.real_corpus import RealCorpora
from generation.render.contact_sheet import contact_sheet
from generation.render.settings import RenderSettings

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--actors", nargs=2, default=["BML_alx", "BML_jen"])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "img" / "bml_vs_generated_gait.png")
    ap.add_argument("--step", type=float, default=0.4)
    ap.add_argument("--columns", type=int, default=6)
    a = ap.parse_args()

    times = [0.5 + a.step * k for k in range(a.columns)]
    settings = RenderSettings(width=320, height=400, fps=30, duration_s=times[-1] + 0.2, camera="tracking")
    generated = generated_walks(settings.duration_s)
    bml = RealCorpora.from_environ(os.environ).bml   # $BML_CORPUS, else var/mocap/emotion-gait-bml.npz
    real = {(c.motion.metadata["performer"], c.style): c for c in bml_clips("test", bml, n_frames=150)}
    posters, labels = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for emotion, _, _ in EMOTIONS:
            rows = []
            for actor in a.actors:
                clip = real.get((actor, emotion))
                if clip is None:
                    raise SystemExit(f"no held-out BML walk of {actor} acting {emotion}")
                rows.append((f"BML {actor[4:]} acted {emotion} (perceived {clip.motion.metadata['perceived_label']})",
                             clip.motion.resample(settings.fps)))
            gen = generated[emotion]
            rows.append((f"{gen.metadata.get('generator', '?')} ({gen.metadata.get('weights_name', '?')}) {emotion}",
                         gen))
            add_frames(rows, settings, times, Path(tmp), posters, labels)
        contact_sheet(posters, labels, a.out, columns=a.columns, thumb_width=200)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
