"""The gait observer calibrated on real walks: trained on both corpora's training actors, its recall on held-out
actors per class beside each reading, and advisory flags for classes it does not recognise on real walks."""
from __future__ import annotations

import numpy as np
import pytest

from generation.mocap.real_corpus import CorpusClip
from generation.procedural.emotion import gait_params_for_emotion
from generation.procedural.walk import walk
from generation.quality import calibrated_observer as co
from generation.quality import evaluate, resolve_thresholds
from study_protocol import GAIT_EMOTIONS


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
