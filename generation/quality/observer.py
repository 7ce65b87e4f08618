"""A synthetic observer of gait emotion: logistic regression on the 18 gait affective features averaged over
time, trained on the synthetic gait corpus's training split (moved here from benchmarks/bench_gait.py, which
imports it). It stands in for a participant when checking clips; it is not a human judgement.

:func:`load_observer` trains it once per corpus version and keeps the fitted model in
``var/quality/gait_observer_<corpus sha256[:12]>.pkl``; :class:`generation.quality.observers.Observers` keeps it in
memory per process (keyed by :func:`observer_version`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from generation.core.digest import file_sha256
from generation.core.features import np_gait_affective_features
from generation.core.motion import Motion
from generation.core.skeleton import GAIT_JOINTS
from protocol.vocabulary import GAIT_EMOTIONS

from .pickle_cache import load_or_build

REPO_ROOT = Path(__file__).resolve().parents[2]
CACHE_DIR = REPO_ROOT / "var" / "quality"
FEATURE_CLIP = 10.0


class GaitObserver:
    """Logistic regression on the 18 affective features averaged over time (synthetic observer).

    Args:
        train: a :class:`generation.gait.data.GaitSequences` (``aff`` (N, T, 18) features, ``emotion`` (N, 4)).
    Labels are GAIT_EMOTIONS indices (the argmax of each training sequence's emotion vector).
    """

    labels = GAIT_EMOTIONS
    kind = "synthetic"
    source = "synthetic procedural gait corpus (training split)"

    def __init__(self, train):
        from sklearn.linear_model import LogisticRegression
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler
        X = self.summarise_seq(train.aff.numpy())
        y = train.emotion.numpy().argmax(1)
        self.clf = make_pipeline(StandardScaler(), LogisticRegression(max_iter=2000, C=1.0)).fit(X, y)

    @staticmethod
    def summarise_seq(aff: np.ndarray) -> np.ndarray:
        """(..., T, 18) features -> (..., 18) clipped time means."""
        a = np.clip(aff, -FEATURE_CLIP, FEATURE_CLIP)
        return a.mean(-2)

    def features(self, motions: list[Motion], frames: slice = slice(None)) -> np.ndarray:
        """(N, 18) time-mean affective features of 21-joint gait motions."""
        return np.clip(np.stack([np_gait_affective_features(m.positions()[frames]).mean(0) for m in motions]),
                       -FEATURE_CLIP, FEATURE_CLIP)

    def predict_motions(self, motions: list[Motion], frames: slice = slice(None)) -> np.ndarray:
        """(N,) GAIT_EMOTIONS indices."""
        return self.clf.predict(self.features(motions, frames))

    def proba_motions(self, motions: list[Motion], frames: slice = slice(None)) -> np.ndarray:
        """(N, 4) probabilities in GAIT_EMOTIONS order."""
        return self.clf.predict_proba(self.features(motions, frames))

    def reads(self, motion: Motion) -> bool:
        """Whether the quality gate asks this observer about ``motion``: the 21-joint gait skeleton, >= 2 frames."""
        return motion.skeleton.num_joints == len(GAIT_JOINTS) and motion.num_frames >= 2

    def read(self, motion: Motion) -> dict:
        """The quality record's reading: ``observed`` (top label), ``observed_p`` (its probability) and
        ``observer``: synthetic."""
        label, p = self.observe(motion)
        return {"observed": label, "observed_p": round(p, 4), "observer": self.kind}

    def observe(self, motion: Motion) -> tuple[str, float]:
        """(top label, its probability) for one gait motion."""
        p = self.proba_motions([motion])[0]
        k = int(np.argmax(p))
        return self.labels[int(self.clf.classes_[k])], float(p[k])


def _gait_data():
    """generation.gait.data, imported when a corpus is read."""
    from generation.gait import data  # heavy: torch (generation.gait loads it)

    return data


def _corpus_path(path: str | Path | None) -> Path:
    p = Path(path) if path is not None else _gait_data().DEFAULT_CORPUS
    return p if p.is_absolute() else REPO_ROOT / p


def train_observer(corpus_path: str | Path | None = None) -> GaitObserver:
    """A GaitObserver fitted on the training split (offset 0) of the gait corpus (built when missing)."""
    data = _gait_data().load_corpus_sequences(_corpus_path(corpus_path))
    train = data.subset((data.split == "train") & (data.offset == 0))
    obs = GaitObserver(train)
    obs.corpus_sha256 = data.training_data.corpus["sha256"]
    return obs


def observer_version(corpus_path: str | Path | None = None) -> str | None:
    """Key of the corpus file's version (path, modification time, size), or None when it does not exist."""
    path = _corpus_path(corpus_path)
    if not path.is_file():
        return None
    st = path.stat()
    return f"{path}:{st.st_mtime_ns}:{st.st_size}"


def load_observer(corpus_path: str | Path | None = None) -> GaitObserver | None:
    """The observer of the current corpus: from the cache file, or trained (and cached); None when the gait corpus
    file does not exist (build it with the gait training; clips then get no observer reading)."""
    path = _corpus_path(corpus_path)
    if not path.is_file():
        return None
    sha = file_sha256(path)
    return load_or_build(CACHE_DIR / f"gait_observer_{sha[:12]}.pkl", GaitObserver, lambda: train_observer(path))
