"""Style observers for seed 004's themes, trained on real styled walks with whole takes held out.

Three scales, each a standardised multinomial logistic regression on the real observer's 2 s window descriptors
(:func:`generation.quality.real_observer.window_descriptors`: 18 gait affective-feature means and spreads, root
speed / height, root bob / height), trained on the straight walks (content ``walk``) of the Bandai Namco Research
Motion Dataset 1 and 2 (Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0):

- ``energy``: energetic (active) / normal / tired (dataset 1 tired, dataset 2 exhausted), both datasets;
- ``gender``: feminine / normal / masculine (dataset 1 masculinity, dataset 2 masculine), both datasets;
- ``emotion``: happy / sad / angry / neutral (normal), dataset 1 only (the only one with these emotions).

Each scale has a ``normal`` (``neutral``) class so that an unstyled walk can be read as unstyled rather than
forced to one pole. Training uses the corpus's training split (held out by take,
:func:`generation.mocap.bandai_namco.split_for`); every take weighs the same (1 / its windows) and every class the
same in total. :meth:`StyleObserver.heldout` reads the val and test takes: the **held-out recall** of a class is the
share of its held-out takes whose mean window probability is highest for that class.

A theme is read on its scale (:data:`THEME_SCALE`); :meth:`StyleObservers.read_theme` gives the probability of the
theme's own class and the top class.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from generation.core.skeleton import GAIT_JOINTS
from generation.mocap.real_corpus import DEFAULT_PATH, load_real_corpus
from generation.mocap.style_scales import SCALES, THEME_SCALE, class_recall, scale_clips

from .real_observer import window_descriptors

REGULARISATION_C = 0.1


@dataclass
class StyleObserver:
    """One scale's classifier. ``classes`` in the classifier's column order; ``train_takes`` per class."""

    scale: str
    classes: tuple[str, ...]
    clf: object
    train_takes: dict = field(default_factory=dict)

    @classmethod
    def fit(cls, clips: list, scale: str, C: float = REGULARISATION_C) -> StyleObserver:
        """Train on the training-split takes of ``clips`` (CorpusClips on the gait skeleton).

        Raises:
            ValueError: when a class of the scale has no training take.
        """
        from sklearn.linear_model import LogisticRegression
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler

        train = [(c, k) for c, k in scale_clips(clips, scale) if c.split == "train"]
        classes = tuple(SCALES[scale])
        counts = {k: sum(1 for _, kk in train if kk == k) for k in classes}
        missing = [k for k, n in counts.items() if n == 0]
        if missing:
            raise ValueError(f"style observer {scale}: no training takes for {missing}")
        X, y, w = [], [], []
        for clip, k in train:
            d = window_descriptors(clip.motion)
            X.append(d)
            y.append(np.full(len(d), classes.index(k)))
            w.append(np.full(len(d), 1.0 / (len(d) * counts[k])))  # each take once, each class once
        X, y, w = np.concatenate(X), np.concatenate(y), np.concatenate(w)
        clf = make_pipeline(StandardScaler(), LogisticRegression(max_iter=5000, C=C))
        clf.fit(X, y, logisticregression__sample_weight=w * len(w) / w.sum())
        return cls(scale, classes, clf, counts)

    def proba(self, motion: Motion) -> np.ndarray:
        """(K,) class probabilities in :attr:`classes` order: the mean over the motion's 2 s windows."""
        if motion.skeleton.joints != GAIT_JOINTS:
            raise ValueError(f"style observer: expected a motion on the gait skeleton, got {motion.skeleton.name!r}")
        p = self.clf.predict_proba(window_descriptors(motion)).mean(0)
        out = np.zeros(len(self.classes))
        out[self.clf.classes_.astype(int)] = p
        return out

    def read(self, motion: Motion) -> dict:
        """{"top": class, "p": {class: probability}}."""
        p = self.proba(motion)
        return {"top": self.classes[int(np.argmax(p))], "p": {k: float(v) for k, v in zip(self.classes, p)}}

    def heldout(self, clips: list) -> dict:
        """Readings of the held-out (val and test) takes of this scale in ``clips``.

        Returns {"recall": {class: share of its held-out takes read as it, or None without takes},
        "takes": {class: n}, "mean_p": {class: mean probability of the own class}, "rows": [per take]}.
        """
        rows = []
        for clip, k in scale_clips(clips, self.scale):
            if clip.split == "train":
                continue
            r = self.read(clip.motion)
            rows.append({"name": clip.name, "dataset": clip.dataset, "class": k, "top": r["top"], "p": r["p"]})
        return class_recall(rows, self.classes)


class StyleObservers:
    """The three scales' observers, trained on one corpus's clips."""

    def __init__(self, clips: list, C: float = REGULARISATION_C, source: str = "") -> None:
        self.scales = {s: StyleObserver.fit(clips, s, C) for s in SCALES}
        self.source = source

    def read_theme(self, motion: Motion, theme: str) -> dict:
        """Reading of ``motion`` on ``theme``'s scale: {"scale", "target", "p_target", "top", "p"}."""
        if theme not in THEME_SCALE:
            raise ValueError(f"unknown theme {theme!r}; expected one of {sorted(THEME_SCALE)}")
        scale, target = THEME_SCALE[theme]
        r = self.scales[scale].read(motion)
        return {"scale": scale, "target": target, "p_target": r["p"][target], "top": r["top"], "p": r["p"]}

    def heldout(self, clips: list) -> dict:
        """{scale: :meth:`StyleObserver.heldout`} on ``clips``' held-out takes."""
        return {s: obs.heldout(clips) for s, obs in self.scales.items()}


def train_style_observers(corpus_path: str | Path | None = None) -> tuple[StyleObservers, list]:
    """Style observers trained on the corpus's walks (default :data:`generation.mocap.real_corpus.DEFAULT_PATH`);
    returns them and the corpus's gait walks (for their held-out takes)."""
    path = Path(corpus_path) if corpus_path is not None else DEFAULT_PATH
    if not path.is_file():
        raise FileNotFoundError(f"real corpus {path} not found; build it as docs/corpus.md says")
    clips = load_real_corpus(path, skeleton="gait", contents=["walk"])
    return StyleObservers(clips, source=f"{path.name}: walks, training split"), clips
