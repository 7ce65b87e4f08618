"""The real captured gestures that generated ones are measured against: dataset-1 gesture takes of the real-capture
corpus seated on the chair, their statistics, and their per-emotion ranges for the training loss.

    python -m generation.quality.real_gestures                  # print each real take's statistics
    python -m generation.quality.real_gestures --write-ranges   # and write generation/data/gesture_real_ranges.json

Real clips: the Bandai Namco Research Motion Dataset 1's bow, bye, byebye and guide takes (one take per content and
style; Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0), from the real corpus
(``--corpus``, else ``$REAL_CORPUS``, else ``var/mocap/bandai-namco.npz``), seated with
:func:`generation.mocap.seated_gesture.seat_gesture`, measured with :func:`generation.gesture.real_stats.motion_stats`
and labelled with the gesture emotion their style names (``protocol.vocabulary.CAPTURE_GESTURE_EMOTIONS``).
"""
from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from generation.core.motion import Motion
from generation.gesture.real_stats import RANGES_FILE, STAT_NAMES, STATS_FPS, motion_stats, real_ranges
from generation.mocap.real_corpus import CITATION, LICENCE, load_real_corpus, real_corpus_path
from generation.mocap.seated_gesture import seat_gesture
from protocol.vocabulary import CAPTURE_GESTURE_EMOTIONS

REAL_CONTENTS = ("bow", "bye", "byebye", "guide")


def real_gesture_clips(path=None, contents=REAL_CONTENTS, styles=None, split=None) -> list[tuple[str, str, Motion]]:
    """(name, style, seated Motion) of the real corpus's dataset-1 gesture takes of ``contents`` in ``styles``
    (default: the styles that name a gesture emotion), seated on the chair. Needs the real corpus at ``path``
    (default ``var/mocap/bandai-namco.npz``, :data:`generation.mocap.real_corpus.DEFAULT_PATH`)."""
    styles = tuple(CAPTURE_GESTURE_EMOTIONS) if styles is None else tuple(styles)
    clips = load_real_corpus(path, skeleton="gesture", contents=contents, styles=styles, split=split)
    return [(c.name, c.style, seat_gesture(c.motion)) for c in clips if c.dataset == "bandai-namco-1"]


def real_stats_table(clips: list[tuple[str, str, Motion]]) -> list[dict]:
    """One row per real clip: name, style, emotion (or None) and its statistics at STATS_FPS."""
    return [{"name": n, "style": s, "emotion": CAPTURE_GESTURE_EMOTIONS.get(s), **motion_stats(m)}
            for n, s, m in clips]


def write_ranges(path: str | Path, rows: list[dict]) -> dict:
    """Write the per-emotion real ranges of ``rows`` (:func:`real_stats_table`) as JSON to ``path``; returns it."""
    data = {"ranges": {k: {s: [round(a, 5), round(b, 5)] for s, (a, b) in v.items()}
                       for k, v in real_ranges(rows).items()},
            "takes": {r["name"]: r["emotion"] for r in rows}, "fps": STATS_FPS,
            "source": "Bandai Namco Research Motion Dataset 1, gesture takes (bow, bye, byebye, guide) in the styles "
                      "happy, sad, angry, proud, normal, seated (generation.mocap.seated_gesture); min and max over "
                      "the takes of each emotion; 'all' over every take",
            "licence": LICENCE, "citation": CITATION,
            "written_by": "python -m generation.quality.real_gestures --write-ranges"}
    Path(path).write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    return data


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description="Statistics of the real captured gestures, seated (per take); "
                                            "--write-ranges stores the per-emotion ranges for training.")
    p.add_argument("--corpus", type=Path, default=real_corpus_path(os.environ),
                   help="real-capture corpus (default: $REAL_CORPUS, else var/mocap/bandai-namco.npz)")
    p.add_argument("--write-ranges", action="store_true", help=f"write {RANGES_FILE}")
    args = p.parse_args(argv)
    rows = real_stats_table(real_gesture_clips(args.corpus))
    for r in rows:
        print(r["name"], r["emotion"], " ".join(f"{k}={r[k]:.3f}" for k in STAT_NAMES))
    if args.write_ranges:
        write_ranges(RANGES_FILE, rows)
        print(f"ranges of {len(rows)} takes -> {RANGES_FILE}")


if __name__ == "__main__":
    main()
