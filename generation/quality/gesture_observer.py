"""A synthetic observer of gesture emotion: a multinomial logistic regression over the 11 gesture emotions
(protocol.vocabulary.GESTURE_EMOTIONS) on motion descriptors of the seated upper body, trained on the procedural
gestures of the SYNTHETIC gesture corpus's training split (:func:`generation.gesture.data.build_dataset`).

It stands in for a participant when checking clips; it is not a human judgement, and what it learned is the
procedural generator's mapping from an emotion's VAD values to gesture style (arousal -> speed, amplitude and head
motion; dominance -> expansion and an upright trunk), not how people show emotions.

The descriptors (:func:`motion_descriptors`; also the inputs of the binary arousal/dominance observers of
benchmarks/bench_gesture.py) are the mean and standard deviation over frames of the 15 gesture affective features
plus the peak and mean wrist speed, measured at the corpus frame rate (10 fps; clips are resampled to it first).

:func:`load_gesture_observer` trains it once per corpus and generator version and keeps the fitted model in
``var/quality/gesture_observer_<key>.pkl``; :class:`generation.quality.observers.Observers` keeps it in memory per
process (keyed by :func:`observer_version`).
"""
from __future__ import annotations

import hashlib
import warnings
from pathlib import Path

import numpy as np

from generation.core.features import np_gesture_affective_features
from generation.core.kinematics import np_forward_kinematics
from generation.core.motion import Motion
from generation.core.skeleton import GESTURE_JOINTS, gesture_skeleton
from generation.gesture import config
from generation.gesture.config import MIN_SECONDS
from generation.gesture.metrics import wrist_speed_of_positions
from protocol.vocabulary import GESTURE_EMOTIONS, GESTURE_VAD

from .pickle_cache import load_or_build

REPO_ROOT = Path(__file__).resolve().parents[2]
CACHE_DIR = REPO_ROOT / "var" / "quality"
#: Inverse regularisation strength, chosen on the corpus's validation split (C in 0.1..10: 0.83-0.97 accuracy).
REGULARISATION_C = 3.0
AROUSAL_SPLIT = 0.5  # NRC-VAD arousal above it: the high-arousal half (8 of the 11 emotions)
#: (11,) NRC-VAD arousal of GESTURE_EMOTIONS, in that order.
AROUSAL = np.array([GESTURE_VAD[e][1] for e in GESTURE_EMOTIONS])
N_DESCRIPTORS = 32  # 15 feature means + 15 feature SDs + peak and mean wrist speed


# ---- descriptors (shared with benchmarks/bench_gesture.py) ----------------------------------------------------
def positions_of(rotations: np.ndarray, data, i: int) -> np.ndarray:
    """(T, 23, 4) local rotations -> (T, 23, 3) joint positions, metres, on the body (gender build) and seated root
    of example ``i`` of a :class:`generation.gesture.data.GestureDataset` ``data``."""
    sk = gesture_skeleton(build=str(data.gender[i]))
    return np_forward_kinematics(rotations, np.repeat(data.root[i][None].astype(np.float64), len(rotations), 0), sk)


def motion_descriptors(positions: np.ndarray, fps: float) -> dict[str, float]:
    """Speed: 90th percentile over frames of the faster wrist's speed (m/s), i.e. the peak speed of the arm
    swings; expansion: mean wrist spread d(10,14)/d(0,6) (feature D3/D6 of seed 003 Fig. 4); plus the mean and
    std of the 15 affective features and both speed measures (the observers' inputs, ``features`` (32,)).

    positions: (T, 23, 3) metres on the gesture skeleton, T >= 2, at ``fps``.

    The speed measure (the "peak" of :func:`generation.gesture.metrics.wrist_speed_of_positions`) was chosen on the
    procedural training gestures (Pearson r with arousal 0.47 there, against -0.20 for the clip-mean speed of both
    wrists, which rest holds and two-handed gestures dilute)."""
    ws = wrist_speed_of_positions(positions, fps)
    feats = np_gesture_affective_features(positions)
    return {"speed": ws["peak"], "expansion": float(feats[:, 11].mean()), "features": np.concatenate(
        [feats.mean(0), feats.std(0), [ws["peak"], ws["mean"]]])}


