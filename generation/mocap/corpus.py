"""Imported, labelled gait Motions -> a gait corpus for ``train_gait`` (the ``GaitCorpus`` .npz format).

Each Motion (the ``.npz`` files ``python -m generation.mocap import --skeleton gait`` writes, with an ``emotion``
label) is resampled to the corpus frame rate and cut into windows of ``frames`` frames every ``stride`` frames
(a clip shorter than one window is skipped and reported). The label vector is both ``emotion`` and
``true_emotion`` (a captured take has no separate ground truth); ``path_kind`` is ``captured``; ``params`` holds
each window's source file and first frame. Splits are 80/10/10 train/val/test by source file (all windows of a
take share one split, so a test take is never seen in training), stratified by the dominant emotion.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from generation.core.motion import Motion, MotionFormatError
from generation.procedural.corpus import GaitCorpus
from protocol.vocabulary import GAIT_EMOTIONS


def _file_splits(dominant: list[str], rng: np.random.Generator) -> list[str]:
    """80/10/10 train/val/test per dominant emotion (val and test get one when a group has 3 or more)."""
    split = ["train"] * len(dominant)
    for emotion in sorted(set(dominant)):
        idx = [i for i, d in enumerate(dominant) if d == emotion]
        rng.shuffle(idx)
        n_hold = max(1, int(round(0.1 * len(idx)))) if len(idx) >= 3 else 0
        for i in idx[:n_hold]:
            split[i] = "test"
        for i in idx[n_hold:2 * n_hold]:
            split[i] = "val"
    return split


def build_captured_gait_corpus(motions: list[tuple[str, Motion]], frames: int = 240, fps: float = 30.0,
                               stride: int | None = None, seed: int = 0) -> tuple[GaitCorpus, list[str]]:
    """Windows of labelled gait Motions as a GaitCorpus.

    Args:
        motions: (name, Motion on the 21-joint gait skeleton with ``metadata["emotion"]`` {emotion: weight}).
        frames: window length T; fps: corpus frame rate; stride: frames between window starts (default T).
        seed: for the split.

    Returns:
        (corpus, problems): one message per skipped Motion (wrong skeleton, no label, too short).

    Raises:
        ValueError: when no Motion gives a window.
    """
    stride = int(stride or frames)
    if frames < 2 or stride < 1:
        raise ValueError(f"frames must be >= 2 and stride >= 1, got {frames}, {stride}")
    problems, used = [], []
    for name, m in motions:
        label = m.metadata.get("emotion")
        if m.skeleton.name != "gait" or m.skeleton.num_joints != 21:
            problems.append(f"{name}: not on the gait skeleton ({m.skeleton.name!r}); import with --skeleton gait")
        elif not isinstance(label, dict) or set(label) != set(GAIT_EMOTIONS):
            problems.append(f"{name}: no gait emotion label (metadata 'emotion'); import with --labels or "
                            f"--label-pattern")
        else:
            m = m.resample(fps)
            if m.num_frames < frames:
                problems.append(f"{name}: {m.num_frames} frames at {fps:g} fps, shorter than one window ({frames})")
            else:
                vec = np.array([float(label[e]) for e in GAIT_EMOTIONS])
                used.append((name, m, vec / vec.sum()))
    if not used:
        raise ValueError("no labelled gait Motion long enough for one window:\n" + "\n".join(problems))
    rng = np.random.default_rng(seed)
    file_split = _file_splits([GAIT_EMOTIONS[int(np.argmax(v))] for _, _, v in used], rng)
    rot, root, emo, split, height, build, params = [], [], [], [], [], [], []
    for (name, m, vec), s in zip(used, file_split):
        for start in range(0, m.num_frames - frames + 1, stride):
            rot.append(m.rotations[start:start + frames])
            root.append(m.root_positions[start:start + frames])
            emo.append(vec)
            split.append(s)
            height.append(m.skeleton.height)
            build.append(m.skeleton.build)
            params.append({"source": name, "start_frame": start})
    N = len(rot)
    corpus = GaitCorpus(
        rotations=np.array(rot, dtype=np.float32), root_positions=np.array(root, dtype=np.float32),
        emotion=np.array(emo), true_emotion=np.array(emo), split=np.array(split), path_kind=np.full(N, "captured"),
        height=np.array(height, dtype=np.float64), build=np.array(build), params=params, fps=fps, seed=seed,
        metadata={"synthetic": False, "origin": "captured", "sources": [n for n, _, _ in used],
                  "frames": frames, "stride": stride, "fps": fps, "emotions": list(GAIT_EMOTIONS)})
    return corpus.validate("captured gait corpus"), problems


def load_motions(paths) -> tuple[list[tuple[str, Motion]], list[str]]:
    """Motion .npz files from files and folders (recursive, sorted); unreadable ones become problem messages."""
    files = []
    for given in paths:
        p = Path(given)
        files += sorted(p.rglob("*.npz")) if p.is_dir() else [p]
    motions, problems = [], []
    for f in files:
        try:
            motions.append((f.name, Motion.load_npz(f)))
        except MotionFormatError as exc:
            problems.append(str(exc))
    return motions, problems
