"""Soft labels for the gesture network: clip_norms.csv's perceived shares of rated gestures as share-weighted NRC-VAD
emotion attributes, each gesture's sentence from its clip record, its paired generated clip or clips.csv, one epoch of
a tiny network through ``python -m generation.gesture.train --soft-labels``, the weights recording the norms, and bad
input named by file, line and column. Tiny: four SIMULATED norms rows on procedural gestures written with the
project's BVH writer."""
from __future__ import annotations

import hashlib
import io
import json

import numpy as np
import pandas as pd
import pytest
import torch

from generation.gesture import config
from generation.gesture.data import SentenceRow, procedural_gesture
from generation.gesture.soft_labels import SoftLabelError, load_soft_label_dataset, soft_vad
from generation.gesture.train import main
from generation.plans.clipgen import write_motion_bvh
from protocol.vocabulary import CLIP_NORMS_COLUMNS, GESTURE_EMOTIONS, GESTURE_VAD

SHARE_COLUMNS = [f"share_{e}" for e in GESTURE_EMOTIONS]
SENTENCE = "We finally did it, look at this!"
CATALOGUED = "I will tell you about the long way home."


def _shares(**named) -> list[float]:
    return [named.get(e, 0.0) for e in GESTURE_EMOTIONS]


#: clip id -> SIMULATED perceived shares
SHARES = {"sim-gen-1": _shares(joyous=0.6, proud=0.3, neutral=0.1),   # generated: its record names its sentence
          "sim-src-1": _shares(sad=0.7, ashamed=0.3),                 # source: the sentence of its paired clip
          "sim-cat-1": _shares(angry=1.0),                            # sentence from clips.csv's extra columns
          "sim-bye": _shares(neutral=0.5, relieved=0.5)}              # a captured take: no sentence, left out


def _record(folder, clip_id, inputs, source_clip_id=""):
    (folder / f"{clip_id}.json").write_text(json.dumps({"clip_id": clip_id, "source_clip_id": source_clip_id,
                                                        "metadata": {"inputs": inputs}}))


@pytest.fixture
def rated(tmp_path, monkeypatch):
    # the token cache of these sentences stays here: library calls get cache_dir, the command lines read the variable
    monkeypatch.setenv("GESTURE_VAR_DIR", str(tmp_path / "var"))
    media = tmp_path / "media"
    records = media / "clip_records"
    records.mkdir(parents=True)
    for i, clip_id in enumerate(SHARES):
        row = SentenceRow(clip_id, "joyous", "narration", SENTENCE)
        write_motion_bvh(procedural_gesture(row, "female", "right", seed=i, fps=25.0), media / "motions", clip_id)
    _record(records, "sim-gen-1", {"sentence": SENTENCE, "task": "narration", "emotion_label": "joyous",
                                   "gender": "female", "handedness": "right"}, source_clip_id="sim-src-1")
    _record(records, "sim-src-1", {"emotion_label": "joyous", "gender": "male", "handedness": "left"})
    _record(records, "sim-bye", {"file": "dataset-1_bye_normal_001.bvh", "emotion_label": "neutral"})
    pd.DataFrame({"clip_id": list(SHARES), "modality": "gesture",
                  "sentence": ["", "", CATALOGUED, ""], "task": ["", "", "conversation", ""],
                  "gender": ["", "", "male", ""], "handedness": ["", "", "right", ""]}).to_csv(
        media / "clips.csv", index=False)
    folder = tmp_path / "pilot-gestures"
    folder.mkdir()
    rows = [{"clip_id": clip_id, "modality": "gesture", "section_type": "gesture_emotion", "question": "perceived",
             "n_ratings": 20 + i, **{c: "" for c in CLIP_NORMS_COLUMNS[5:]},
             **dict(zip(SHARE_COLUMNS, shares))} for i, (clip_id, shares) in enumerate(SHARES.items())]
    pd.DataFrame(rows)[[*CLIP_NORMS_COLUMNS, *SHARE_COLUMNS]].to_csv(folder / "clip_norms.csv", index=False)
    return folder / "clip_norms.csv", media / "motions"


def test_soft_target_is_the_share_weighted_nrc_vad():
    one_hot = np.eye(len(GESTURE_EMOTIONS))[GESTURE_EMOTIONS.index("proud")]
    np.testing.assert_allclose(soft_vad(one_hot), GESTURE_VAD["proud"])
    mix = _shares(sad=0.5, joyous=0.5)
    np.testing.assert_allclose(soft_vad(mix), (np.array(GESTURE_VAD["sad"]) + GESTURE_VAD["joyous"]) / 2)


