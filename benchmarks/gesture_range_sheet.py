"""Contact sheet: generated gestures per emotion beside the real seated gesture of the closest captured emotion.

Rows: afraid, ashamed, sad, angry, joyous, proud, neutral. Columns: the real seated ``bye`` take of the closest
captured emotion (Bandai Namco dataset 1, CC BY-NC 4.0), the network's gesture of one sentence with that emotion
(``real_range: off``) and the same fitted into the real range (``real_range: closest``,
:mod:`generation.gesture.range_fit`: the amplitude factor and the shoulder angle in the caption).
Each tile: the frame of the fastest wrist movement over ghosts of the clip
(:func:`benchmarks.bench_gesture.onion_skin`), upper body; the caption gives wrist speed (mean / 90th percentile,
m/s) and reach (90th percentile, m).

    OMP_NUM_THREADS=1 python -m benchmarks.gesture_range_sheet --corpus CORPUS_WITH_BYE_TAKES \
        [--out docs/img/gesture_range_sheet.png]

CORPUS_WITH_BYE_TAKES: a real corpus holding dataset 1's ``bye`` takes (``python -m generation.mocap dataset
bandai-namco DIR --contents bye --out ...``). About 1 min on the 2-core machine.
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from benchmarks.bench_gesture import onion_skin
from generation.gesture.generate import generate_gesture
from generation.gesture.range_fit import closest_captured, fit_closest_range
from generation.gesture.real_range import load_ranges
from generation.gesture.real_stats import gesture_stats
from generation.quality.real_gestures import real_gesture_clips
from generation.render.offscreen import prepare_render_process
from protocol.vocabulary import CAPTURE_GESTURE_EMOTIONS

EMOTIONS = ("afraid", "ashamed", "sad", "angry", "joyous", "proud", "neutral")
SENTENCE = "We waited at the station for hours, and then the last train finally arrived."


def main(argv=None) -> int:
    from PIL import Image

    from generation.render.clip import render_frames
    from generation.render.contact_sheet import contact_sheet
    from generation.render.settings import RenderSettings

    prepare_render_process()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", required=True)
    ap.add_argument("--out", default="docs/img/gesture_range_sheet.png")
    a = ap.parse_args(argv)
    real = {CAPTURE_GESTURE_EMOTIONS[s]: (n, m) for n, s, m in real_gesture_clips(a.corpus, contents=("bye",))}
    captured = [k for k in load_ranges()["ranges"] if k != "all"]
    settings = RenderSettings(width=480, height=480, fps=10.0, camera="fixed", anti_aliasing="none")
    H, W = settings.height, settings.width
    tiles, labels = [], []
    with tempfile.TemporaryDirectory() as tmp:
        def tile(motion, name, label):
            m = motion.resample(10.0)
            P = m.positions()
            speed = np.linalg.norm(np.diff(P[:, [10, 14]], axis=0), axis=-1).max(1) * m.fps
            frames = [f[: int(0.72 * H), int(0.14 * W): int(0.86 * W)] for f in render_frames(m, settings)]
            path = Path(tmp) / f"{name}.png"
            Image.fromarray(onion_skin(frames, int(np.argmax(speed)) + 1)).save(path)
            s = gesture_stats(P, m.fps)
            tiles.append(path)
            labels.append(f"{label}; wrist {s['wrist_mean']:.2f}/{s['wrist_p90']:.2f} m/s, "
                          f"reach {s['reach_p90']:.2f} m")

        for emo in EMOTIONS:
            ref = closest_captured(emo, captured)
            name, motion = real[ref]
            tile(motion, f"real_{emo}", f"{emo}: REAL {ref} ({name}, seated)")
            raw = generate_gesture(SENTENCE, task="narration", emotion=emo, gender="female", handedness="right",
                                   fps=30.0, seed=0)
            tile(raw, f"raw_{emo}", f"{emo}: network")
            fitted = fit_closest_range(raw, emo)
            rec = fitted.metadata["real_range"]
            tile(fitted, f"fit_{emo}", f"{emo}: fitted x{rec['factor']:.2f}, shoulders "
                 f"{rec.get('shoulder_flexion_deg', 0.0):+.0f} deg ({'inside' if rec['inside'] else 'not'})")
        contact_sheet(tiles, labels, a.out, columns=3, thumb_width=300)
    Image.open(a.out).quantize(96).save(a.out, optimize=True)
    print("wrote", a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
