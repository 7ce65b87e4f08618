"""The gait observer calibrated on real walks: trained on both corpora's training actors, its recall on held-out
actors per class beside each reading, and advisory flags for classes it does not recognise on real walks."""
from __future__ import annotations

import json

import numpy as np
import pytest

from generation.core.digest import file_sha256
from generation.mocap import emotion_gait_bml as eg
from generation.mocap.real_corpus import DEFAULT_BML_PATH, DEFAULT_PATH, CorpusClip, RealCorpora
from generation.procedural.emotion import gait_params_for_emotion
from generation.procedural.walk import walk
from generation.quality import calibrated_observer as co
from generation.quality import evaluate, resolve_thresholds
from generation.quality import real_observer as ro
from generation.quality.observers import Observers
from protocol.vocabulary import GAIT_EMOTIONS


def _clip(performer: str, acted: str, perceived: str, split: str, seed: int) -> CorpusClip:
    rng = np.random.default_rng(seed)
    m = walk(gait_params_for_emotion(np.eye(4)[GAIT_EMOTIONS.index(acted)], rng=rng, jitter=0.3), n_frames=90,
             fps=30.0)
    m.metadata.update(performer=performer, acted_label=acted, perceived_label=perceived)
    return CorpusClip(f"{performer}_{acted}", co.BML_DATASET, "walk", acted, acted, 1, split, "gait", m)


@pytest.fixture(scope="module")
def corpus():
    """Five 'actors' x four emotions of procedural walks; actor e is held out. Perceived = acted except that
    the angry walks of actors a, b and e are perceived as happy."""
    clips = []
    for k, p in enumerate("abcde"):
        for e in GAIT_EMOTIONS:
            perceived = "happy" if e == "angry" and p in "abe" else e
            clips.append(_clip(f"BML_{p}", e, perceived, "test" if p == "e" else "train", 10 * k + len(e)))
    return [c for c in clips if c.split == "train"], [c for c in clips if c.split == "test"]


def test_observer_reports_recall_on_held_out_actors(corpus):
    train, heldout = corpus
    obs = co.CalibratedGaitObserver(train, heldout, "acted", source="test")
    assert obs.heldout_performers == ["BML_e"] and "BML_e" not in obs.train_performers
    assert set(obs.heldout_recall) == set(GAIT_EMOTIONS) and all(n == 1 for n in obs.heldout_n.values())
    values = obs.read(heldout[0].motion)
    assert values["observer"] == "real" and values["observer_labels"] == "acted"
    assert values["observer_heldout_recall"] == obs.heldout_recall
    perceived = co.CalibratedGaitObserver(train, heldout, "perceived", source="test")
    assert perceived.heldout_n["angry"] == 0 and perceived.heldout_recall["angry"] is None   # none held out
    assert perceived.heldout_n["happy"] == 2 and "angry" in perceived.advisory_classes


def test_held_out_actor_in_training_is_refused(corpus):
    train, heldout = corpus
    with pytest.raises(ValueError, match="also in training"):
        co.CalibratedGaitObserver(train + heldout[:1], heldout, "acted")


class _Fixed:
    """An observer with a fixed reading and held-out recall (the gate's logic without training)."""

    def __init__(self, observed, recall):
        self.observed, self.recall = observed, recall

    def reads(self, motion):
        return True

    def read(self, motion):
        return {"observed": self.observed, "observed_p": 0.9, "observer": "real", "observer_labels": "acted",
                "observer_heldout_recall": self.recall, "observer_heldout_n": dict.fromkeys(self.recall, 6)}


