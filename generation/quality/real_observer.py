"""A real-capture observer of gait emotion: a classifier trained on real captured walks, for the quality gate.

The four gait emotions (protocol.vocabulary.GAIT_EMOTIONS: happy, sad, angry, neutral) are the real corpus's dataset-1
styles happy, sad, angry and normal (protocol.vocabulary.CAPTURE_GAIT_EMOTIONS; the
Bandai Namco Research Motion Dataset,
Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0). Dataset 2's normal walks are left out of the emotion
classifier: only one emotion of the four is in dataset 2, so its actors would teach "dataset 2 = neutral".

**Descriptors** (:func:`window_descriptors`), computed the same way on generated and real motion (both on the
21-joint gait skeleton: real takes are retargeted onto it), per 2 s window (hop 0.5 s; a clip shorter than a
window is one window): the 18 gait affective features of :mod:`generation.core.features` averaged over the
window (clipped to +-10 as the synthetic observer does) and their standard deviations over the window, the
ground-plane root speed and the root's vertical peak-to-peak (both divided by the skeleton's height, so a
smaller body is not "slower"). Windows of 2 s hold about one stride.

**Classifier** (:class:`RealGaitObserver`): standardised multinomial logistic regression (scikit-learn) on the
windows of the training split's takes, each take weighted equally (long takes do not count more); a clip's
probabilities are the mean of its windows' probabilities. The theme pairs (energetic vs tired, feminine vs
masculine, happy vs sad) get one binary classifier each on the same descriptors, trained on both datasets' takes
of those styles (:data:`THEME_PAIRS`); the quality gate does not use them, the benchmark reports where they
separate.

:func:`load_real_observer` trains it once per corpus version (file SHA-256) and keeps it in
``var/quality/real_gait_observer_<sha[:12]>.pkl`` (in memory: :class:`generation.quality.observers.Observers`).
Without the corpus file it trains on the real walks shipped in the repository (generation/data/mocap/bandai-namco/:
one take per emotion, nothing held out; the observer says so in ``source``), and with neither it is None and the
gate says that no real observer is available.
"""
from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np

from generation.core.digest import file_sha256
from generation.core.features import np_gait_affective_features
from generation.core.motion import Motion
from generation.core.skeleton import GAIT_JOINTS
from generation.core.windows import windows
from generation.mocap.bandai_namco import shipped_takes
from generation.mocap.dataset_import import import_take
from generation.mocap.real_corpus import DEFAULT_PATH, load_real_corpus
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS

from .pickle_cache import load_or_build

REPO_ROOT = Path(__file__).resolve().parents[2]
CACHE_DIR = REPO_ROOT / "var" / "quality"
DESCRIPTOR_VERSION = "1"   # bump when the descriptors or the classifier change (it is part of the cache key)
WINDOW_S = 2.0
HOP_S = 0.5
FEATURE_CLIP = 10.0
#: Binary theme classifiers: name -> (first theme's styles, second theme's styles), both datasets.
THEME_PAIRS = {
    "energetic_vs_tired": (("active",), ("tired", "exhausted")),
    "feminine_vs_masculine": (("feminine",), ("masculinity", "masculine")),
    "happy_vs_sad": (("happy",), ("sad",)),
}
EMOTION_DATASET = "bandai-namco-1"


def window_slices(num_frames: int, fps: float) -> list[slice]:
    """2 s windows with 0.5 s hop (the last window ends at the clip's end); one window for a shorter clip."""
    return windows(num_frames, int(round(WINDOW_S * fps)), int(round(HOP_S * fps)), whole_if_short=True)


def window_descriptors(motion: Motion) -> np.ndarray:
    """(W, 38) descriptors of a gait motion's windows (see the module docstring): 18 affective-feature means,
    their 18 standard deviations, root speed / height (1/s) and root vertical peak-to-peak / height."""
    if motion.skeleton.joints != GAIT_JOINTS:
        raise ValueError(f"real observer: expected a motion on the gait skeleton, got {motion.skeleton.name!r}")
    if motion.num_frames < 2:
        raise ValueError("real observer: need at least 2 frames")
    P = motion.positions()
    aff = np.clip(np_gait_affective_features(P), -FEATURE_CLIP, FEATURE_CLIP)        # (T, 18)
    height = motion.skeleton.height if motion.skeleton.height > 0 else 1.75
    root = P[:, 0]
    speed = np.linalg.norm(np.diff(root[:, [0, 2]], axis=0), axis=-1) * motion.fps / height
    speed = np.concatenate([speed[:1], speed])
    rows = []
    for s in window_slices(motion.num_frames, motion.fps):
        rows.append(np.concatenate([aff[s].mean(0), aff[s].std(0),
                                    [speed[s].mean(), np.ptp(root[s, 1]) / height]]))
    return np.asarray(rows)


