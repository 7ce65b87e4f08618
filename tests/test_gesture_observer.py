"""The synthetic gesture observer (generation/quality/gesture_observer.py) and its place in the quality gate."""
from __future__ import annotations

import pickle

import numpy as np
import pytest
import yaml

from generation.core.motion import Motion
from generation.core.skeleton import gesture_skeleton
from generation.gesture.data import build_dataset
from generation.pipeline import plan_qa
from generation.quality import checks, evaluate, failed_checks, qa_columns, resolve_thresholds
from generation.quality import gesture_observer as go
from generation.quality.observers import Observers
from protocol.vocabulary import GESTURE_EMOTIONS, GESTURE_VAD, QA_THRESHOLDS
from tests.test_render import seated, swinging_walk

PER_CLASS = 20  # training gestures per emotion for the fast test observer (the shipped one uses all 792)


@pytest.fixture(scope="module")
def corpus():
    return build_dataset()


@pytest.fixture(scope="module")
def small_observer(corpus):
    """Fitted on PER_CLASS training gestures of each emotion (a few seconds instead of ~20)."""
    tr = corpus.indices("train")
    idx = np.concatenate([tr[corpus.emotion[tr] == e][:PER_CLASS] for e in GESTURE_EMOTIONS])
    return go.GestureObserver.from_corpus(corpus, idx)


def corpus_motion(data, i: int, fps: float = 25.0) -> Motion:
    """Procedural corpus example ``i`` as a clip Motion (its body, seated root) at ``fps``."""
    L = int(data.lengths[i])
    rot = data.rotations[i, :L].astype(np.float64)
    root = np.repeat(data.root[i][None].astype(np.float64), L, 0)
    m = Motion(gesture_skeleton(build=str(data.gender[i])), rot, root, data.fps, {"synthetic": True})
    return m.resample(fps)


def test_observer_reads_held_out_procedural_gestures_far_above_chance(corpus, small_observer):
    test = corpus.indices("test")
    p = small_observer.proba_features(go.corpus_descriptors(corpus, test))
    assert p.shape == (len(test), len(GESTURE_EMOTIONS))
    np.testing.assert_allclose(p.sum(1), 1.0, atol=1e-9)
    read = np.array(GESTURE_EMOTIONS)[p.argmax(1)]
    accuracy = float((read == corpus.emotion[test]).mean())
    assert accuracy > 0.6, accuracy            # chance is 1/11 = 0.09; measured 0.96 with the full training split
    half = np.mean([go.arousal_half(a) == go.arousal_half(b) for a, b in zip(read, corpus.emotion[test])])
    assert half > 0.85


def test_observe_returns_a_gesture_label_and_probability_at_any_frame_rate(corpus, small_observer):
    i = int(corpus.indices("test")[0])
    label, p = small_observer.observe(corpus_motion(corpus, i, 25.0))
    assert label in GESTURE_EMOTIONS and 0.0 < p <= 1.0
    label10, p10 = small_observer.observe(corpus_motion(corpus, i, corpus.fps))
    assert label10 == label and p10 == pytest.approx(p, abs=0.1)      # clips are resampled to the corpus rate
    _, _, arousal = small_observer.reading(corpus_motion(corpus, i))
    assert min(go.AROUSAL) <= arousal <= max(go.AROUSAL)
    with pytest.raises(ValueError, match="gesture skeleton"):
        small_observer.observe(swinging_walk(T=20, fps=30.0))
    label, p = small_observer.observe(seated(T=2, fps=25.0))          # 0.04 s: too short to resample, still read
    assert label in GESTURE_EMOTIONS and 0.0 < p <= 1.0


def test_observer_rejects_bad_training_input():
    with pytest.raises(ValueError, match="X must be"):
        go.GestureObserver(np.zeros((3, 5)), ["sad"] * 3, 10.0)
    with pytest.raises(ValueError, match="GESTURE_EMOTIONS"):
        go.GestureObserver(np.zeros((2, go.N_DESCRIPTORS)), ["sad", "bored"], 10.0)


def test_default_observer_cache_round_trips(tmp_path, monkeypatch, small_observer, corpus):
    calls = []

    def train(data=None):
        calls.append(1)
        return small_observer

    monkeypatch.setattr(go, "CACHE_DIR", tmp_path)
    monkeypatch.setattr(go, "train_gesture_observer", train)
    observers = Observers()
    first = observers.gesture()
    assert first is small_observer and len(calls) == 1
    files = list(tmp_path.glob("gesture_observer_*.pkl"))
    assert [f.name for f in files] == [f"gesture_observer_{go.corpus_version()}.pkl"]
    assert observers.gesture() is first and len(calls) == 1                    # from memory
    loaded = Observers().gesture()                                              # from the file
    assert len(calls) == 1 and loaded is not small_observer
    X = go.corpus_descriptors(corpus, corpus.indices("val")[:5])
    np.testing.assert_allclose(loaded.proba_features(X), small_observer.proba_features(X))
    files[0].write_bytes(b"not a pickle")                                       # a broken file: trained again
    assert Observers().gesture() is small_observer and len(calls) == 2
    assert isinstance(pickle.loads(files[0].read_bytes()), go.GestureObserver)


