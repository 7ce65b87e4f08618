"""Soft labels from norms: clip_norms.csv's perceived shares of rated walks as the gait network's emotion targets,
the weights recording the norms they learned from, and bad input named by file, line and column. Tiny: two
SIMULATED norms rows on two procedural walks, a tiny network, one epoch."""
from __future__ import annotations

import dataclasses
import hashlib

import numpy as np
import pandas as pd
import pytest
import torch

from generation.core.paths import straight
from generation.gait.config import GaitDataConfig
from generation.gait.soft_labels import SoftLabelError, load_soft_label_sequences, read_soft_labels
from generation.gait.train import main
from generation.plans.clipgen import write_motion_bvh
from generation.procedural.walk import WalkParams, walk
from protocol.vocabulary import CLIP_NORMS_COLUMNS, GAIT_EMOTIONS

SHARES = {"sim-walk-a": (0.6, 0.1, 0.1, 0.2), "sim-walk-b": (0.05, 0.7, 0.05, 0.2)}


@pytest.fixture
def rated(tmp_path):
    motions = tmp_path / "media" / "motions"
    rows = []
    for i, (clip_id, shares) in enumerate(SHARES.items()):
        m = walk(WalkParams(cadence_spm=100 + 10 * i), straight(12.0), 260, 30.0)
        write_motion_bvh(m, motions, clip_id)
        rows.append({"clip_id": clip_id, "modality": "gait", "section_type": "emotion_choice",
                     "question": "perceived", "n_ratings": 20 + i, "intended": "", "top_label": "happy",
                     "top_share": max(shares), **{c: "" for c in CLIP_NORMS_COLUMNS[8:]},
                     **{f"share_{e}": v for e, v in zip(GAIT_EMOTIONS, shares)}})
    folder = tmp_path / "pilot-study"
    folder.mkdir()
    df = pd.DataFrame(rows)[[*CLIP_NORMS_COLUMNS, *[f"share_{e}" for e in GAIT_EMOTIONS]]]
    df.to_csv(folder / "clip_norms.csv", index=False)
    return folder / "clip_norms.csv", motions


