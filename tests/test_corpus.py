"""Emotion mappings, simulated annotators, and the synthetic gait / gesture corpora."""
import json

import numpy as np
import pytest

from generation.core.features import np_gait_affective_features
from generation.procedural.corpus import (
    CorpusFormatError,
    GaitCorpus,
    GestureCorpus,
    build_gait_corpus,
    build_gesture_corpus,
    sample_true_emotions,
)
from generation.procedural.emotion import (
    gait_params_for_emotion,
    gesture_params_for_vad,
    normalize_emotion,
    simulate_annotators,
    vad_for,
)
from protocol.vocabulary import GAIT_EMOTIONS, GESTURE_EMOTIONS, GESTURE_VAD


@pytest.fixture(scope="module")
def small_corpus():
    return build_gait_corpus(40, seed=3, frames=64)


# ---- emotion ---------------------------------------------------------------------------------------
def test_nrc_vad_table_and_gesture_emotions():
    assert len(GESTURE_VAD) == 11
    assert GESTURE_VAD["proud"] == pytest.approx((0.906, 0.700, 0.873))
    assert GESTURE_VAD["sad"] == pytest.approx((0.225, 0.333, 0.149))
    assert tuple(GESTURE_VAD) == GESTURE_EMOTIONS
    assert all(0.0 <= x <= 1.0 for vad in GESTURE_VAD.values() for x in vad)


def test_vad_for_names_the_known_words():
    assert vad_for(" Proud ") == GESTURE_VAD["proud"]
    with pytest.raises(KeyError, match="known words"):
        vad_for("happy")  # a gait emotion, not one of the 11 gesture categories


def test_normalize_emotion():
    np.testing.assert_allclose(normalize_emotion([2, 0, 1, 1]), [0.5, 0, 0.25, 0.25])
    np.testing.assert_allclose(normalize_emotion({"sad": 3.0}), [0, 1, 0, 0])
    for bad, msg in (([1, 2, 3], "4 entries"), ([1, -1, 0, 0], "non-negative"), ([0, 0, 0, 0], "sums to zero"),
                     ([np.nan, 1, 0, 0], "NaN"), ({"joy": 1.0}, "unknown")):
        with pytest.raises(ValueError, match=msg):
            normalize_emotion(bad)


def test_simulated_annotators_are_relative_counts():
    rng = np.random.default_rng(0)
    labels = np.stack([simulate_annotators([1, 0, 0, 0], 10, rng) for _ in range(2000)])
    np.testing.assert_allclose(labels.sum(1), 1.0)
    np.testing.assert_allclose(labels * 10, np.round(labels * 10))        # multiples of 1/n
    mean = labels.mean(0)
    assert mean[0] == pytest.approx(0.75, abs=0.02)                       # 1 - confusion
    assert mean[3] > mean[1]                                              # happy is confused with neutral, not sad
    with pytest.raises(ValueError, match="n_annotators"):
        simulate_annotators([1, 0, 0, 0], 0, rng)


def test_gait_params_follow_the_literature_and_vary_continuously():
    p = {e: gait_params_for_emotion(np.eye(4)[i]) for i, e in enumerate(GAIT_EMOTIONS)}
    assert p["sad"].speed_mps < p["neutral"].speed_mps < min(p["happy"].speed_mps, p["angry"].speed_mps)
    assert p["sad"].head_pitch_rad > p["neutral"].head_pitch_rad > p["happy"].head_pitch_rad
    assert p["sad"].arm_abduction_rad < p["neutral"].arm_abduction_rad < p["angry"].arm_abduction_rad
    assert p["angry"].torso_pitch_rad > p["neutral"].torso_pitch_rad
    assert p["happy"].bounce_m > p["neutral"].bounce_m > p["sad"].bounce_m
    # mixtures interpolate: speed is monotone along sad -> happy
    speeds = [gait_params_for_emotion([w, 1 - w, 0, 0]).speed_mps for w in np.linspace(0, 1, 6)]
    assert np.all(np.diff(speeds) > 0)
    a = gait_params_for_emotion([0.5, 0.5, 0, 0]).to_dict()
    b = gait_params_for_emotion([0.51, 0.49, 0, 0]).to_dict()
    assert max(abs(a[k] - b[k]) for k in a) < 1.0                          # small change in, small change out
    # individual variation with an rng, deterministic per seed
    r1 = gait_params_for_emotion([1, 0, 0, 0], np.random.default_rng(1))
    r2 = gait_params_for_emotion([1, 0, 0, 0], np.random.default_rng(1))
    assert r1 == r2 and r1 != p["happy"]


