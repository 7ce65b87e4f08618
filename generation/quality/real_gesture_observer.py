"""A real-capture gesture observer: which gesture emotion a seated gesture shows, learned from REAL captured gestures
(Bandai Namco Research Motion Dataset 1, Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0), with its accuracy
on held-out takes.

Inputs per clip (:func:`real_gesture_features`, (42,)): the synthetic observer's 32 descriptors
(:func:`generation.quality.gesture_observer.motion_descriptors`) and the 10 statistics of
:func:`generation.gesture.real_stats.gesture_stats`, at the network's 10 fps. Classes: the styles that name a
gesture emotion (``protocol.vocabulary.CAPTURE_GESTURE_EMOTIONS``: joyous, sad, angry, proud, neutral) or, with
``labels="style"``, every dataset-1 style. Model: multinomial logistic regression on standardised features.

Held-out accuracy (:func:`held_out_accuracy`): dataset 1 has one take per content and style (bow, bye, byebye,
guide), so each fold holds out every take of one content (leave one content out): the observer never sees the take
it reads, nor that action in any style. The quality gate uses an observer only where that accuracy is good
(:data:`GATE_MIN_ACCURACY`); :func:`gate_ready` says whether this one is.
"""
from __future__ import annotations

import numpy as np

from generation.core.motion import Motion
from generation.gesture.real_stats import STAT_NAMES, STATS_FPS, gesture_stats
from protocol.vocabulary import CAPTURE_GESTURE_EMOTIONS

from .gesture_observer import is_gesture_motion, motion_descriptors

#: Held-out accuracy an observer needs before the quality gate may use it (chance is 0.2 for five emotions).
GATE_MIN_ACCURACY = 0.75
REGULARISATION_C = 1.0
STYLES_15 = ("normal", "happy", "sad", "angry", "proud", "not-confident", "masculinity", "feminine", "childish", "old",
             "tired", "active", "musical", "giant", "chimpira")


def real_gesture_features(motion: Motion) -> np.ndarray:
    """(42,) features of a seated gesture Motion on the gesture skeleton (resampled to 10 fps first)."""
    if not is_gesture_motion(motion):
        raise ValueError(f"the real gesture observer reads the 23-joint gesture skeleton with >= 2 frames, got "
                         f"{motion.skeleton.name!r} ({motion.num_frames} frames)")
    m = motion.resample(STATS_FPS) if abs(motion.fps - STATS_FPS) > 1e-9 else motion
    return features_of_positions(m.positions(), m.fps)


def features_of_positions(P: np.ndarray, fps: float) -> np.ndarray:
    """(42,) features of seated gesture joint positions P (T, 23, 3) metres at ``fps`` (10 fps for the observer)."""
    stats = gesture_stats(P, fps)
    return np.concatenate([motion_descriptors(P, fps)["features"], [stats[k] for k in STAT_NAMES]])


class RealGestureObserver:
    """Logistic regression over real seated gestures' features. X (N, 42), y (N,) labels."""

    def __init__(self, X: np.ndarray, y, C: float = REGULARISATION_C):
        from sklearn.linear_model import LogisticRegression
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler

        X, y = np.asarray(X, dtype=np.float64), np.asarray(y).astype(str)
        if X.ndim != 2 or len(X) != len(y) or len(np.unique(y)) < 2:
            raise ValueError(f"need (N, F) features with one label each and at least 2 labels, got {X.shape}, "
                             f"{len(np.unique(y))} labels")
        self.clf = make_pipeline(StandardScaler(), LogisticRegression(max_iter=5000, C=C)).fit(X, y)
        self.labels = tuple(self.clf.classes_)

    def predict(self, X: np.ndarray) -> np.ndarray:
        return self.clf.predict(np.asarray(X, dtype=np.float64))

    def observe(self, motion: Motion) -> tuple[str, float]:
        """(top label, its probability) for one seated gesture."""
        p = self.clf.predict_proba(real_gesture_features(motion)[None])[0]
        k = int(np.argmax(p))
        return str(self.labels[k]), float(p[k])


def real_gesture_dataset(clips, labels: str = "emotion") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(X (N, 42), y (N,), content (N,)) of real seated clips [(name, style, Motion)] (names
    ``dataset-1_<content>_<style>_<take>``); ``labels``: "emotion" keeps the emotion styles and labels them with
    their gesture emotion, "style" keeps every clip labelled with its style."""
    if labels not in ("emotion", "style"):
        raise ValueError(f"labels must be 'emotion' or 'style', got {labels!r}")
    X, y, content = [], [], []
    for name, style, motion in clips:
        label = CAPTURE_GESTURE_EMOTIONS.get(style) if labels == "emotion" else style
        if label is None:
            continue
        X.append(real_gesture_features(motion))
        y.append(label)
        content.append(name.split("_")[1])
    return np.array(X), np.array(y), np.array(content)


def held_out_accuracy(X: np.ndarray, y: np.ndarray, groups: np.ndarray, C: float = REGULARISATION_C) -> dict:
    """Leave-one-group-out evaluation (a group = one content: every take of it held out at once).

    Returns {"accuracy", "n", "per_group": {group: accuracy}, "labels", "confusion": rows = true, columns =
    predicted, in ``labels`` order, "per_class": {label: recall}}."""
    y = np.asarray(y).astype(str)
    pred = np.empty(len(y), dtype=object)
    for g in np.unique(groups):
        test = groups == g
        pred[test] = RealGestureObserver(X[~test], y[~test], C).predict(X[test])
    labels = [str(v) for v in sorted(np.unique(y))]
    confusion = [[int(((y == a) & (pred == b)).sum()) for b in labels] for a in labels]
    return {"accuracy": float((pred == y).mean()), "n": int(len(y)),
            "per_group": {str(g): float((pred[groups == g] == y[groups == g]).mean()) for g in np.unique(groups)},
            "labels": labels, "confusion": confusion,
            "per_class": {a: float((pred[y == a] == a).mean()) for a in labels}}


def gate_ready(evaluation: dict, min_accuracy: float = GATE_MIN_ACCURACY) -> bool:
    """Whether a held-out evaluation (:func:`held_out_accuracy`) is good enough for the quality gate."""
    return evaluation["accuracy"] >= min_accuracy