def _take_windows(motions: list[Motion], labels: list[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stacked windows, their labels and weights (1 / windows of the take, so each take counts once)."""
    X, y, w = [], [], []
    for m, label in zip(motions, labels):
        d = window_descriptors(m)
        X.append(d)
        y.append(np.full(len(d), label))
        w.append(np.full(len(d), 1.0 / len(d)))
    return np.concatenate(X), np.concatenate(y), np.concatenate(w)


def _fit(X: np.ndarray, y: np.ndarray, w: np.ndarray, C: float):
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    clf = make_pipeline(StandardScaler(), LogisticRegression(max_iter=5000, C=C))
    return clf.fit(X, y, logisticregression__sample_weight=w)


class WindowedGaitObserver:
    """What the real-capture gait observers share: a (4,) probability per motion (``proba``, the mean over its 2 s
    windows, by the subclass) read as the top label, on the 21-joint gait skeleton."""

    labels = GAIT_EMOTIONS

    def proba(self, motion: Motion) -> np.ndarray:
        raise NotImplementedError

    def observe(self, motion: Motion) -> tuple[str, float]:
        """(top label, its probability) for one gait motion."""
        p = self.proba(motion)
        k = int(np.argmax(p))
        return self.labels[k], float(p[k])

    def reads(self, motion: Motion) -> bool:
        """Whether the quality gate asks this observer about ``motion``: the 21-joint gait skeleton, >= 2 frames."""
        return motion.skeleton.joints == GAIT_JOINTS and motion.num_frames >= 2


class RealGaitObserver(WindowedGaitObserver):
    """Emotion (and theme-pair) classifiers trained on real captured walks.

    Args:
        clips: training CorpusClips on the gait skeleton (any styles; the emotion styles of
            :data:`EMOTION_DATASET` train the emotion classifier, the :data:`THEME_PAIRS` styles the pairs).
        source: where the clips came from (kept for the record and the benchmark).
        C: inverse regularisation strength of the logistic regressions.
    """

    kind = "real"

    def __init__(self, clips, source: str = "", C: float = 0.1):
        style_to_emotion = {s: GAIT_EMOTIONS.index(e) for s, e in CAPTURE_GAIT_EMOTIONS.items()}
        emo = [c for c in clips if c.dataset == EMOTION_DATASET and c.style in style_to_emotion]
        missing = sorted(set(GAIT_EMOTIONS) - {CAPTURE_GAIT_EMOTIONS[c.style] for c in emo})
        if missing:
            raise ValueError(f"real observer: no {EMOTION_DATASET} training takes for {missing}")
        X, y, w = _take_windows([c.motion for c in emo], [style_to_emotion[c.style] for c in emo])
        self.clf = _fit(X, y, w, C)
        self.train_takes = Counter(CAPTURE_GAIT_EMOTIONS[c.style] for c in emo)
        self.themes = {}
        for name, (first, second) in THEME_PAIRS.items():
            pair = [c for c in clips if c.style in first + second]
            sides = {int(c.style in second) for c in pair}
            if sides != {0, 1}:
                continue
            X, y, w = _take_windows([c.motion for c in pair], [int(c.style in second) for c in pair])
            self.themes[name] = _fit(X, y, w, C)
        self.source = source
        self.C = C

    def proba(self, motion: Motion) -> np.ndarray:
        """(4,) probabilities in GAIT_EMOTIONS order: the mean over the motion's windows."""
        p = self.clf.predict_proba(window_descriptors(motion)).mean(0)
        out = np.zeros(len(GAIT_EMOTIONS))
        out[self.clf.classes_.astype(int)] = p
        return out

    def theme_proba(self, motion: Motion, pair: str) -> float:
        """Probability of the second theme of ``pair`` (e.g. tired in energetic_vs_tired), mean over windows."""
        if pair not in self.themes:
            raise KeyError(f"real observer: no classifier for theme pair {pair!r} (have {sorted(self.themes)})")
        return float(self.themes[pair].predict_proba(window_descriptors(motion))[:, 1].mean())

    def read(self, motion: Motion) -> dict:
        """The quality record's reading: ``observed``, ``observed_p`` and ``observer``: real."""
        label, p = self.observe(motion)
        return {"observed": label, "observed_p": round(p, 4), "observer": self.kind}


def train_real_observer(corpus_path: str | Path | None = None) -> RealGaitObserver:
    """A RealGaitObserver fitted on the gait takes of the corpus's training split."""

    path = Path(corpus_path) if corpus_path is not None else DEFAULT_PATH
    clips = load_real_corpus(path, skeleton="gait", split="train")
    return RealGaitObserver(clips, source=f"real-capture corpus {path.name} (training split, {len(clips)} gait takes)")


def shipped_clips() -> list:
    """The gait takes shipped in the repository (generation/data/mocap/bandai-namco/), imported onto the gait
    skeleton (CorpusClips; a take that fails to import raises)."""

    out = []
    for take in shipped_takes():
        if take.skeleton != "gait":
            continue
        clip, row = import_take(take)
        if clip is None:
            raise ValueError(f"shipped real take {take.name} does not import: {row.get('message')}")
        out.append(clip)
    return out


def observer_version(corpus_path: str | Path | None = None) -> str:
    """Key of the corpus file's version (path, modification time, size), or ``shipped`` without the file."""
    path = Path(corpus_path) if corpus_path is not None else DEFAULT_PATH
    if not path.is_file():
        return "shipped"
    st = path.stat()
    return f"{path}:{st.st_mtime_ns}:{st.st_size}"


def load_real_observer(corpus_path: str | Path | None = None) -> RealGaitObserver | None:
    """The real-capture observer: from the cache file, or trained (and cached) on the corpus file (default
    :data:`generation.mocap.real_corpus.DEFAULT_PATH`); without that file, on the shipped real takes
    (``source`` says so); None when neither is there."""
    path = Path(corpus_path) if corpus_path is not None else DEFAULT_PATH
    if path.is_file():
        sha = file_sha256(path)
        return load_or_build(CACHE_DIR / f"real_gait_observer_v{DESCRIPTOR_VERSION}_{sha[:12]}.pkl",
                             RealGaitObserver, lambda: train_real_observer(path))
    try:
        clips = shipped_clips()
    except (FileNotFoundError, ValueError):
        return None
    return RealGaitObserver(clips, source=f"shipped real takes only ({len(clips)} walks, one take per style; no "
                                          f"corpus at {path}; not validated on held-out takes)")