def corpus_descriptors(data, idx) -> np.ndarray:
    """(len(idx), 32) :func:`motion_descriptors` features of the procedural gestures ``idx`` of ``data``."""
    return np.stack([motion_descriptors(positions_of(data.rotations[i, : data.lengths[i]].astype(np.float64),
                                                     data, i), data.fps)["features"] for i in idx])


def is_gesture_motion(motion: Motion) -> bool:
    """Whether ``motion`` is on the 23-joint gesture skeleton (the observer's input) with at least 2 frames."""
    return tuple(motion.skeleton.joints) == tuple(GESTURE_JOINTS) and motion.num_frames >= 2


def arousal_half(emotion: str) -> str:
    """"high" or "low": the NRC-VAD arousal of a gesture emotion above or at most 0.5."""
    if emotion not in GESTURE_VAD:
        raise ValueError(f"unknown gesture emotion {emotion!r}; expected one of {', '.join(GESTURE_EMOTIONS)}")
    return "high" if GESTURE_VAD[emotion][1] > AROUSAL_SPLIT else "low"


# ---- the observer ---------------------------------------------------------------------------------------------
class GestureObserver:
    """Multinomial logistic regression (standardised features) over GESTURE_EMOTIONS (synthetic observer).

    Args:
        X: (N, 32) :func:`motion_descriptors` features at ``fps``; y: (N,) emotion names (GESTURE_EMOTIONS).
        fps: the frame rate the descriptors were measured at; motions are resampled to it before observing.
        C: inverse regularisation strength.
        min_seconds: the shortest clip the gate lets it read (:meth:`reads`): the descriptors of much shorter clips
            than the training gestures are out of its range (a 1 s neutral gesture reads as joyous).
    """

    labels = GESTURE_EMOTIONS
    kind = "synthetic-gesture"
    source = "synthetic procedural gesture corpus (training split)"

    def __init__(self, X: np.ndarray, y, fps: float, C: float = REGULARISATION_C, min_seconds: float = 0.0):
        from sklearn.linear_model import LogisticRegression
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler

        X = np.asarray(X, dtype=np.float64)
        y = np.asarray(y).astype(str)
        if X.ndim != 2 or X.shape[1] != N_DESCRIPTORS or len(X) != len(y):
            raise ValueError(f"X must be (N, {N_DESCRIPTORS}) with one label per row, got {X.shape}, {len(y)} labels")
        unknown = sorted(set(y) - set(GESTURE_EMOTIONS))
        if unknown:
            raise ValueError(f"labels not in GESTURE_EMOTIONS: {unknown}")
        self.fps = float(fps)
        self.min_seconds = float(min_seconds)
        self.clf = make_pipeline(StandardScaler(), LogisticRegression(max_iter=5000, C=C)).fit(X, y)
        self._columns = [list(self.clf.classes_).index(e) if e in self.clf.classes_ else None
                         for e in GESTURE_EMOTIONS]

    @classmethod
    def from_corpus(cls, data, idx=None, C: float = REGULARISATION_C) -> GestureObserver:
        """Fitted on the procedural gestures ``idx`` of ``data`` (default: the training split), labelled with the
        emotion each gesture performs (``data.emotion``; the counterfactual variants included). ``min_seconds``:
        the shortest of them (2.7 s in the shipped corpus) or the shortest gesture the network makes
        (:data:`generation.gesture.config.MIN_SECONDS`, 2.5 s), whichever is shorter."""

        idx = data.indices("train") if idx is None else np.asarray(idx)
        return cls(corpus_descriptors(data, idx), data.emotion[idx], data.fps, C,
                   min_seconds=min(float(data.lengths[idx].min()) / data.fps, MIN_SECONDS))

    def reads(self, motion: Motion) -> bool:
        """Whether the quality gate asks this observer about ``motion``: a gesture-skeleton motion lasting at least
        :attr:`min_seconds` (frames / fps)."""
        return is_gesture_motion(motion) and motion.num_frames / motion.fps >= self.min_seconds - 1e-9

    def features(self, motions: list[Motion]) -> np.ndarray:
        """(N, 32) descriptors of gesture motions, each resampled to the observer's frame rate first (kept at its
        own rate when that would leave fewer than 2 frames, i.e. clips shorter than 2 corpus frames)."""
        rows = []
        for m in motions:
            if not is_gesture_motion(m):
                raise ValueError(f"the gesture observer reads the 23-joint gesture skeleton with >= 2 frames, got "
                                 f"{m.skeleton.name!r} ({m.skeleton.num_joints} joints, {m.num_frames} frames)")
            resampled = m.resample(self.fps)
            if resampled.num_frames >= 2:
                m = resampled
            rows.append(motion_descriptors(m.positions(), m.fps)["features"])
        return np.stack(rows)

    def proba_features(self, X: np.ndarray) -> np.ndarray:
        """(N, 11) probabilities in GESTURE_EMOTIONS order (0 for an emotion absent from the training labels)."""
        p = self.clf.predict_proba(np.asarray(X, dtype=np.float64))
        out = np.zeros((len(p), len(GESTURE_EMOTIONS)))
        for k, col in enumerate(self._columns):
            if col is not None:
                out[:, k] = p[:, col]
        return out

    def proba_motions(self, motions: list[Motion]) -> np.ndarray:
        """(N, 11) probabilities in GESTURE_EMOTIONS order."""
        return self.proba_features(self.features(motions))

    def read(self, motion: Motion) -> dict:
        """The quality record's reading: ``observed`` (top label), ``observed_p`` (its probability) and
        ``observed_arousal`` (what the gesture ``observer`` check compares), and ``observer``: synthetic-gesture."""
        label, p, arousal = self.reading(motion)
        return {"observed": label, "observed_p": round(p, 4), "observed_arousal": round(arousal, 4),
                "observer": self.kind}

    def observe(self, motion: Motion) -> tuple[str, float]:
        """(top label, its probability) for one gesture motion."""
        label, p, _ = self.reading(motion)
        return label, p

    def reading(self, motion: Motion) -> tuple[str, float, float]:
        """(top label, its probability, the observed arousal) for one gesture motion: the observed arousal is the
        NRC-VAD arousal (0..1) of the 11 emotions weighted by their probabilities; the quality gate's ``observer``
        check compares it with the intended emotion's arousal."""
        p = self.proba_motions([motion])[0]
        k = int(np.argmax(p))
        return GESTURE_EMOTIONS[k], float(p[k]), float(p @ AROUSAL)


