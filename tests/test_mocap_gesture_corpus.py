"""Imported gesture takes + their sentences -> a corpus for the gesture network, and both training commands
(``manage.py train_gait --corpus``, ``manage.py train_gesture --corpus``) on tiny imported corpora."""
from __future__ import annotations

import csv

import numpy as np
import pytest
from django.core.management import call_command

from generation.core.skeleton import gesture_skeleton
from generation.mocap.cli import main
from generation.procedural.emotion import gesture_params_for_vad
from generation.procedural.gesture import seated_gesture
from protocol.vocabulary import GAIT_EMOTIONS, GESTURE_TASKS, GESTURE_VAD
from tests.mocap_conventions import export_as

EMOTIONS = ("proud", "sad", "afraid", "joyous")


@pytest.fixture(scope="module")
def gesture_takes(tmp_path_factory):
    """Eight procedural seated gestures (SYNTHETIC stand-ins for captured takes) exported as Mixamo BVH files,
    imported with their emotion from the file name, and a sentences CSV for seven of them."""
    d = tmp_path_factory.mktemp("gestures")
    (d / "takes").mkdir()
    rng = np.random.default_rng(0)
    rows = []
    for k in range(8):
        emotion = EMOTIONS[k % len(EMOTIONS)]
        params = gesture_params_for_vad(*GESTURE_VAD[emotion], rng)
        build = ("female", "male")[k % 2]
        motion = seated_gesture(params, 90 + 10 * k, 30.0, gesture_skeleton(build=build), seed=k)
        export_as(motion, "mixamo", d / "takes" / f"take{k}_{emotion}.bvh")
        if k != 7:
            rows.append({"source": f"take{k}_{emotion}.bvh", "sentence": f"Sentence number {k} said with feeling.",
                         "task": GESTURE_TASKS[k % 2]})
    with open(d / "sentences.csv", "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=["source", "sentence", "task"])
        w.writeheader()
        w.writerows(rows)
    assert main(["import", str(d / "takes"), "--skeleton", "gesture", "--out", str(d / "imported"), "--quiet",
                 "--label-pattern", r"_(?P<emotion>[a-z]+)\.bvh"]) == 0
    return d


def test_gesture_corpus_from_imported_takes(gesture_takes, tmp_path):
    from generation.gesture import config
    from generation.mocap.gesture_corpus import load_gesture_corpus

    out = tmp_path / "gestures.npz"
    code = main(["corpus", str(gesture_takes / "imported"), "--skeleton", "gesture", "--sentences",
                 str(gesture_takes / "sentences.csv"), "--out", str(out)])
    assert code == 1                                   # take7 has no sentence: skipped and reported
    with np.load(out) as f:
        assert len(f["lengths"]) == 7 and f["rotations"].shape[2:] == (23, 4) and float(f["fps"]) == config.TRAIN_FPS
        assert sorted(set(f["emotion"])) == sorted(EMOTIONS) and set(f["gender"]) == {"male"}  # import --build
    data = load_gesture_corpus(out, cache_dir=tmp_path)
    assert len(data) == 7 and data.tokens.shape[2] == 384
    assert data.row(0).sentence == "Sentence number 0 said with feeling." and data.emotion[0] == "proud"


def test_gesture_corpus_errors(gesture_takes, tmp_path):
    assert main(["corpus", str(gesture_takes / "imported"), "--skeleton", "gesture", "--out",
                 str(tmp_path / "x.npz")]) == 2                                     # no --sentences
    bad = tmp_path / "bad.csv"
    bad.write_text("source,sentence,task\ntake0_proud.bvh,Hello there,singing\n", encoding="utf-8")
    assert main(["corpus", str(gesture_takes / "imported"), "--skeleton", "gesture", "--sentences", str(bad),
                 "--out", str(tmp_path / "x.npz")]) == 2


@pytest.mark.django_db
def test_train_gesture_on_an_imported_corpus(gesture_takes, tmp_path):
    corpus = tmp_path / "gestures.npz"
    main(["corpus", str(gesture_takes / "imported"), "--skeleton", "gesture", "--sentences",
          str(gesture_takes / "sentences.csv"), "--out", str(corpus)])
    weights = tmp_path / "gesture.pt"
    call_command("train_gesture", corpus=str(corpus), epochs=1, out=str(weights), device="cpu", quiet=True,
                 checkpoint=str(tmp_path / "gesture.ckpt"), threads=1)
    assert weights.is_file() and weights.stat().st_size > 0


@pytest.mark.django_db
def test_train_gait_on_an_imported_corpus(tmp_path):
    from generation.procedural.walk import WalkParams, walk

    takes = tmp_path / "takes"
    takes.mkdir()
    for k, emotion in enumerate(GAIT_EMOTIONS * 2):
        export_as(walk(WalkParams(stride_m=1.2 + 0.05 * k), n_frames=280), "cmu", takes / f"t{k}_{emotion}.bvh")
    assert main(["import", str(takes), "--skeleton", "gait", "--out", str(tmp_path / "imp"), "--quiet",
                 "--label-pattern", r"_(?P<emotion>[a-z]+)\.bvh"]) == 0
    corpus = tmp_path / "gait.npz"
    # windows of 240 frames: the network reads 60 steps every 4th frame (seed 000 section 5.1)
    assert main(["corpus", str(tmp_path / "imp"), "--out", str(corpus), "--frames", "240", "--stride", "20"]) == 0
    weights = tmp_path / "gait.pt"
    call_command("train_gait", corpus=str(corpus), epochs=1, out=str(weights), device="cpu", quiet=True,
                 checkpoint=str(tmp_path / "gait.ckpt"), threads=1)
    assert weights.is_file() and weights.stat().st_size > 0
