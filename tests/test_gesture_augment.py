"""Phrase-recombination augmentation of the gesture corpus's training split (build_dataset(augment=N), --augment)."""
from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from generation.gesture.data import (
    MAX_PHRASES,
    augment_rows,
    build_dataset,
    count_words,
    is_augmented,
    load_sentences,
    phrases,
    split_sentences,
)
from generation.gesture.train import TrainConfig, build_parser, config_from_args


@pytest.fixture(scope="module")
def corpus():
    rows = load_sentences()
    return rows, split_sentences(rows, 0)


def _norm(phrase: str) -> str:
    return phrase.strip().lower()


def test_augmented_sentences_recombine_training_phrases_only(corpus):
    rows, split = corpus
    aug = augment_rows(rows, split, 300, seed=0)
    assert len(aug) == 300
    assert [r.sentence_id for r in aug] == [f"aug{k:05d}" for k in range(300)]
    assert all(is_augmented(r) for r in aug) and not any(is_augmented(r) for r in rows)
    train_phrases = {_norm(p) for r in rows if split[r.sentence_id] == "train" for p in phrases(r.sentence)}
    train_words = [count_words(r.sentence) for r in rows if split[r.sentence_id] == "train"]
    corpus_texts = {r.sentence.lower() for r in rows}
    for r in aug:
        parts = phrases(r.sentence)
        assert 2 <= len(parts) <= MAX_PHRASES, r
        assert all(_norm(p) in train_phrases for p in parts), r  # every phrase comes from a training sentence
        assert min(train_words) <= count_words(r.sentence) <= max(train_words), r
        assert r.sentence[0].isupper() and r.sentence[-1] in ".?!", r
        assert r.sentence.lower() not in corpus_texts
    assert len({r.sentence for r in aug}) == len(aug)
    # the tasks come from the sources, the emotions are spread evenly over the 11
    assert {r.task for r in aug} == {"narration", "conversation"}
    counts = Counter(r.emotion for r in aug)
    assert len(counts) == 11 and max(counts.values()) - min(counts.values()) <= 1


def test_sources_are_never_validation_or_test_sentences(corpus):
    rows, split = corpus
    # only the training split may be a source: with the other splits marked as not train, a phrase found only in
    # a validation or test sentence can never appear in an augmented sentence
    held_out_only = ({_norm(p) for r in rows if split[r.sentence_id] != "train" for p in phrases(r.sentence)}
                     - {_norm(p) for r in rows if split[r.sentence_id] == "train" for p in phrases(r.sentence)})
    assert held_out_only  # the check below means something
    for r in augment_rows(rows, split, 500, seed=3):
        assert not {_norm(p) for p in phrases(r.sentence)} & held_out_only, r
    # and with a split that has no training sentences there is nothing to recombine
    with pytest.raises(ValueError, match="at least 2 training sentences"):
        augment_rows(rows, {sid: "test" for sid in split}, 5)


def test_augmentation_is_deterministic(corpus):
    rows, split = corpus
    a = augment_rows(rows, split, 120, seed=0)
    assert a == augment_rows(rows, split, 120, seed=0)
    assert augment_rows(rows, split, 40, seed=0) == a[:40]  # a prefix of the longer run
    assert augment_rows(rows, split, 120, seed=1) != a
    assert augment_rows(rows, split, 0) == []


@pytest.mark.parametrize("bad", [-1, -100, 2.5, "10", True])
def test_bad_augment_values_raise(corpus, bad, tmp_path):
    rows, split = corpus
    with pytest.raises(ValueError, match="augment must be a whole number >= 0"):
        augment_rows(rows, split, bad)
    with pytest.raises(ValueError, match="augment must be a whole number >= 0"):
        build_dataset(cache_dir=tmp_path, rows=rows[:6], augment=bad)
    assert not list(tmp_path.iterdir())  # refused before anything is built or cached


def test_cli_flag_flows_into_the_training_config():
    assert TrainConfig().augment == 0
    assert config_from_args(build_parser().parse_args(["--device", "cpu"])).augment == 0
    assert config_from_args(build_parser().parse_args(["--device", "cpu", "--augment", "600"])).augment == 600
    with pytest.raises(ValueError, match="--augment must be >= 0"):
        config_from_args(build_parser().parse_args(["--device", "cpu", "--augment", "-1"]))


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """10 corpus sentences (sad and proud: 3 train, 1 val, 1 test each), without and with 6 augmented ones."""
    rows = [r for r in load_sentences() if r.emotion in ("sad", "proud")][::6]
    cache = tmp_path_factory.mktemp("gesture_cache")
    plain = build_dataset(variants=1, seed=0, cache_dir=cache, rows=rows)
    files_plain = sorted(p.name for p in cache.iterdir())
    again = build_dataset(variants=1, seed=0, cache_dir=cache, rows=rows, augment=0)
    files_again = sorted(p.name for p in cache.iterdir())
    aug = build_dataset(variants=1, seed=0, cache_dir=cache, rows=rows, augment=6)
    files_aug = sorted(p.name for p in cache.iterdir())
    return {"rows": rows, "plain": plain, "again": again, "aug": aug, "files": (files_plain, files_again, files_aug)}


