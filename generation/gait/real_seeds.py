"""Real seed walks for the real-trained gait network: a stretch of the shipped captured walk of the asked emotion.

The shipped real subset (generation/data/mocap/bandai-namco/: the Bandai Namco Research Motion Dataset, Kobayashi et
al. 2023, arXiv:2306.08861, CC BY-NC 4.0) holds dataset 1's walk take 1 in happy, sad, angry and normal. These are
training takes of the real-trained network (its held-out takes are take 2), so a fresh clone generates without the
full corpus. The seed of an emotion vector is the take of its dominant emotion (normal for neutral).
"""
from __future__ import annotations

import functools

import numpy as np

from generation.core.motion import Motion
from generation.mocap.bandai_namco import shipped_takes
from generation.mocap.importer import ImportOptions, import_file
from generation.mocap.real_corpus import CITATION, LICENCE
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS

STYLE_OF_EMOTION = {emotion: style for style, emotion in CAPTURE_GAIT_EMOTIONS.items()}
"""Gait emotion -> the dataset's style (neutral -> normal)."""


@functools.cache
def shipped_walk(style: str) -> Motion:
    """The shipped dataset-1 forward walk of ``style`` on the gait skeleton at 30 fps (imported once)."""

    takes = [t for t in shipped_takes() if t.content == "walk" and t.style == style and t.skeleton == "gait"]
    if not takes:
        raise FileNotFoundError(f"no shipped real walk of style {style!r} in generation/data/mocap/bandai-namco")
    take = min(takes, key=lambda t: t.take)
    result = import_file(take.path, ImportOptions(skeleton="gait", fps=30.0))
    if result.motion is None:
        raise ValueError(f"shipped real walk {take.path} does not import: {result.row.get('message')}")
    return result.motion


def real_seed(emotion: np.ndarray, n_frames: int, rng: np.random.Generator) -> Motion:
    """``n_frames`` consecutive frames (30 fps) of the shipped walk of the dominant emotion of ``emotion`` (4,),
    starting at a frame drawn from ``rng``; metadata ``origin`` captured, ``seed_take`` the take's name."""
    style = STYLE_OF_EMOTION[GAIT_EMOTIONS[int(np.argmax(emotion))]]
    walk = shipped_walk(style)
    if walk.num_frames < n_frames:
        raise ValueError(f"shipped real walk {style} has {walk.num_frames} frames; a seed needs {n_frames}")
    start = int(rng.integers(0, walk.num_frames - n_frames + 1))
    seed = walk.slice(start, start + n_frames)
    seed.metadata = {**walk.metadata, "origin": "captured", "seed_take": walk.metadata.get("source", style),
                     "seed_start_frame": start, "licence": LICENCE, "citation": CITATION}
    return seed
