"""Walker-normalised style observers (generation/rbf/observer.py): a synthetic check that can fail, and the held-out
recall on real walks (Bandai Namco, CC BY-NC 4.0, Kobayashi et al. 2023) when the corpus is built."""
from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from generation.mocap.real_corpus import DEFAULT_PATH
from generation.procedural.walk import WalkParams, walk
from generation.rbf import observer as O

# six walkers whose habitual walks differ more than one walker's styles do (cadence 96-124, stride 1.20-1.60 m)
WALKERS = [(96, 1.60, 0.20), (124, 1.20, 0.40), (104, 1.50, 0.45), (118, 1.30, 0.15), (100, 1.25, 0.35),
           (120, 1.55, 0.25)]
TRAIN = tuple(f"walker-{w}" for w in range(4))
HELD = ("walker-4", "walker-5")
STYLES = {"normal": (1.0, 1.0, 0.0), "active": (1.12, 1.6, -0.05), "tired": (0.88, 0.5, 0.30)}


def _walks(walker: int, split: str) -> list:
    cadence, stride, swing = WALKERS[walker]
    out = []
    for style, (k_cad, k_swing, head) in STYLES.items():
        base = WalkParams(cadence_spm=cadence, stride_m=stride, arm_swing_rad=swing)
        params = replace(base, cadence_spm=cadence * k_cad, arm_swing_rad=swing * k_swing,
                         head_pitch_rad=base.head_pitch_rad + head)
        out.append(SimpleNamespace(name=f"w{walker}_{style}", dataset=f"walker-{walker}", content="walk",
                                   style=style, split=split, motion=walk(params, n_frames=180, seed=walker)))
    return out


@pytest.fixture(scope="module")
def synthetic():
    train = [c for w in range(4) for c in _walks(w, "train")]
    held = [c for w in (4, 5) for c in _walks(w, "test")]
    return train, held


def test_walker_normalisation_reads_styles_of_unseen_walkers(synthetic):
    """Trained on four walkers, read two others relative to their own normal walk: every styled walk is read as its
    style. Without the walker reference the same classifier family confuses walkers with styles."""
    train, held = synthetic
    walker = O.RbfStyleObserver.fit(train, "energy", "walker", datasets=TRAIN)
    refs = O.dataset_references(held, ("test",))
    out = walker.heldout(held, ("test",), refs, HELD)
    assert out["takes"] == {"energetic": 2, "normal": 2, "tired": 2}
    assert out["recall"]["energetic"] == 1.0 and out["recall"]["tired"] == 1.0
    plain = O.RbfStyleObserver.fit(train, "energy", "none", datasets=TRAIN).heldout(held, ("test",), {}, HELD)
    assert np.mean([r["p"][r["class"]] for r in out["rows"]]) > np.mean([r["p"][r["class"]] for r in plain["rows"]])
    with pytest.raises(ValueError, match="reference"):
        walker.read(held[1].motion)


def test_reading_the_reference_itself_is_neutral(synthetic):
    train, held = synthetic
    obs = O.RbfStyleObserver.fit(train, "energy", "walker", datasets=TRAIN)
    normal = next(c.motion for c in held if c.style == "normal")
    assert obs.read(normal, reference=normal)["top"] == "normal"


def test_fit_refuses_a_class_without_takes(synthetic):
    train, _ = synthetic
    with pytest.raises(ValueError, match="no training takes"):
        O.RbfStyleObserver.fit([c for c in train if c.style != "tired"], "energy", datasets=TRAIN)
    with pytest.raises(ValueError, match="normalise"):
        O.RbfStyleObserver.fit(train, "energy", "global", datasets=TRAIN)


@pytest.mark.slow
@pytest.mark.skipif(not DEFAULT_PATH.is_file(), reason="real corpus not built (docs/corpus.md)")
def test_heldout_recall_on_real_walks_is_above_chance():
    """Held out by take (val and test takes of both datasets): recall of each class above chance (1 / classes) on
    the energy and gender scales, which have held-out takes in both datasets."""
    obs, clips = O.train_observers(DEFAULT_PATH)
    held = obs.heldout(clips)
    for scale in ("energy", "gender"):
        k = len(O.SCALES[scale])
        for cls, recall in held[scale]["recall"].items():
            assert recall is not None and recall > 1.0 / k, (scale, cls, held[scale]["recall"])


@pytest.mark.slow
@pytest.mark.skipif(not DEFAULT_PATH.is_file(), reason="real corpus not built (docs/corpus.md)")
def test_extended_walks_read_as_their_theme_at_full_weight():
    """With the extended intensities, happy, tired and feminine at w = 1 (ten features) are read as their style
    relative to the neutral walk, and every theme's p(theme) rises from w = 0.4 to 1.0 (docs/benchmarks/rbf.md)."""
    from generation.rbf.real_neutral import load_cycle
    from generation.rbf.stylise import neutral_walk, stylise

    obs, _ = O.train_observers(DEFAULT_PATH)
    base = load_cycle()
    ref = O.reference_descriptor(neutral_walk(base, n_cycles=3, fps=25.0))
    for theme in O.THEME_SCALE:
        low, full = (obs.read_theme(stylise(base, theme, w, 10, n_cycles=3, fps=25.0), theme, ref) for w in (0.4, 1.0))
        assert full["p_target"] > low["p_target"], theme
        if theme in ("happy", "tired", "feminine"):
            assert full["top"] == O.THEME_SCALE[theme][1], (theme, full)