def test_flag_is_advisory_where_held_out_recall_is_below_0_6(corpus):
    motion = corpus[1][0].motion
    th = resolve_thresholds(None)
    good = {"happy": 0.83, "sad": 1.0, "angry": 0.67, "neutral": 0.67}
    res = evaluate(motion, th, intended=[0.0, 1.0, 0.0, 0.0], observer=_Fixed("neutral", good))
    assert "observer" in res.flags and res.values["observer_flag"] == "exclusionary"
    weak = {**good, "neutral": 0.33}
    res = evaluate(motion, th, intended=[0.0, 1.0, 0.0, 0.0], observer=_Fixed("neutral", weak))
    assert "observer" not in res.flags
    assert res.values["observer_flag"].startswith("advisory") and "neutral 0.33" in res.values["observer_flag"]
    res = evaluate(motion, th, intended=[0.0, 1.0, 0.0, 0.0], observer=_Fixed("sad", weak))
    assert "observer" not in res.flags and res.values["observer_flag"] == "none"


def test_judged_against_the_real_reference():
    out = co.judge_against_reference({"happy": 0.5, "sad": 0.9, "angry": 0.2},
                                     {"happy": 0.5, "sad": 1.0, "angry": None, "neutral": 0.7})
    assert out == {"happy": True, "sad": False, "angry": None, "neutral": None}


# ---- the shipped parameter files --------------------------------------------------------------------------------

#: The held-out recall and advisory classes the shipped files document (docs/benchmarks/calibrated_observer.json).
SHIPPED_REFERENCE = {
    "acted": ({"happy": 0.333, "sad": 0.667, "angry": 0.667, "neutral": 0.5},
              {"happy": 6, "sad": 6, "angry": 6, "neutral": 6}, ("happy", "neutral")),
    "perceived": ({"happy": 0.833, "sad": 0.556, "angry": 0.0, "neutral": 0.5},
                  {"happy": 6, "sad": 9, "angry": 1, "neutral": 8}, ("sad", "angry", "neutral")),
}


@pytest.fixture(scope="module")
def procedural_walk():
    return walk(gait_params_for_emotion(np.eye(4)[1]), n_frames=120, fps=30.0)


@pytest.mark.parametrize("labels", co.LABEL_VARIANTS)
def test_the_shipped_observers_read_a_walk_with_their_held_out_reference(labels, procedural_walk):
    obs = co.load_shipped_observer(labels)
    recall, n, advisory = SHIPPED_REFERENCE[labels]
    assert obs.kind == ("real" if labels == "acted" else "real-perceived") and obs.variant == labels
    assert obs.heldout_recall == recall and obs.heldout_n == n and obs.advisory_classes == advisory
    assert obs.heldout_confusion.sum() == 24 and len(obs.heldout_performers) == 6
    assert obs.parameters_sha256 == file_sha256(co.shipped_path(labels)) and "shipped" in obs.source
    p = obs.proba(procedural_walk)
    assert p.shape == (4,) and np.all(p >= 0) and p.sum() == pytest.approx(1.0, abs=1e-12)
    values = obs.read(procedural_walk)
    assert values["observer"] == obs.kind and values["observer_labels"] == labels
    assert values["observer_heldout_recall"] == recall and values["observer_advisory_classes"] == list(advisory)
    params = json.loads(co.shipped_path(labels).read_text())
    assert params["descriptor_version"] == ro.DESCRIPTOR_VERSION           # re-export when the descriptors change
    assert params["advisory_classes"] == list(advisory)
    assert {c["licence"] for c in params["corpora"].values()} == {"CC BY-NC 4.0", eg.LICENCE}
    assert (co.SHIPPED_DIR / "README.md").is_file()


def test_parameters_round_trip_to_identical_readings(corpus, tmp_path):
    train, heldout = corpus
    for labels in co.LABEL_VARIANTS:
        fitted = co.CalibratedGaitObserver(train, heldout, labels, source="test")
        path = co.write_parameters(tmp_path / f"{labels}.json", co.observer_parameters(fitted))
        loaded = co.read_parameters(path)
        assert loaded.parameters_sha256 == file_sha256(path)
        for clip in train + heldout:
            np.testing.assert_allclose(loaded.proba(clip.motion), fitted.proba(clip.motion), rtol=0, atol=1e-12)
        assert loaded.read(heldout[0].motion) == fitted.read(heldout[0].motion)
        assert (loaded.heldout_confusion == fitted.heldout_confusion).all()
        assert (loaded.train_takes, loaded.train_performers, loaded.C) == (fitted.train_takes,
                                                                             fitted.train_performers, fitted.C)


