"""The walker of a clip and folds over walkers (generation/rbf/observer.py): performer-keyed references for BML-like
clips, every actor held out exactly once and never trained on, and a synthetic emotion check that can fail; the
held-out-by-actor recall on the real BML walks when that corpus is built."""
from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from generation.mocap.real_corpus import DEFAULT_BML_PATH
from generation.procedural.walk import WalkParams, walk
from generation.rbf import observer as O

BML = "emotion-gait-bml"
# habitual walks of six walkers (cadence steps/min, stride m, arm swing rad): they differ more than one walker's moods
WALKERS = [(96, 1.60, 0.20), (124, 1.20, 0.40), (104, 1.50, 0.45), (118, 1.30, 0.15), (100, 1.25, 0.35),
           (120, 1.55, 0.25)]
# emotion -> (cadence factor, stride factor, arm swing factor, torso pitch added rad)
EMOTIONS = {"neutral": (1.0, 1.0, 1.0, 0.0), "sad": (0.82, 0.85, 1.0, 0.0), "happy": (1.12, 1.08, 1.6, 0.0),
            "angry": (1.10, 1.10, 1.0, 0.20)}


def _clip(name: str, style: str, performer: str | None, dataset: str = BML, motion=None) -> SimpleNamespace:
    motion = motion if motion is not None else SimpleNamespace(metadata={} if performer is None else
                                                               {"performer": performer})
    return SimpleNamespace(name=name, dataset=dataset, content="walk", style=style, split="train", motion=motion)


def _walk(walker: int, emotion: str, seed: int):
    cadence, stride, swing = WALKERS[walker]
    k_cad, k_stride, k_swing, torso = EMOTIONS[emotion]
    base = WalkParams(cadence_spm=cadence, stride_m=stride, arm_swing_rad=swing)
    params = replace(base, cadence_spm=cadence * k_cad, stride_m=stride * k_stride, arm_swing_rad=swing * k_swing,
                     torso_pitch_rad=base.torso_pitch_rad + torso)
    motion = walk(params, n_frames=90, seed=seed)
    motion.metadata["performer"] = f"actor-{walker}"
    return _clip(f"a{walker}_{emotion}", emotion, f"actor-{walker}", motion=motion)


def test_walker_is_the_performer_where_named_else_the_dataset():
    assert O.walker_of(_clip("x", "sad", "BML_ale")) == "BML_ale"
    assert O.walker_of(_clip("y", "sad", None, dataset="bandai-namco-1")) == "bandai-namco-1"
    assert O.walker_of(_clip("z", "sad", "", dataset="bandai-namco-2")) == "bandai-namco-2"


def test_folds_hold_every_actor_out_once_and_never_train_on_it(monkeypatch):
    """Every actor is in exactly one held-out fold, and the clips an observer is fitted on never include a clip of
    that fold's actors (recorded at the fit itself)."""
    actors = [f"BML_{i:02d}" for i in range(12)]
    clips = [_clip(f"{a}_{e}", e, a) for a in actors for e in ("happy", "sad", "angry", "neutral")]
    fitted = []

    class Stub:
        classes = ("happy", "sad", "angry", "neutral")

        def heldout(self, clips, splits, references, datasets):
            return {"rows": [{"class": c.style, "top": c.style, "p": {k: float(k == c.style) for k in self.classes},
                              "walker": O.walker_of(c)} for c in clips]}

        def read(self, motion, reference):
            return {"top": "neutral", "p": {k: float(k == "neutral") for k in self.classes}}

    def fake_fit(clips, *args, **kwargs):
        fitted.append({O.walker_of(c) for c in clips})
        return Stub()

    monkeypatch.setattr(O.RbfStyleObserver, "fit", staticmethod(fake_fit))
    monkeypatch.setattr(O, "walker_references", lambda clips, splits: {O.walker_of(c): np.zeros(44) for c in clips})
    out = O.heldout_by_walker(clips, k=4)
    held = [a for f in out["folds"] for a in f["heldout"]]
    assert sorted(held) == actors  # each actor exactly once
    assert len(fitted) == 4
    for fold, trained in zip(out["folds"], fitted):
        assert not trained & set(fold["heldout"]), fold
        assert trained == set(actors) - set(fold["heldout"])
    assert out["takes"] == {"happy": 12, "sad": 12, "angry": 12, "neutral": 12}
    with pytest.raises(ValueError, match="folds"):
        O.walker_folds(actors[:3], k=4)


def test_slower_than_its_own_neutral_walk_reads_as_sad():
    """Trained on five walkers whose sad walks are slower than their own neutral walk (but not slower than every
    other walker's neutral walk), the observer reads a sixth walker's slowed walk, relative to that walker's neutral
    walk, as sad, and the neutral walk itself as neutral; relative to the slowest walker's neutral walk (walker 4,
    1.04 m/s against the slowed walk's 1.08 m/s) the same walk is not sad: the reference decides."""
    train = [_walk(w, e, seed=w) for w in range(5) for e in EMOTIONS]
    obs = O.train_bml_observer(train)
    assert obs.classes == ("happy", "sad", "angry", "neutral")
    neutral = _walk(5, "neutral", seed=5).motion
    slowed = _walk(5, "sad", seed=5).motion
    ref = O.reference_descriptor(neutral)
    r = obs.read(slowed, ref)
    assert r["top"] == "sad", r
    assert obs.read(neutral, ref)["top"] == "neutral"
    slowest = O.reference_descriptor(_walk(4, "neutral", seed=4).motion)
    assert obs.read(slowed, slowest)["top"] != "sad"


@pytest.mark.slow
@pytest.mark.skipif(not DEFAULT_BML_PATH.is_file(), reason="BML corpus var/mocap/emotion-gait-bml.npz not built "
                    "(docs/mocap.md, A positions-only dataset)")
def test_bml_emotions_of_unseen_actors_above_chance():
    """Held out by actor on the real BML walks (acted labels): happy, sad and angry each read as themselves more
    often than chance (1/4) (docs/benchmarks/rbf.md, BML observer)."""
    clips = O.load_bml_walks()
    out = O.heldout_by_walker(clips)
    assert out["takes"] == {"happy": 30, "sad": 30, "angry": 30, "neutral": 30}
    for k in ("happy", "sad", "angry"):
        assert out["recall"][k] > 0.25, out["recall"]