# ---- training and the cache --------------------------------------------------------------------------------
#: Source files the descriptors are computed by (besides this module); a change retrains the cached observer.
FEATURE_SOURCES = (REPO_ROOT / "generation" / "core" / "features.py",
                   REPO_ROOT / "generation" / "gesture" / "metrics.py")


def corpus_version() -> str:
    """Key of the corpus and observer version: a hash of the sentence CSV, the procedural generator and corpus
    code (:func:`generation.gesture.config.generator_fingerprint`), the feature code and this module's source."""
    h = hashlib.sha256()
    h.update(Path(config.SENTENCES_CSV).read_bytes())
    h.update(config.generator_fingerprint().encode())
    for path in (*FEATURE_SOURCES, Path(__file__)):
        h.update(path.read_bytes())
    return h.hexdigest()[:12]


def train_gesture_observer(data=None) -> GestureObserver:
    """A GestureObserver fitted on the training split of the synthetic gesture corpus (built when missing)."""
    from generation.gesture.data import build_dataset  # heavy: torch

    data = build_dataset() if data is None else data
    return GestureObserver.from_corpus(data)


def observer_version() -> str | None:
    """:func:`corpus_version`, or None (with a warning) when the corpus files cannot be read here."""
    try:
        return corpus_version()
    except OSError as exc:
        warnings.warn(f"gesture observer unavailable: {exc}", stacklevel=2)
        return None


def load_gesture_observer() -> GestureObserver | None:
    """The observer of the current corpus: from the cache file, or trained (and cached); None (with a warning)
    when the corpus cannot be built here (clips then get no gesture observer reading)."""
    key = observer_version()
    if key is None:
        return None
    try:
        return load_or_build(CACHE_DIR / f"gesture_observer_{key}.pkl", GestureObserver, train_gesture_observer)
    except Exception as exc:  # noqa: BLE001 - any failure to build the corpus leaves clips without a reading
        warnings.warn(f"gesture observer could not be trained ({type(exc).__name__}: {exc})", stacklevel=2)
        return None