def test_dataset_takes_shares_sentences_and_motions(rated, tmp_path):
    path, motions = rated
    logged = []
    data, norms = load_soft_label_dataset(path, motions, cache_dir=tmp_path / "var", log=logged.append)
    assert [r.sentence_id for r in data.rows] == ["sim-gen-1", "sim-src-1", "sim-cat-1"]
    assert [(r.sentence, r.task) for r in data.rows] == [(SENTENCE, "narration"), (SENTENCE, "narration"),
                                                         (CATALOGUED, "conversation")]
    assert list(data.gender) == ["female", "male", "male"] and list(data.handedness) == ["right", "left", "right"]
    expected = soft_vad(np.array([SHARES[r.sentence_id] for r in data.rows]))
    np.testing.assert_allclose(data.vad, expected, atol=1e-6)
    np.testing.assert_allclose(data.attributes[:, 2:5], expected, atol=1e-6)   # [task (2), E = VAD (3), ...]
    assert list(data.emotion) == ["joyous", "sad", "angry"] and set(data.split) == {"train"}
    assert data.fps == config.TRAIN_FPS and data.rotations.shape[2:] == (23, 4)
    assert norms["n_clips"] == 3 and norms["n_ratings"] == 20 + 21 + 22 and norms["study"] == "pilot-gestures"
    assert norms["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
    assert list(norms["skipped"]) == ["sim-bye"] and any("sim-bye" in line for line in logged)


def test_one_epoch_through_the_command_records_the_norms(rated, tmp_path):
    path, motions = rated
    out = tmp_path / "gesture_soft.pt"
    summary = main(["--soft-labels", str(path), "--motions", str(motions), "--out", str(out),
                    "--checkpoint", str(tmp_path / "ck.pt"), "--epochs", "1", "--d-model", "16", "--batch-size", "2",
                    "--rollout-every", "0", "--max-minutes", "0", "--quiet"])
    assert summary["epochs_run"] == 1
    assert (tmp_path / "var" / "sentence_tokens.npz").is_file()          # $GESTURE_VAR_DIR, read by the command line
    saved = torch.load(out, weights_only=False)
    info = saved["corpus"]["soft_labels"]
    assert info["n_clips"] == 3 and info["n_ratings"] == 63 and info["study"] == "pilot-gestures"
    assert info["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
    assert info["clips"] == {"sim-gen-1": 20, "sim-src-1": 21, "sim-cat-1": 22}
    assert saved["trained_on"].startswith("soft labels: 3 rated gestures")
    assert saved["train_config"]["soft_labels"] == str(path) and saved["config"]["d_model"] == 16


def test_unknown_clip_and_missing_motion_name_file_line_and_column(rated, tmp_path, capsys):
    path, motions = rated
    df = pd.read_csv(path)
    df.assign(clip_id=["sim-gen-1", "sim-nowhere", "sim-cat-1", "sim-bye"]).to_csv(tmp_path / "u.csv", index=False)
    with pytest.raises(SoftLabelError) as unknown:
        load_soft_label_dataset(tmp_path / "u.csv", motions, cache_dir=tmp_path / "var")
    assert str(unknown.value) == (f"u.csv line 3, column 'clip_id': clip 'sim-nowhere': unknown clip (not in the "
                                  f"catalogue {motions.parent / 'clips.csv'})")
    (motions / "sim-cat-1.bvh").unlink()
    with pytest.raises(SystemExit):
        main(["--soft-labels", str(path), "--motions", str(motions), "--out", str(tmp_path / "x.pt"), "--quiet"])
    err = capsys.readouterr().err
    assert "clip_norms.csv line 4, column 'clip_id': clip 'sim-cat-1': no motion file" in err
    assert not (tmp_path / "x.pt").exists()
    df.assign(share_sad=[0.0, 0.7, 0.2, 0.0]).to_csv(tmp_path / "s.csv", index=False)
    with pytest.raises(SoftLabelError, match="s.csv line 4, columns 'share_afraid' 0.0, .*'share_angry' 1.0, .*"
                                             "'share_sad' 0.2, .*: the gesture shares sum to 1.2, not 1"):
        load_soft_label_dataset(tmp_path / "s.csv", motions, cache_dir=tmp_path / "var")


def test_manage_py_train_gesture_takes_the_same_soft_labels(rated, tmp_path):
    from django.core.management import CommandError, call_command

    path, motions = rated
    out = tmp_path / "via_manage.pt"
    call_command("train_gesture", "--soft-labels", str(path), "--motions", str(motions), "--out", str(out),
                 "--checkpoint", str(tmp_path / "ck2.pt"), "--epochs", "1", "--d-model", "16", "--rollout-every", "0",
                 "--quiet", stdout=io.StringIO())
    assert torch.load(out, weights_only=False)["corpus"]["soft_labels"]["n_clips"] == 3
    with pytest.raises(CommandError, match="choose one training set"):
        call_command("train_gesture", "--soft-labels", str(path), "--corpus", "x.npz", "--quiet")