def test_gesture_params_follow_arousal_and_dominance():
    lo = gesture_params_for_vad(*GESTURE_VAD["sad"], kind="beat")
    hi = gesture_params_for_vad(*GESTURE_VAD["proud"], kind="beat")
    assert hi.speed > lo.speed and hi.amplitude > lo.amplitude
    assert hi.expansion > 0 > lo.expansion
    assert lo.torso_lean > hi.torso_lean and lo.head_pitch > hi.head_pitch
    assert gesture_params_for_vad(0.5, 0.5, 0.5, handedness="left", kind="pointing").handedness == "left"
    with pytest.raises(ValueError, match="arousal"):
        gesture_params_for_vad(0.5, 1.5, 0.5)


# ---- gait corpus -------------------------------------------------------------------------------------
def test_gait_corpus_contents(small_corpus):
    c = small_corpus
    assert c.rotations.shape == (40, 64, 21, 4) and c.rotations.dtype == np.float32
    assert c.root_positions.shape == (40, 64, 3)
    np.testing.assert_allclose(c.emotion.sum(1), 1.0, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(c.rotations, axis=-1), 1.0, atol=1e-5)
    pure = c.true_emotion.max(1) > 0.999
    assert 10 <= pure.sum() <= 22 and (~pure).sum() >= 18                 # pure emotions and mixtures
    assert set(c.split) == {"train", "val", "test"}
    assert (c.split == "train").sum() >= 28
    assert len(set(c.path_kind)) >= 2 and set(c.build) == {"male", "female"}
    assert c.height.std() > 0.03
    assert c.metadata["synthetic"] is True
    m = c.motion(0)
    assert m.skeleton.height == pytest.approx(c.height[0]) and m.metadata["synthetic"] is True
    assert "simulated" in c.metadata["labels"]


def test_sample_true_emotions_balanced_pure():
    t = sample_true_emotions(100, np.random.default_rng(0), pure_fraction=0.4)
    pure = t.max(1) > 0.999
    assert pure.sum() == 40
    np.testing.assert_array_equal(np.bincount(t[pure].argmax(1), minlength=4), [10, 10, 10, 10])