def test_sequences_carry_the_shares(rated):
    path, motions = rated
    seqs = load_soft_label_sequences(path, motions, GaitDataConfig())
    targets = {tuple(np.round(v.astype(float), 3).tolist()) for v in seqs.emotion.cpu().numpy()}
    assert targets == {tuple(v) for v in SHARES.values()}
    assert seqs.training_data.kind == "rated"
    info = seqs.training_data.corpus["soft_labels"]
    assert info["study"] == "pilot-study" and info["n_ratings"] == 41 and info["clips"] == {"sim-walk-a": 20,
                                                                                          "sim-walk-b": 21}
    assert info["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()


def test_finetune_records_the_norms_in_the_weights(rated, tmp_path):
    path, motions = rated
    out = tmp_path / "soft.pt"
    main(["--soft-labels", str(path), "--motions", str(motions), "--out", str(out), "--epochs", "1",
          "--set", "model.gru_hidden=16", "--set", "model.versor_hidden=16", "--set", "model.gru_layers=1",
          "--set", "model.root_hidden=8", "--set", "model.enc1_sizes=[8,8]", "--set", "model.enc2_sizes=[8,8]",
          "--set", "train.batch_size=4", "--checkpoint", str(tmp_path / "ckpt"), "--quiet"])
    saved = torch.load(out, weights_only=False)
    info = saved["corpus"]["soft_labels"]
    assert info["n_clips"] == 2 and info["n_ratings"] == 41 and info["study"] == "pilot-study"
    assert "soft labels" in saved["trained_on"]


def test_bad_norms_name_file_line_and_column(rated, tmp_path):
    path, motions = rated
    df = pd.read_csv(path)
    df.drop(columns="share_sad").to_csv(tmp_path / "a.csv", index=False)
    with pytest.raises(SoftLabelError, match="a.csv header, column 'share_sad': required column is missing"):
        read_soft_labels(tmp_path / "a.csv")
    df.assign(share_happy=[0.9, 0.05]).to_csv(tmp_path / "b.csv", index=False)
    with pytest.raises(SoftLabelError) as bad_sum:
        read_soft_labels(tmp_path / "b.csv")
    assert str(bad_sum.value) == ("b.csv line 2, columns 'share_happy' 0.9, 'share_sad' 0.1, 'share_angry' 0.1, "
                                  "'share_neutral' 0.2: the gait shares sum to 1.3, not 1")
    df.assign(clip_id=["sim-walk-a", "sim-walk-x"]).to_csv(tmp_path / "c.csv", index=False)
    with pytest.raises(SoftLabelError, match="c.csv line 3, column 'clip_id': clip 'sim-walk-x': no motion file"):
        load_soft_label_sequences(tmp_path / "c.csv", motions, GaitDataConfig())


def test_a_clip_the_catalogue_does_not_know_is_named_so(rated, tmp_path):
    """With a catalogue beside the motions folder (MEDIA_ROOT/clips.csv), a clip id it lacks is an unknown clip, not
    a missing motion file; a catalogued clip whose file is gone is still a missing motion file."""
    path, motions = rated
    catalogue = motions.parent / "clips.csv"
    pd.DataFrame({"clip_id": ["sim-walk-a", "sim-walk-b", "sim-walk-gone"], "modality": "gait"}).to_csv(
        catalogue, index=False)
    df = pd.read_csv(path)
    df.assign(clip_id=["sim-walk-a", "sim-walk-x"]).to_csv(tmp_path / "c.csv", index=False)
    with pytest.raises(SoftLabelError) as unknown:
        load_soft_label_sequences(tmp_path / "c.csv", motions, GaitDataConfig())
    assert str(unknown.value) == (f"c.csv line 3, column 'clip_id': clip 'sim-walk-x': unknown clip (not in the "
                                  f"catalogue {catalogue})")
    df.assign(clip_id=["sim-walk-gone", "sim-walk-a"]).to_csv(tmp_path / "d.csv", index=False)
    with pytest.raises(SoftLabelError, match="d.csv line 2, column 'clip_id': clip 'sim-walk-gone': no motion file"):
        load_soft_label_sequences(tmp_path / "d.csv", motions, GaitDataConfig())
    assert set(load_soft_label_sequences(path, motions, GaitDataConfig()).clip_names) == set(SHARES)


def test_real_finetune_with_soft_labels_trains_on_both(rated, tmp_path, monkeypatch):
    """The documented command ``--real finetune --soft-labels clip_norms.csv``: the real fine-tuning stage's takes
    (here two procedural walks with hard labels standing in for them; the real corpus is not built in tests) and the
    rated walks reach train() as one set, rated rows after the real ones with their shares, and the weights' record
    says both. The heavy training step is replaced by a recorder."""
    import generation.gait.train as gait_train
    from generation.gait.real_data import STAGE_AUGMENT, clip_sequences
    from generation.gait.soft_labels import RatedClip
    from generation.gait.weights import TrainingData

    path, motions = rated
    stand_ins = [RatedClip(f"sim-real-{label}", walk(WalkParams(cadence_spm=cadence), straight(12.0), 260, 30.0),
                           "train", None, label) for label, cadence in (("happy", 120), ("sad", 90))]
    asked, made = [], {}

    def fake_real(stage, data, path=None):
        asked.append((stage, path))
        seqs = clip_sequences(stand_ins, data, STAGE_AUGMENT[stage])
        made.update(rows=len(seqs), names=len(seqs.clip_names))
        return dataclasses.replace(seqs, training_data=TrainingData.real(stage, {"path": "sim-real.npz"}))

    seen = {}

    def fake_train(config, data, out, *args, **kwargs):
        seen.update(data=data, out=out)
        return {}

    monkeypatch.setattr(gait_train, "load_real_sequences", fake_real)
    monkeypatch.setattr(gait_train, "train", fake_train)
    out = tmp_path / "both.pt"
    main(["--real", "finetune", "--soft-labels", str(path), "--motions", str(motions), "--out", str(out),
          "--corpus", "sim-real.npz", "--quiet"])
    assert asked == [("finetune", "sim-real.npz")] and seen["out"] == str(out)
    data, n = seen["data"], made["rows"]
    assert len(data) > n
    assert set(data.clip_names[:made["names"]]) == {"sim-real-happy", "sim-real-sad"}
    assert set(data.clip_names[made["names"]:]) == set(SHARES)
    rounded = lambda rows: {tuple(np.round(v, 3)) for v in rows.cpu().numpy().astype(float)}  # noqa: E731
    assert rounded(data.emotion[:n]) == {(1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0)}
    assert rounded(data.emotion[n:]) == {tuple(v) for v in SHARES.values()}
    assert data.base_index[n:].min() > data.base_index[:n].max()   # rated windows never share a real one's base
    record = data.training_data
    assert record.kind == "real" and "soft labels" in record.description
    assert record.corpus["path"] == "sim-real.npz" and record.corpus["soft_labels"]["n_clips"] == 2
