"""The ``pooled`` intensity set (generation/rbf/extended.py, generation/data/rbf/pooled_intensities.json): happy and
sad sized from the mean over two sources, each weighing the same (Bandai Namco dataset 1, CC BY-NC 4.0; the BML walks
of Emotion-Gait, research use with citation); the other themes as the ``extended`` set."""
from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from generation.mocap.real_corpus import DEFAULT_BML_PATH, DEFAULT_PATH, load_real_corpus
from generation.rbf import calibrate as C
from generation.rbf import extended as E
from generation.rbf.observer import load_bml_walks
from generation.rbf.real_neutral import load_cycle
from generation.rbf.stylise import stylise
from generation.rbf.themes import EXTENDED_PATH, POOLED_PATH, all_features

BANDAI, BML = "bandai-namco-1", "emotion-gait-bml"
POOLED_THEMES = ("happy", "sad")


@pytest.fixture(scope="module")
def pooled():
    return json.loads(POOLED_PATH.read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def extended():
    return json.loads(EXTENDED_PATH.read_text(encoding="utf-8"))


def test_happy_and_sad_targets_are_the_mean_of_both_sources(pooled):
    for theme in POOLED_THEMES:
        entry = pooled["themes"][theme]
        assert [s["source"] for s in entry["sized_on"]] == [BANDAI, BML]
        licences = {s["source"]: s for s in entry["sized_on"]}
        assert licences[BANDAI]["licence"] == "CC BY-NC 4.0" and "arXiv:2306.08861" in licences[BANDAI]["citation"]
        assert "research use" in licences[BML]["licence"] and "Pollick" in licences[BML]["citation"]
        assert "STEP" in licences[BML]["citation"]
        for g in entry["groups"]:
            for kind in ("train", "heldout"):
                per = g[f"real_{kind}_sources"]
                assert sorted(per) == [BANDAI, BML], (theme, g)
                assert g[f"real_{kind}"] == pytest.approx((per[BANDAI] + per[BML]) / 2, abs=2e-6), (theme, g, kind)
        # at least one group where the sources differ, so the mean is not one of them
        assert any(abs(g["real_train_sources"][BANDAI] - g["real_train_sources"][BML]) > 0.01 for g in entry["groups"])
        tempo = entry["tempo"]
        assert [d["dataset"] for d in tempo["datasets"]] == [BANDAI, BML]
        for key, ratio in (("per_weight", "speed_ratio"), ("stride_per_weight", "stride_ratio"),
                           ("cadence_per_weight", "cadence_ratio")):
            assert tempo[key] == pytest.approx(np.mean([d[ratio] for d in tempo["datasets"]]) - 1, abs=2e-6), key


def test_bml_sizes_on_training_actors_and_checks_on_the_others(pooled):
    for theme in POOLED_THEMES:
        train = next(s for s in pooled["themes"][theme]["sources"]["train"] if s["dataset"] == BML)
        held = next(s for s in pooled["themes"][theme]["sources"]["heldout"] if s["dataset"] == BML)
        assert train["splits"] == ["train"] and held["splits"] == list(C.HELDOUT_SPLITS)
        assert len(train["walkers"]) >= 15 and len(held["walkers"]) >= 5
        assert not set(train["walkers"]) & set(held["walkers"])


def test_other_themes_and_the_default_set_are_bandai_alone(pooled, extended):
    for theme, entry in extended["themes"].items():
        assert "sized_on" not in entry and all("real_train_sources" not in g for g in entry["groups"])
        if theme not in POOLED_THEMES:
            assert pooled["themes"][theme] == entry, theme


def test_pooled_is_selectable_with_its_tempo_and_sources(pooled):
    out = stylise(load_cycle(), "sad", 1.0, 10, intensities="pooled", n_cycles=1, plant=False)
    tempo = pooled["themes"]["sad"]["tempo"]
    assert out.metadata["intensities"] == "pooled"
    assert out.metadata["stride_scale"] == pytest.approx(max(0.5, 1 + tempo["stride_per_weight"]))
    assert out.metadata["cadence_scale"] == pytest.approx(max(0.5, 1 + tempo["cadence_per_weight"]))
    assert sorted(out.metadata["intensity_sources"]) == [BANDAI, BML]
    default = stylise(load_cycle(), "sad", 1.0, 10, n_cycles=1, plant=False)
    assert "intensity_sources" not in default.metadata
    assert default.metadata["cadence_scale"] != out.metadata["cadence_scale"]


def test_pooled_file_is_current(pooled):
    """The w = 1 measures the file records are what the code makes from its intensities."""
    base = load_cycle()
    for theme in POOLED_THEMES:
        by_rank = {r["rank"]: r["extended"] for r in pooled["themes"][theme]["features"]}
        reached = C.generated_measures(base, theme, by_rank, 1.0, all_features(theme), True)
        np.testing.assert_allclose(reached, [g["extended_w1"] for g in pooled["themes"][theme]["groups"]], atol=1e-5)


def _walker_clip(walker: str, style: str, split: str = "train") -> SimpleNamespace:
    return SimpleNamespace(name=f"{walker}_{style}", dataset=BML, content="walk", style=style, split=split,
                           motion=SimpleNamespace(metadata={"performer": walker}))


def test_each_source_weighs_the_same_however_many_actors_it_has(monkeypatch):
    """Bandai's one dataset (difference [1, 2]) and BML's three actors ([0, 0], [0, 0], [3, 3]: mean [1, 1]) give
    [1, 1.5]; weighing the four walkers alike would give [0.75, 1]."""
    monkeypatch.setattr(C, "real_differences", lambda *a, **k: (np.array([1.0, 2.0]), [
        {"dataset": BANDAI, "difference": [1.0, 2.0]}]))
    per = {"a": [0.0, 0.0], "b": [0.0, 0.0], "c": [3.0, 3.0]}
    seen = []

    def walker_differences(clips, theme, styles, neutral, m, feats):
        seen.append(sorted({c.split for c in clips}))
        walkers = sorted({c.motion.metadata["performer"] for c in clips})
        return [{"walker": w, "difference": per[w], "speed_ratio": 1.0, "stride_ratio": 1.0, "cadence_ratio": 1.0}
                for w in walkers]

    monkeypatch.setattr(C, "walker_differences", walker_differences)
    clips = [_walker_clip(w, s) for w in per for s in ("sad", "neutral")]
    target, sources, info = E.source_differences([], clips, "sad", ("train",))
    np.testing.assert_allclose(target, [1.0, 1.5])
    np.testing.assert_allclose(sources[BML], [1.0, 1.0])
    assert info[-1]["walkers"] == ["a", "b", "c"] and info[-1]["splits"] == ["train"]
    # no happy walk in the BML clips: Bandai alone, unchanged
    target, sources, _ = E.source_differences([], clips, "happy", ("train",))
    np.testing.assert_allclose(target, [1.0, 2.0])
    assert sorted(sources) == [BANDAI]
    # no training actor: all actors size it and the result says so; a held-out check never falls back
    held_out = [_walker_clip(w, s, "test") for w in per for s in ("sad", "neutral")]
    assert E.bml_source(held_out, "sad", ("train",))["splits"] == ["test"]
    assert E.bml_source(held_out, "sad", ("train",), all_if_none=False) is None


@pytest.mark.slow
@pytest.mark.skipif(not (DEFAULT_PATH.is_file() and DEFAULT_BML_PATH.is_file()),
                    reason="real corpora not built (docs/corpus.md, docs/mocap.md)")
def test_rebuild_on_the_corpora_matches_the_shipped_file(pooled):
    clips = load_real_corpus(DEFAULT_PATH, skeleton="gait", contents=["walk"])
    bml = load_bml_walks()
    for theme in POOLED_THEMES:
        train, _, _ = E.source_differences(clips, bml, theme, ("train",), 100, all_features(theme))
        np.testing.assert_allclose(train, [g["real_train"] for g in pooled["themes"][theme]["groups"]], atol=1e-5)
        tempo = E.pooled_tempo(clips, E.bml_source(bml, theme, ("train",)), theme)
        for key in ("per_weight", "stride_per_weight", "cadence_per_weight"):
            assert tempo[key] == pytest.approx(pooled["themes"][theme]["tempo"][key], abs=1e-5), key