def test_default_observer_is_none_without_the_corpus(tmp_path, monkeypatch):
    from generation.gesture import config

    monkeypatch.setattr(config, "SENTENCES_CSV", tmp_path / "missing.csv")
    with pytest.warns(UserWarning, match="gesture observer"):
        assert Observers().gesture() is None


class FixedReading(go.GestureObserver):
    """An observer that reads every gesture the same (label, p, arousal); no training."""

    def __init__(self, label: str, p: float, arousal: float):
        self.fixed = (label, p, arousal)
        self.min_seconds = 2.5

    def reading(self, motion):
        return self.fixed


def test_gate_fills_observed_for_a_gesture_clip(small_observer):
    assert small_observer.min_seconds == pytest.approx(2.5)                    # the network's shortest
    res = evaluate(seated(T=75, fps=25.0), seated=True, intended="sad", observer=small_observer)
    assert res.values["observed"] in GESTURE_EMOTIONS and 0 < res.values["observed_p"] <= 1
    cols = qa_columns(res.as_dict())
    assert cols["qa_observed"] == res.values["observed"] and cols["qa_observed_p"] == res.values["observed_p"]
    # a gait observer never reads a gesture, the gesture observer never reads a gait
    walk = evaluate(swinging_walk(T=20, fps=30.0), observer=small_observer)
    assert walk.values["observed"] is None and "observed_arousal" not in walk.values
    short = evaluate(seated(T=50, fps=25.0), seated=True, intended="sad", observer=small_observer)   # 2 s
    assert short.values["observed"] is None and short.flags == []


def test_flag_rule_catches_another_arousal_and_spares_a_matching_or_neighbouring_reading():
    sit = seated(T=75, fps=25.0)
    angry = FixedReading("angry", 0.9, GESTURE_VAD["angry"][1])
    res = evaluate(sit, seated=True, intended="sad", observer=angry)             # sad read as angry: gap 0.50
    assert res.values["observed"] == "angry" and res.flags == ["observer"]
    assert evaluate(sit, seated=True, intended="sad", observer=FixedReading("sad", 0.9, 0.36)).flags == []
    # ashamed read as sad: another label, but neighbours in arousal (0.588 vs 0.333): not flagged
    assert evaluate(sit, seated=True, intended="ashamed", observer=FixedReading("sad", 0.95, 0.40)).flags == []
    assert evaluate(sit, seated=True, intended=None, observer=angry).flags == []   # nothing intended
    gap = QA_THRESHOLDS["gesture_arousal_gap"]
    base = {"observed": "angry", "observed_p": 0.9}
    a_sad = GESTURE_VAD["sad"][1]
    assert failed_checks({**base, "observed_arousal": a_sad + gap + 0.01}, intended="sad") == ["observer"]
    assert failed_checks({**base, "observed_arousal": a_sad + gap - 0.01}, intended="sad") == []
    assert failed_checks({**base, "observed_arousal": None}, intended="sad") == []
    assert failed_checks({**base, "observed_arousal": 0.9}, intended="bored") == []   # not a gesture emotion
    # the gait rule is unchanged: a gait vector is judged by observer_mismatch_p
    assert failed_checks({"observed": "sad", "observed_p": 0.95}, intended=[1.0, 0, 0, 0]) == ["observer"]


def test_plan_qa_block_switches_the_gesture_rule_off_or_changes_it():
    values = {"observed": "angry", "observed_p": 0.9, "observed_arousal": 0.83}
    assert failed_checks(values, resolve_thresholds(None), "sad") == ["observer"]
    assert failed_checks(values, resolve_thresholds({"gesture_arousal_gap": None}), "sad") == []
    assert failed_checks(values, resolve_thresholds({"gesture_arousal_gap": 0.6}), "sad") == []
    # switching the gait rule off leaves the gesture rule on
    assert failed_checks(values, resolve_thresholds({"observer_mismatch_p": None}), "sad") == ["observer"]
    assert "gesture_arousal_gap" in checks.__doc__


def test_intended_emotion_of_gait_and_gesture_entries():
    assert plan_qa.intended_emotion({"emotion": [0, 1, 0, 0]}) == [0, 1, 0, 0]
    assert plan_qa.intended_emotion({"emotion_label": "proud", "sentence": "x"}) == "proud"
    assert plan_qa.intended_emotion({"vad": [0.1, 0.2, 0.3]}) is None


def test_plan_qa_run_reads_gesture_clips(tmp_path, monkeypatch, small_observer):
    plan = tmp_path / "g.yaml"
    plan.write_text(yaml.safe_dump({"name": "g", "render": {"width": 160, "height": 120, "fps": 25, "duration_s": 4},
                                    "clips": [{"id": "sad_sit", "generator": "procedural_gesture", "origin": "source",
                                               "emotion_label": "sad", "duration_s": 3.0, "seed": 1}]}))
    monkeypatch.setattr(plan_qa, "observer_for",
                        lambda modality, *_: small_observer if modality == "gesture" else None)
    rows = plan_qa.run(str(plan), log=lambda line: None, modality="gesture", figure_height=False)
    assert len(rows) == 1 and rows[0]["intended"] == "sad" and rows[0]["modality"] == "gesture"
    assert rows[0]["observed"] in GESTURE_EMOTIONS and rows[0]["figure_height_frac"] is None
    assert rows[0]["observed_arousal"] is not None
