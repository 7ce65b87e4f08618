"""A gesture corpus for the gesture network (seed 003) from imported gesture Motions and the sentences spoken.

    python -m generation.mocap corpus imported_gestures/ --skeleton gesture --sentences sentences.csv \
        --out var/corpus/captured_gestures.npz
    python manage.py train_gesture --corpus var/corpus/captured_gestures.npz ...

Seed 003 trains on text + captured gestures (the MPI Emotional Body Expressions database: each take is an actor
narrating or conversing one sentence with one of 11 emotions). The sentences CSV pairs each take with its text:
columns ``source`` (the imported .npz's name or stem, or the original file's name or stem), ``sentence``,
``task`` (``protocol.vocabulary.GESTURE_TASKS``) and optionally ``handedness`` (default right). The emotion is the
take's label (``emotion_label`` metadata, from ``import --labels`` / ``--label-pattern``); the body build is the
skeleton's (``import --build``). Takes are resampled to the network's frame rate
(``generation.gesture.config.TRAIN_FPS``) and cut to its longest gesture (``MAX_SECONDS``).

The file holds the arrays the training corpus is assembled from (:func:`load_gesture_corpus` ->
``generation.gesture.data.GestureDataset``, split 80/10/10 by sentence within each emotion as the synthetic corpus):
``sentence_id, emotion, task, sentence, gender, handedness`` (N,), ``lengths`` (N,), ``rotations`` (N, T, 23, 4)
float32 padded with the last frame, ``fps`` and ``metadata`` (JSON: origin captured, synthetic false, sources).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from generation.core.quaternion import np_qfix, np_qnormalize
from generation.gesture import config
from generation.gesture.text import cached_encodings
from protocol.vocabulary import GESTURE_TASKS, GESTURE_VAD, HANDEDNESS

from .labels import LabelError, open_csv

CSV_COLUMNS = ("source", "sentence", "task")


def read_sentences(path: str | Path) -> dict[str, dict]:
    """{source: {"sentence", "task", "handedness"}} from a sentences CSV; LabelError names the file and line."""
    path, reader, cols = open_csv(path)
    if any(c not in cols for c in CSV_COLUMNS):
        raise LabelError(f"{path}: line 1: need the columns {', '.join(CSV_COLUMNS)} (and optionally handedness); "
                         f"found {', '.join(cols) or 'no header'}")
    out: dict[str, dict] = {}
    for row in reader:
        ln = reader.line_num
        source, sentence = (row.get("source") or "").strip(), (row.get("sentence") or "").strip()
        task = (row.get("task") or "").strip().lower()
        hand = (row.get("handedness") or "right").strip().lower()
        if not source or not sentence:
            raise LabelError(f"{path}: line {ln}: empty 'source' or 'sentence'")
        if task not in GESTURE_TASKS:
            raise LabelError(f"{path}: line {ln}: task {task!r} is not one of {', '.join(GESTURE_TASKS)}")
        if hand not in HANDEDNESS:
            raise LabelError(f"{path}: line {ln}: handedness {hand!r} is not one of {', '.join(HANDEDNESS)}")
        if source in out:
            raise LabelError(f"{path}: line {ln}: {source!r} appears twice")
        out[source] = {"sentence": sentence, "task": task, "handedness": hand}
    return out


def _sentence_for(sentences: dict, name: str, motion) -> dict | None:
    original = str(motion.metadata.get("source", ""))
    for key in (name, Path(name).stem, original, Path(original).stem):
        if key and key in sentences:
            return sentences[key]
    return None


def build_gesture_corpus(named_motions, sentences: dict) -> tuple[dict, list[str]]:
    """Arrays of the gesture corpus (module docstring) from [(file name, Motion)] and :func:`read_sentences`.

    Returns (arrays, skipped: one message per Motion left out: not on the gesture skeleton, no gesture emotion
    label, no sentence). ValueError when none is left."""

    fps, max_frames = config.TRAIN_FPS, int(round(config.MAX_SECONDS * config.TRAIN_FPS))
    keep, skipped = [], []
    for name, motion in named_motions:
        label = motion.metadata.get("emotion_label")
        text = _sentence_for(sentences, name, motion)
        if motion.skeleton.name != "gesture":
            skipped.append(f"{name}: on the {motion.skeleton.name} skeleton, not gesture")
        elif label not in GESTURE_VAD:
            skipped.append(f"{name}: no gesture emotion label (import with --labels or --label-pattern)")
        elif text is None:
            skipped.append(f"{name}: no row in the sentences CSV")
        else:
            rot = np_qfix(np_qnormalize(motion.resample(fps).rotations[:max_frames])).astype(np.float32)
            keep.append((name, motion, label, text, rot))
    if not keep:
        raise ValueError("no imported gesture take has both a gesture emotion label and a sentence")
    lengths = np.array([len(k[4]) for k in keep], dtype=np.int64)
    rotations = np.zeros((len(keep), int(lengths.max()), keep[0][4].shape[1], 4), dtype=np.float32)
    for n, (*_, rot) in enumerate(keep):
        rotations[n, :len(rot)], rotations[n, len(rot):] = rot, rot[-1]
    arrays = {
        "sentence_id": np.array([Path(k[0]).stem for k in keep]), "emotion": np.array([k[2] for k in keep]),
        "task": np.array([k[3]["task"] for k in keep]), "sentence": np.array([k[3]["sentence"] for k in keep]),
        "gender": np.array([k[1].skeleton.build for k in keep]),
        "handedness": np.array([k[3]["handedness"] for k in keep]), "lengths": lengths, "rotations": rotations,
        "fps": np.float64(fps),
        "metadata": json.dumps({"origin": "captured", "synthetic": False, "sources": [k[0] for k in keep],
                                "cropped_to_s": config.MAX_SECONDS}),
    }
    return arrays, skipped


def save_gesture_corpus(arrays: dict, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, **arrays)
    return path


def load_gesture_corpus(path: str | Path, seed: int = 0, cache_dir: str | Path | None = None):
    """A ``generation.gesture.data.GestureDataset`` from a corpus file (sentence tokens cached next to the synthetic
    corpus's, in ``cache_dir`` or the gesture package's var folder). ValueError names a bad file."""
    from generation.gesture.data import SentenceRow, assemble_dataset, split_sentences  # heavy: torch

    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as f:
            a = {k: f[k] for k in f.files}
    except (OSError, ValueError) as exc:
        raise ValueError(f"{path}: not a readable gesture corpus ({exc})") from None
    missing = [k for k in ("sentence_id", "emotion", "task", "sentence", "gender", "handedness", "lengths",
                           "rotations", "fps") if k not in a]
    if missing:
        raise ValueError(f"{path}: not a gesture corpus of `python -m generation.mocap corpus --skeleton gesture` "
                         f"(missing {', '.join(missing)})")
    rows = [SentenceRow(str(i), str(e), str(t), str(s))
            for i, e, t, s in zip(a["sentence_id"], a["emotion"], a["task"], a["sentence"])]
    cache = Path(cache_dir) if cache_dir is not None else config.DEFAULT_VAR_DIR
    encodings = cached_encodings([r.sentence for r in rows], cache / "captured_sentence_tokens.npz")
    pairs = {"sentence_index": np.arange(len(rows)), "emotion": a["emotion"].astype(str),
             "gender": a["gender"].astype(str), "handedness": a["handedness"].astype(str),
             "lengths": a["lengths"], "rotations": a["rotations"]}
    return assemble_dataset(pairs, rows, encodings, split_sentences(rows, seed), float(a["fps"]))
