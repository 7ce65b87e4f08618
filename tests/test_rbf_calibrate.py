"""Calibrated intensities of seed 004's expert features, and the style observers that read the styled walks.

The fast tests use the shipped files (generation/data/rbf/) and the shipped real takes (generation/data/mocap/
bandai-namco/, CC BY-NC 4.0, Kobayashi et al. 2023); the slow one refits on the full corpus when it is built.
"""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from generation.mocap.real_corpus import DEFAULT_PATH, load_real_corpus
from generation.rbf import calibrate as C
from generation.rbf.real_neutral import load_cycle
from generation.rbf.stylise import stylise, stylised_cycle
from generation.rbf.themes import CALIBRATED_PATH, THEME_NAMES, THEMES, calibrated_intensities, theme_features

HELDOUT_SLACK = 0.01  # heights (1.75 cm): tolerance on top of the real takes' own train-vs-held-out disagreement


@pytest.fixture(scope="module")
def base():
    return load_cycle()


@pytest.fixture(scope="module")
def shipped():
    return json.loads(CALIBRATED_PATH.read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def shipped_walks():
    from generation.quality.real_observer import shipped_clips

    return [c for c in shipped_clips() if c.content == "walk"]


def test_visual_set_is_the_old_numbers_exactly(base):
    for theme in THEME_NAMES:
        assert theme_features(theme, None, "visual") == THEMES[theme]
    old = {r: f.intensity for f in THEMES["sad"] for r in [f.rank]}
    a = stylised_cycle(base, "sad", 0.7, 10, intensities="visual")
    b = stylised_cycle(base, "sad", 0.7, 10, intensities=old)
    np.testing.assert_array_equal(a["rotations"], b["rotations"])
    clip = stylise(base, "sad", 0.7, 10, n_cycles=1, plant=False, intensities="visual")
    assert clip.metadata["intensities"] == "visual"


def test_calibrated_is_selectable_and_carries_the_licence(base):
    # no longer the default (extended is, tests/test_rbf_extended.py); still selectable by name
    out = stylise(base, "tired", 1.0, 10, n_cycles=1, plant=False, intensities="calibrated")
    assert out.metadata["intensities"] == "calibrated" and out.metadata["licence"] == "CC BY-NC 4.0"
    cal = calibrated_intensities()["tired"]
    assert [f.intensity for f in theme_features("tired", None, "calibrated")] == [cal[r] for r in range(1, 11)]
    with pytest.raises(ValueError, match="intensities"):
        stylise(base, "tired", 1.0, 10, intensities="louder")


def test_shipped_file_names_its_data_and_keeps_the_experts_features(shipped):
    assert shipped["licence"] == "CC BY-NC 4.0" and "Kobayashi" in shipped["citation"]
    for theme in THEME_NAMES:
        rows = shipped["themes"][theme]["features"]
        assert [r["feature"] for r in rows] == [f.describe() for f in THEMES[theme]]
        assert [r["visual"] for r in rows] == [f.intensity for f in THEMES[theme]]
        assert all(0 <= r["calibrated"] <= C.MAX_FACTOR * r["visual"] + 1e-9 for r in rows)


def test_w1_reproduces_the_heldout_real_difference(base, shipped):
    """At w = 1 the calibrated edit's measures are as close to the held-out takes' real differences as the training
    takes' real differences are, plus 1 cm; closer than the visual set's on the whole, and for tired, feminine and
    masculine (many held-out takes in both datasets) at most half the visual set's error."""
    calibrated_err, visual_err = [], []
    for theme in THEME_NAMES:
        groups = shipped["themes"][theme]["groups"]
        train = np.array([g["real_train"] for g in groups])
        held = np.array([g["real_heldout"] for g in groups])
        reached = C.generated_measures(base, theme, "calibrated")
        visual = C.generated_measures(base, theme, "visual")
        np.testing.assert_allclose(reached, [g["calibrated_w1"] for g in groups], atol=1e-5)  # the file is current
        assert np.abs(reached - held).mean() <= np.abs(train - held).mean() + HELDOUT_SLACK, theme
        calibrated_err.append(np.abs(reached - held).mean())
        visual_err.append(np.abs(visual - held).mean())
        if theme in ("tired", "feminine", "masculine"):
            assert calibrated_err[-1] <= 0.5 * visual_err[-1], theme
    assert np.mean(calibrated_err) < np.mean(visual_err)


def test_inversion_moves_the_other_way(base):
    """w = -1 reverses at least half of a theme's changes and its largest one; energetic's largest (elbow swing
    along Z, peak-to-peak) is the known exception: a strongly decreased swing overshoots and swings the other way."""
    for theme in THEME_NAMES:
        up = C.generated_measures(base, theme, "calibrated", 1.0)
        down = C.generated_measures(base, theme, "calibrated", -1.0)
        moved = np.abs(up) > 0.005
        reversed_ = np.sign(up[moved]) != np.sign(down[moved])
        assert reversed_.mean() >= 0.5, theme
        k = int(np.argmax(np.abs(up)))
        assert bool(np.sign(down[k]) == -np.sign(up[k])) == (theme != "energetic"), theme


def test_real_differences_of_shipped_takes(shipped_walks):
    d, info = C.real_differences(shipped_walks, "sad", ("train",))
    assert info[0]["dataset"] == "bandai-namco-1" and info[0]["takes"] == 1 and d.shape == (len(C.theme_groups("sad")),)
    sad = next(c for c in shipped_walks if c.style == "sad")
    normal = next(c for c in shipped_walks if c.style == "normal")
    np.testing.assert_allclose(d, C._take_measures(sad, "sad", 100) - C._take_measures(normal, "sad", 100))
    with pytest.raises(ValueError, match="no dataset"):
        C.real_differences(shipped_walks, "sad", ("test",))


def test_calibration_reaches_a_reachable_target(base):
    """Targets made by the visual set at w = 0.5 are reached by factors near 0.5 (the fit can find what exists)."""
    target = C.generated_measures(base, "feminine", "visual", 0.5)
    factors, reached = C.calibrate_theme(base, "feminine", target)
    np.testing.assert_allclose(reached, target, atol=2e-3)


def test_style_observers_on_shipped_takes(shipped_walks):
    from generation.quality.style_observer import StyleObserver, StyleObservers

    clips = list(shipped_walks)
    # a held-out copy: the second half of each take (whole takes held out in the corpus; here the shipped subset)
    held = [dataclasses.replace(c, split="test", motion=c.motion.slice(c.motion.num_frames // 2, None))
            for c in clips if c.style in ("active", "tired", "normal")]
    obs = StyleObservers(clips)
    out = obs.scales["energy"].heldout(held)
    assert out["takes"] == {"energetic": 1, "normal": 1, "tired": 1}
    assert out["recall"]["energetic"] == 1.0 and out["recall"]["tired"] == 1.0
    r = obs.read_theme(next(c for c in clips if c.style == "feminine").motion, "feminine")
    assert r["scale"] == "gender" and r["top"] == "feminine"
    with pytest.raises(ValueError, match="no training takes"):
        StyleObserver.fit([c for c in clips if c.style != "tired"], "energy")


@pytest.mark.slow
@pytest.mark.skipif(not DEFAULT_PATH.is_file(), reason="real corpus not built (docs/corpus.md)")
def test_refit_on_the_corpus_matches_the_shipped_file(base, shipped):
    clips = load_real_corpus(DEFAULT_PATH, skeleton="gait", contents=["walk"])
    for theme in ("tired", "masculine"):
        train, _ = C.real_differences(clips, theme, ("train",))
        np.testing.assert_allclose(train, [g["real_train"] for g in shipped["themes"][theme]["groups"]], atol=1e-5)