def test_augment_zero_is_todays_dataset(small):
    plain, again = small["plain"], small["again"]
    files_plain, files_again, _ = small["files"]
    assert files_plain == files_again  # same cache files: no augmentation file, no new key
    assert not [f for f in files_plain if "aug" in f]
    for k in ("tokens", "token_lengths", "rotations", "lengths", "attributes", "split", "emotion", "gender",
              "handedness", "sentence_index"):
        np.testing.assert_array_equal(getattr(plain, k), getattr(again, k), err_msg=k)
    assert again.rows == small["rows"]


def test_augmented_rows_join_the_training_split_only(small):
    rows, plain, aug = small["rows"], small["plain"], small["aug"]
    files_aug = small["files"][2]
    assert [f for f in files_aug if f.startswith("gesture_pairs_aug_")] and "sentence_tokens_aug.npz" in files_aug
    n = len(plain)
    assert len(aug) == n + 6 and aug.rows[: len(rows)] == rows
    assert all(is_augmented(r) for r in aug.rows[len(rows):])
    # the corpus examples are unchanged: same split, attributes, gestures and token vectors
    np.testing.assert_array_equal(aug.split[:n], plain.split)
    np.testing.assert_array_equal(aug.attributes[:n], plain.attributes)
    np.testing.assert_array_equal(aug.emotion[:n], plain.emotion)
    T, S = plain.rotations.shape[1], plain.tokens.shape[1]
    np.testing.assert_array_equal(aug.rotations[:n, :T], plain.rotations)
    np.testing.assert_array_equal(aug.tokens[:n, :S], plain.tokens)
    np.testing.assert_array_equal(aug.indices("val"), plain.indices("val"))
    np.testing.assert_array_equal(aug.indices("test"), plain.indices("test"))
    # the new examples: training split, one gesture each, of the sentence's drawn emotion, sources from train
    new = np.arange(n, len(aug))
    assert set(aug.split[new]) == {"train"}
    assert sorted(aug.sentence_index[new]) == list(range(len(rows), len(rows) + 6))
    assert [str(aug.emotion[i]) for i in new] == [aug.row(i).emotion for i in new]
    train_phrases = {_norm(p) for r in rows if plain.split[list(plain.sentence_index).index(rows.index(r))] == "train"
                     for p in phrases(r.sentence)}
    for i in new:
        assert {_norm(p) for p in phrases(aug.row(i).sentence)} <= train_phrases
        assert aug.lengths[i] > 0 and aug.token_lengths[i] > 2


def test_training_keeps_the_best_epochs_weights_not_the_last(small, tmp_path, monkeypatch):
    """The kept weights are a copy taken at the best epoch: on the CPU the state dict shares the parameters'
    storage, so without a copy every later step overwrote the 'best' weights (found while training with
    augmentation: the kept epoch was always the last)."""
    import torch

    from generation.gesture import train as train_mod
    from generation.gesture.model import GestureNetConfig

    seen = {}

    def fake_score(net, data, val_idx, cfg, epoch, last_epoch, va, entry, ranges=None):
        seen[epoch] = {k: v.detach().clone() for k, v in net.state_dict().items()}
        return [3.0, 1.0, 2.0][epoch]

    monkeypatch.setattr(train_mod, "_score", fake_score)
    cfg = TrainConfig(epochs=3, batch_size=4, max_minutes=None, rollout_every=0, lr=1e-2, device="cpu",
                      model=GestureNetConfig(d_model=16, d_ff=32, dropout=0.0),
                      out=str(tmp_path / "w.pt"), checkpoint=str(tmp_path / "ck.pt"))
    summary = train_mod.train(cfg, data=small["plain"], progress=False)
    assert summary["best_epoch"] == 1 and summary["epochs_run"] == 3
    kept = torch.load(tmp_path / "w.pt", weights_only=False)["state_dict"]
    last = torch.load(tmp_path / "ck.pt", weights_only=False)["state_dict"]
    assert all(torch.equal(kept[k], seen[1][k]) for k in kept)
    assert not all(torch.equal(kept[k], last[k]) for k in kept)