def test_gait_corpus_is_deterministic():
    a = build_gait_corpus(6, seed=11, frames=20)
    b = build_gait_corpus(6, seed=11, frames=20)
    c = build_gait_corpus(6, seed=12, frames=20)
    for field in ("rotations", "root_positions", "emotion", "true_emotion", "split", "height"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    assert not np.array_equal(a.rotations, c.rotations)


def test_gait_corpus_save_load_round_trip(small_corpus, tmp_path):
    path = small_corpus.save(tmp_path / "sub" / "gait_corpus_synthetic.npz")
    back = GaitCorpus.load(path)
    np.testing.assert_array_equal(back.rotations, small_corpus.rotations)
    np.testing.assert_array_equal(back.split, small_corpus.split)
    assert back.params == small_corpus.params and back.metadata["synthetic"] is True
    # a file missing a field is reported with the field's name
    data = dict(np.load(path))
    del data["emotion"]
    np.savez(tmp_path / "broken.npz", **data)
    with pytest.raises(CorpusFormatError, match="'emotion'"):
        GaitCorpus.load(tmp_path / "broken.npz")
    with pytest.raises(CorpusFormatError, match="not a readable"):
        GaitCorpus.load(tmp_path / "nothing.npz")


def test_pure_emotions_show_the_expected_feature_directions():
    c = build_gait_corpus(24, seed=0, frames=60, pure_fraction=1.0)
    feats = {e: [] for e in GAIT_EMOTIONS}
    speed = {e: [] for e in GAIT_EMOTIONS}
    for i in range(len(c)):
        e = GAIT_EMOTIONS[int(c.true_emotion[i].argmax())]
        feats[e].append(np_gait_affective_features(c.motion(i).positions()).mean(0))
        speed[e].append(np.linalg.norm(c.root_positions[i, -1, [0, 2]] - c.root_positions[i, 0, [0, 2]]))
    f = {e: np.mean(v, axis=0) for e, v in feats.items()}
    s = {e: np.mean(v) for e, v in speed.items()}
    assert s["sad"] < s["neutral"] < min(s["happy"], s["angry"])
    # feature 4: head-neck-shoulder angle, smaller when the head is bowed
    assert f["sad"][4] < f["neutral"][4] - np.radians(1)
    # feature 13: hand-to-hand distance / neck-root: arms contracted when sad, expanded when happy/angry
    assert f["sad"][13] < f["neutral"][13] < min(f["happy"][13], f["angry"][13])
    # feature 14: toe-to-toe distance (stride) / neck-root
    assert f["sad"][14] < f["neutral"][14] < min(f["happy"][14], f["angry"][14])


# ---- gesture corpus ---------------------------------------------------------------------------------
SPECS = [("proud", "narration", "male", "right", 60), ("sad", "conversation", "female", "left", 40),
         ("afraid", "narration", "female", "right", 50), ("amused", "conversation", "male", "left", 45)]


def test_gesture_corpus_padding_labels_and_determinism(tmp_path):
    g = build_gesture_corpus(SPECS, seed=4)
    assert g.rotations.shape == (4, 60, 23, 4)
    np.testing.assert_array_equal(g.lengths, [60, 40, 50, 45])
    np.testing.assert_allclose(g.vad[0], GESTURE_VAD["proud"], atol=1e-6)
    np.testing.assert_array_equal(g.rotations[1, 40:], np.broadcast_to(g.rotations[1, 39], (20, 23, 4)))
    assert list(g.handedness) == ["right", "left", "right", "left"] and g.metadata["synthetic"] is True
    assert g.motion(1).num_frames == 40 and g.motion(1).skeleton.build == "female"
    again = build_gesture_corpus(SPECS, seed=4)
    np.testing.assert_array_equal(g.rotations, again.rotations)
    back = GestureCorpus.load(g.save(tmp_path / "gesture_corpus_synthetic.npz"))
    np.testing.assert_array_equal(back.rotations, g.rotations)
    assert back.params == json.loads(json.dumps(g.params))


@pytest.mark.parametrize("spec, msg", [
    (("gleeful", "narration", "male", "right", 40), "gleeful"),
    (("sad", "lecture", "male", "right", 40), "task"),
    (("sad", "narration", "robot", "right", 40), "gender"),
    (("sad", "narration", "male", "both", 40), "handedness"),
    (("sad", "narration", "male", "right", 2), "n_frames"),
    (("sad", "narration"), "expected"),
])
def test_gesture_spec_errors(spec, msg):
    with pytest.raises((ValueError, KeyError), match=msg):
        build_gesture_corpus([spec])


# ---- command ----------------------------------------------------------------------------------------
def test_build_corpus_command(tmp_path):
    from io import StringIO

    from django.core.management import call_command

    out = StringIO()
    call_command("build_corpus", out=str(tmp_path), num=8, frames=24, seed=1, stdout=out)
    text = out.getvalue()
    assert "SYNTHETIC gait corpus" in text and "8 sequences" in text
    c = GaitCorpus.load(tmp_path / "gait_corpus_synthetic.npz")
    assert len(c) == 8 and c.num_frames == 24


def test_module_entry_point(tmp_path, capsys):
    from generation.procedural.corpus import main

    assert main(["--out", str(tmp_path), "--num", "5", "--frames", "16"]) == 0
    assert "split" in capsys.readouterr().out
    assert (tmp_path / "gait_corpus_synthetic.npz").exists()
