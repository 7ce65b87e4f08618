"""The real-capture corpus file: save/load round trip, filters, default path and bad input."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from generation.core.motion import Motion, MotionFormatError
from generation.core.skeleton import gait_skeleton, gesture_skeleton
from generation.mocap import real_corpus as rc
from protocol.vocabulary import capture_label


def _motion(skeleton, frames, seed):
    """A synthetic motion: random unit quaternions and a drifting root (values, not realism, are checked)."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(frames, skeleton.num_joints, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    root = np.cumsum(rng.normal(scale=0.01, size=(frames, 3)), axis=0) + [0, 0.9, 0]
    return Motion(skeleton, q, root, 30.0, {"origin": "captured", "source": f"synthetic-{seed}.bvh"})


def _clips():
    gait, gesture = gait_skeleton(1.75, "male"), gesture_skeleton(1.75, "male")
    spec = [("dataset-1_walk_happy_001", "bandai-namco-1", "walk", "happy", 1, "train", gait, 40),
            ("dataset-1_bow_sad_001", "bandai-namco-1", "bow", "sad", 1, "test", gesture, 25),
            ("dataset-1_walk_happy_002", "bandai-namco-1", "walk", "happy", 2, "test", gait, 31),
            ("dataset-2_walk_exhausted_007", "bandai-namco-2", "walk", "exhausted", 7, "val", gait, 17),
            ("dataset-2_wave-left-hand_normal_003", "bandai-namco-2", "wave-left-hand", "normal", 3, "train",
             gesture, 12)]
    return [rc.CorpusClip(n, d, c, s, capture_label(s), t, sp, sk.name, _motion(sk, f, i), 0.5 + i, 1.7, f"/x/{n}.bvh")
            for i, (n, d, c, s, t, sp, sk, f) in enumerate(spec)]


def test_round_trip_keeps_every_clip_in_order(tmp_path):
    clips = _clips()
    path = rc.save_real_corpus(tmp_path / "sub" / "corpus.npz", clips, {"split_rule": "synthetic rule"})
    loaded = rc.load_real_corpus(path)
    assert [c.name for c in loaded] == [c.name for c in clips]
    for a, b in zip(clips, loaded):
        assert (a.dataset, a.content, a.style, a.label, a.take, a.split, a.skeleton, a.source) == \
               (b.dataset, b.content, b.style, b.label, b.take, b.split, b.skeleton, b.source)
        assert b.motion.skeleton.joints == a.motion.skeleton.joints
        np.testing.assert_allclose(b.motion.skeleton.offsets, a.motion.skeleton.offsets)
        np.testing.assert_allclose(b.motion.rotations, a.motion.rotations, atol=1e-6)
        np.testing.assert_allclose(b.motion.root_positions, a.motion.root_positions, atol=1e-6)
        assert b.motion.fps == 30.0 and b.import_error_cm == pytest.approx(a.import_error_cm)
        md = b.motion.metadata
        assert md["captured"] is True and md["licence"] == "CC BY-NC 4.0" and "2306.08861" in md["citation"]
        assert md["take"] == a.take and md["dataset"] == a.dataset and md["source"] == a.motion.metadata["source"]
    meta = rc.read_meta(path)
    assert meta["split_rule"] == "synthetic rule" and meta["skeletons"]["gait"] == {"height": 1.75, "build": "male"}


def test_file_layout_follows_the_contract(tmp_path):
    path = rc.save_real_corpus(tmp_path / "c.npz", _clips(), {})
    data = np.load(path)
    assert data["gait_rotations"].dtype == np.float32 and data["gait_rotations"].shape == (40 + 31 + 17, 21, 4)
    assert data["gait_root_positions"].shape == (88, 3)
    assert data["gait_starts"].tolist() == [0, 40, 71, 88] and data["gesture_starts"].tolist() == [0, 25, 37]
    rows = json.loads(str(data["clips_json"]))
    assert set(rc.CLIP_FIELDS) <= set(rows[0]) and rows[1]["frames"] == 25


def test_filters(tmp_path):
    path = rc.save_real_corpus(tmp_path / "c.npz", _clips(), {})
    assert [c.name for c in rc.load_real_corpus(path, skeleton="gesture")] == [
        "dataset-1_bow_sad_001", "dataset-2_wave-left-hand_normal_003"]
    assert [c.take for c in rc.load_real_corpus(path, skeleton="gait", split="test")] == [2]
    assert len(rc.load_real_corpus(path, split=("train", "val"))) == 3
    assert [c.label for c in rc.load_real_corpus(path, styles=["exhausted", "normal"])] == ["tired", "neutral"]
    assert rc.load_real_corpus(path, contents="walk", styles="sad") == []
    with pytest.raises(ValueError, match="split"):
        rc.load_real_corpus(path, split="training")
    with pytest.raises(ValueError, match="skeleton"):
        rc.load_real_corpus(path, skeleton="hands")


def test_nan_measures_and_default_path(tmp_path, monkeypatch):
    clips = _clips()[:1]
    clips[0].import_error_cm = math.nan
    path = rc.save_real_corpus(tmp_path / "c.npz", clips, {})
    assert math.isnan(rc.load_real_corpus(path)[0].import_error_cm)
    default = rc.REPO_ROOT / "var" / "mocap" / "bandai-namco.npz"
    # the variable counts only where an edge passes its environment; the library never reads it
    monkeypatch.setenv("REAL_CORPUS", str(path))
    assert rc.real_corpus_path() == default == rc.DEFAULT_PATH
    assert rc.real_corpus_path({"REAL_CORPUS": str(path)}) == path
    assert rc.real_corpus_path({"REAL_CORPUS": ""}) == default
    assert rc.RealCorpora.from_environ({"REAL_CORPUS": str(path)}) == rc.RealCorpora(path, rc.DEFAULT_BML_PATH)
    assert rc.RealCorpora.from_environ({"BML_CORPUS": "b.npz"}) == rc.RealCorpora(default, Path("b.npz"))
    assert rc.RealCorpora.of(None, "") == rc.RealCorpora() == rc.DEFAULT_CORPORA


def test_bad_input(tmp_path):
    with pytest.raises(FileNotFoundError, match="dataset bandai-namco"):
        rc.load_real_corpus(tmp_path / "none.npz")
    np.savez(tmp_path / "other.npz", x=np.zeros(2))
    with pytest.raises(MotionFormatError, match="clips_json"):
        rc.load_real_corpus(tmp_path / "other.npz")
    clip = _clips()[0]
    clip.skeleton = "gesture"
    with pytest.raises(ValueError, match="gait"):
        rc.save_real_corpus(tmp_path / "bad.npz", [clip], {})
    clips = _clips()
    clips[2].motion = _motion(gait_skeleton(1.60, "female"), 5, 9)
    with pytest.raises(ValueError, match="one skeleton per kind"):
        rc.save_real_corpus(tmp_path / "bad.npz", clips, {})