def test_a_file_of_other_descriptors_is_refused(corpus):
    params = co.observer_parameters(co.CalibratedGaitObserver(*corpus, "acted"))
    with pytest.raises(ValueError, match="descriptor version"):
        co.CalibratedGaitObserver.from_parameters({**params, "descriptor_version": "0"})
    bad = {**params, "classifier": {**params["classifier"], "intercept": [0.0, 0.0]}}
    with pytest.raises(ValueError, match="do not fit together"):
        co.CalibratedGaitObserver.from_parameters(bad)


def test_without_the_corpora_the_gate_reads_the_shipped_calibrated_observer(tmp_path, procedural_walk):
    """No corpus built: ``real`` and ``real-perceived`` are the shipped calibrated observers (their advisory
    classes apply); their version names the file's content; without the files ``real`` falls back to the
    Bandai-only observer of the shipped takes and ``real-perceived`` is None."""
    nowhere = RealCorpora.of(tmp_path / "bandai.npz", tmp_path / "bml.npz")
    observers = Observers()
    for kind, labels in (("real", "acted"), ("real-perceived", "perceived")):
        obs = observers.gait(kind, corpora=nowhere)
        assert isinstance(obs, co.CalibratedGaitObserver) and obs.kind == kind
        assert obs.parameters_sha256 == file_sha256(co.shipped_path(labels))
        assert observers.gait(kind, corpora=nowhere) is obs
        assert obs.parameters_sha256 in co.observer_version(labels, nowhere.bandai, nowhere.bml)
    # another file content is another version
    copy = tmp_path / "shipped"
    copy.mkdir()
    text = co.shipped_path("acted").read_text()
    (copy / co.shipped_path("acted").name).write_text(text.replace('"C": 0.1', '"C": 0.10'))
    assert (co.observer_version("acted", nowhere.bandai, nowhere.bml, copy)
            != co.observer_version("acted", nowhere.bandai, nowhere.bml))
    bare = Observers(shipped_dir=tmp_path / "none")
    assert bare.gait("real-perceived", corpora=nowhere) is None
    fallback = bare.gait("real", corpora=nowhere)
    assert isinstance(fallback, ro.RealGaitObserver) and "shipped real takes only" in fallback.source


def test_export_command_needs_both_corpora(tmp_path, capsys):
    assert co.main(["export", "--out", str(tmp_path), "--bandai", str(tmp_path / "absent.npz")]) == 2
    assert "no corpus at" in capsys.readouterr().out and not list(tmp_path.iterdir())


@pytest.mark.skipif(not (DEFAULT_PATH.is_file() and DEFAULT_BML_PATH.is_file()),
                    reason="the real corpora are not built in var/mocap/")
def test_the_shipped_files_equal_a_fresh_fit_on_the_built_corpora(tmp_path):
    """Built from ../shared/mocap (docs/mocap.md): the fit equals the shipped file. The corpus files' digests and
    contents may differ (a Bandai corpus built with more contents than walk); the observer reads only dataset 1's
    walk takes and the BML walks, so its parameters and held-out reference may not."""
    def comparable(params: dict) -> dict:
        params = {k: v for k, v in params.items() if k not in ("classifier", "fitted_with")}
        params["corpora"] = {k: {f: v for f, v in c.items() if f not in ("sha256", "contents")}
                             for k, c in params["corpora"].items()}
        return params

    for path, obs in co.export_observers(tmp_path):
        fresh, shipped = json.loads(path.read_text()), json.loads(co.shipped_path(obs.variant).read_text())
        assert comparable(fresh) == comparable(shipped), "the built corpora give another observer: re-export it"
        for key in ("scaler_mean", "scaler_scale", "coef", "intercept"):
            np.testing.assert_allclose(fresh["classifier"][key], shipped["classifier"][key], rtol=1e-9, atol=1e-12)
