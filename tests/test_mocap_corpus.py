"""``python -m generation.mocap corpus``: labelled imported gait Motions -> a GaitCorpus for train_gait."""
from __future__ import annotations

import numpy as np
import pytest

from generation.mocap.cli import main
from generation.procedural.corpus import GaitCorpus
from generation.procedural.walk import WalkParams, walk
from protocol.vocabulary import GAIT_EMOTIONS
from tests.mocap_conventions import export_as


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("takes")
    for k, emotion in enumerate(GAIT_EMOTIONS * 2):
        motion = walk(WalkParams(stride_m=1.2 + 0.05 * k), n_frames=250)
        export_as(motion, "cmu", tmp / f"take{k}_{emotion}.bvh")
    export_as(walk(WalkParams(), n_frames=50), "cmu", tmp / "short_sad.bvh")
    out = tmp / "imported"
    assert main(["import", str(tmp), "--skeleton", "gait", "--out", str(out), "--quiet",
                 "--label-pattern", r"_(?P<emotion>[a-z]+)\.bvh"]) == 0
    return out


def test_corpus_from_imported_takes(tmp_path, imported):
    path = tmp_path / "captured.npz"
    code = main(["corpus", str(imported), "--out", str(path), "--frames", "120", "--stride", "60"])
    assert code == 1                                   # the short take is skipped and reported
    corpus = GaitCorpus.load(path)
    assert len(corpus) == 8 * 3 and corpus.num_frames == 120 and corpus.rotations.shape[2:] == (21, 4)
    assert corpus.metadata["synthetic"] is False and corpus.metadata["origin"] == "captured"
    assert set(corpus.path_kind) == {"captured"}
    np.testing.assert_allclose(corpus.emotion.sum(1), 1.0)
    by_file = {}
    for p, s in zip(corpus.params, corpus.split):
        by_file.setdefault(p["source"], set()).add(str(s))
    assert all(len(s) == 1 for s in by_file.values()) and len(by_file) == 8
    first = corpus.params.index({"source": "take0_happy.npz", "start_frame": 0})
    assert corpus.emotion[first].tolist() == [1.0, 0.0, 0.0, 0.0]


def test_corpus_feeds_the_gait_network_data(tmp_path, imported):
    from generation.gait.data import load_corpus_sequences
    path = tmp_path / "captured.npz"
    assert main(["corpus", str(imported), "--out", str(path), "--frames", "120"]) == 1
    data = load_corpus_sequences(path, frame_step=4, seq_len=20)
    assert data.training_data.corpus["path"] == str(path)


def test_corpus_without_labels_fails(tmp_path, imported):
    unlabelled = tmp_path / "u"
    assert main(["import", str(imported.parent / "take0_happy.bvh"), "--skeleton", "gait", "--out",
                 str(unlabelled), "--quiet"]) == 0
    assert main(["corpus", str(unlabelled), "--out", str(tmp_path / "c.npz")]) == 2
