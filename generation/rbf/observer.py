"""Style observers for seed 004's themes that read a walk relative to the same walker's neutral walk.

The observers of :mod:`generation.quality.style_observer` read absolute window descriptors, so a styled walk made
from one neutral base is compared with other people's walks: the differences between walkers (build, habitual
speed, arm carriage) are as large as the differences between styles, and every RBF-styled walk reads as its base.
Here (``normalise="walker"``) each descriptor is expressed **relative to that walker's own neutral walk**: the mean
descriptor of the walker's normal walk is subtracted, so ``observer.read(motion, reference=base_motion)`` asks
"how does this walk differ from the same person walking normally?", which is what an RBF edit changes.

Descriptors (:func:`window_descriptors`, 2 s windows with 0.5 s hop, as the real-capture observer's): the 18 gait
affective features of seed 000 (means and standard deviations over the window), root speed / height, root vertical
peak-to-peak / height, and six posture and swing measures in the walker's frame, in heights: wrist height and
fore-aft swing (peak-to-peak) relative to the pelvis, head forward offset and height relative to the pelvis, foot
lift (peak-to-peak of the heels' height) and step width.

Training data: the straight walks of the Bandai Namco Research Motion Dataset 1 and 2 (Kobayashi et al. 2023,
arXiv:2306.08861, CC BY-NC 4.0), training split only (held out by take, :func:`generation.mocap.bandai_namco.
split_for`). The corpus has no actor ids; a dataset's takes come from its own three actors, so the walker's
reference for a real take is the mean of its dataset's **training** normal walks (never a held-out take).
Scales and classes: :mod:`generation.mocap.style_scales`, shared with :mod:`generation.quality.style_observer`.
:meth:`RbfStyleObserver.heldout` reports the held-out recall (val and test takes) that belongs
beside every reading.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generation.core.features import np_gait_affective_features
from generation.core.motion import Motion
from generation.core.skeleton import GAIT_JOINTS
from generation.core.windows import windows
from generation.mocap.real_corpus import DEFAULT_PATH, load_real_corpus
from generation.mocap.style_scales import SCALES, THEME_SCALE, class_recall, scale_clips

WINDOW_S = 2.0
HOP_S = 0.5
FEATURE_CLIP = 10.0
REGULARISATION_C = 0.1
NORMALISE = ("walker", "none")


_J = {name: i for i, name in enumerate(GAIT_JOINTS)}


def _walker_frame(P: np.ndarray) -> np.ndarray:
    """(T, J, 3) positions turned so the walk's mean ground direction is +z, relative to the pelvis in x and z."""
    root = P[:, 0]
    d = root[-1, [0, 2]] - root[0, [0, 2]]
    heading = np.arctan2(d[0], d[1]) if np.linalg.norm(d) > 1e-6 else 0.0
    c, s = np.cos(-heading), np.sin(-heading)
    Q = P.copy()
    Q[..., 0] -= root[:, None, 0]
    Q[..., 2] -= root[:, None, 2]
    x, z = Q[..., 0].copy(), Q[..., 2].copy()
    Q[..., 0] = c * x + s * z
    Q[..., 2] = -s * x + c * z
    return Q


def window_descriptors(motion: Motion) -> np.ndarray:
    """(W, 44) descriptors of a gait motion's 2 s windows (see the module docstring).

    Raises:
        ValueError: for a motion not on the 21-joint gait skeleton or with fewer than 2 frames.
    """
    if motion.skeleton.joints != GAIT_JOINTS:
        raise ValueError(f"style observer: expected a motion on the gait skeleton, got {motion.skeleton.name!r}")
    if motion.num_frames < 2:
        raise ValueError("style observer: need at least 2 frames")
    P = motion.positions()
    h = motion.skeleton.height if motion.skeleton.height > 0 else 1.75
    aff = np.clip(np_gait_affective_features(P), -FEATURE_CLIP, FEATURE_CLIP)  # (T, 18)
    root = P[:, 0]
    speed = np.linalg.norm(np.diff(root[:, [0, 2]], axis=0), axis=-1) * motion.fps / h
    speed = np.concatenate([speed[:1], speed])
    W = _walker_frame(P) / h
    rel_y = W[..., 1] - W[:, :1, 1]
    hands, heels = [_J["left_hand"], _J["right_hand"]], [_J["left_heel"], _J["right_heel"]]
    rows = []
    for s in windows(motion.num_frames, int(round(WINDOW_S * motion.fps)), int(round(HOP_S * motion.fps)),
                     whole_if_short=True):
        posture = [rel_y[s][:, hands].mean(), np.ptp(W[s][:, hands, 2], axis=0).mean(),
                   W[s][:, _J["head"], 2].mean(), rel_y[s][:, _J["head"]].mean(),
                   np.ptp(W[s][:, heels, 1], axis=0).mean(),
                   np.abs(W[s][:, heels[0], 0] - W[s][:, heels[1], 0]).mean()]
        rows.append(np.concatenate([aff[s].mean(0), aff[s].std(0), [speed[s].mean(), np.ptp(root[s, 1]) / h],
                                    posture]))
    return np.asarray(rows)


def reference_descriptor(reference: Motion | list[Motion]) -> np.ndarray:
    """(44,) the walker's neutral descriptor: the mean window descriptor of ``reference`` (one motion or several,
    each weighing the same)."""
    motions = reference if isinstance(reference, (list, tuple)) else [reference]
    if not motions:
        raise ValueError("style observer: an empty reference")
    return np.mean([window_descriptors(m).mean(0) for m in motions], axis=0)


def dataset_references(clips: list, splits: tuple[str, ...] = ("train",)) -> dict[str, np.ndarray]:
    """{dataset: (44,) mean descriptor of its normal walks in ``splits`` (default the training split)}: the walker
    reference of real takes."""
    out = {}
    for dataset in sorted({c.dataset for c in clips}):
        normal = [c.motion for c in clips if c.dataset == dataset and c.content == "walk" and c.style == "normal"
                  and c.split in splits]
        if normal:
            out[dataset] = reference_descriptor(normal)
    return out


@dataclass
class RbfStyleObserver:
    """One scale's classifier (standardised multinomial logistic regression over windows).

    Attributes:
        scale: key of :data:`SCALES`; classes: the classifier's column order; normalise: ``walker`` (descriptors
        minus the walker's neutral descriptor) or ``none``; train_takes: training takes per class.
    """

    scale: str
    classes: tuple[str, ...]
    clf: object
    normalise: str = "walker"
    train_takes: dict = field(default_factory=dict)
    datasets: tuple[str, ...] | None = None

    @classmethod
    def fit(cls, clips: list, scale: str, normalise: str = "walker", C: float = REGULARISATION_C,
            train_splits: tuple[str, ...] = ("train",), datasets: tuple[str, ...] | None = None
            ) -> RbfStyleObserver:
        """Train on the takes of ``train_splits`` (every take once, every class once in total) of ``datasets``
        (default :data:`SCALE_DATASETS`; each dataset is one walker's, or one group of actors', walks).

        Raises:
            ValueError: when a class has no training take, or a dataset has no training normal walk to refer to.
        """
        from sklearn.linear_model import LogisticRegression
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler

        if normalise not in NORMALISE:
            raise ValueError(f"normalise must be one of {list(NORMALISE)}, got {normalise!r}")
        train = [(c, k) for c, k in scale_clips(clips, scale, datasets) if c.split in train_splits]
        classes = tuple(SCALES[scale])
        counts = {k: sum(1 for _, kk in train if kk == k) for k in classes}
        missing = [k for k, n in counts.items() if n == 0]
        if missing:
            raise ValueError(f"style observer {scale}: no training takes for {missing}")
        refs = dataset_references(clips, train_splits) if normalise == "walker" else {}
        X, y, w = [], [], []
        for clip, k in train:
            d = window_descriptors(clip.motion)
            if normalise == "walker":
                if clip.dataset not in refs:
                    raise ValueError(f"style observer {scale}: dataset {clip.dataset} has no training normal walk")
                d = d - refs[clip.dataset]
            X.append(d)
            y.append(np.full(len(d), classes.index(k)))
            w.append(np.full(len(d), 1.0 / (len(d) * counts[k])))
        X, y, w = np.concatenate(X), np.concatenate(y), np.concatenate(w)
        clf = make_pipeline(StandardScaler(), LogisticRegression(max_iter=5000, C=C))
        clf.fit(X, y, logisticregression__sample_weight=w * len(w) / w.sum())
        return cls(scale, classes, clf, normalise, counts, datasets)

    def _descriptors(self, motion: Motion, reference) -> np.ndarray:
        d = window_descriptors(motion)
        if self.normalise == "walker":
            if reference is None:
                raise ValueError("a walker-normalised observer needs the walker's neutral walk (reference=...)")
            ref = reference if isinstance(reference, np.ndarray) else reference_descriptor(reference)
            d = d - ref
        return d

    def proba(self, motion: Motion, reference: Motion | np.ndarray | None = None) -> np.ndarray:
        """(K,) class probabilities in :attr:`classes` order, the mean over the motion's windows. ``reference``: the
        same walker's neutral walk (a Motion, list of Motions or a :func:`reference_descriptor`); required when
        :attr:`normalise` is ``walker``."""
        p = self.clf.predict_proba(self._descriptors(motion, reference)).mean(0)
        out = np.zeros(len(self.classes))
        out[self.clf.classes_.astype(int)] = p
        return out

    def read(self, motion: Motion, reference: Motion | np.ndarray | None = None) -> dict:
        """{"top": class, "p": {class: probability}}."""
        p = self.proba(motion, reference)
        return {"top": self.classes[int(np.argmax(p))], "p": {k: float(v) for k, v in zip(self.classes, p)}}

    def heldout(self, clips: list, splits: tuple[str, ...] = ("val", "test"),
                references: dict[str, np.ndarray] | None = None, datasets: tuple[str, ...] | None = None) -> dict:
        """Readings of the takes of ``splits`` of this scale in ``clips`` (of ``datasets``, default
        :data:`SCALE_DATASETS`); each take's reference is its dataset's training normal walks (``references``,
        default :func:`dataset_references` of ``clips``).

        Returns {"recall": {class: share of its held-out takes whose mean probability is highest for it, None
        without takes}, "takes": {class: n}, "mean_p": {class: mean own-class probability}, "rows": [per take]}.
        """
        refs = references if references is not None else dataset_references(clips)
        rows = []
        for clip, k in scale_clips(clips, self.scale, datasets):
            if clip.split not in splits or (self.normalise == "walker" and clip.dataset not in refs):
                continue
            r = self.read(clip.motion, refs.get(clip.dataset))
            rows.append({"name": clip.name, "dataset": clip.dataset, "class": k, "top": r["top"], "p": r["p"]})
        return class_recall(rows, self.classes)


class RbfStyleObservers:
    """The three scales' observers trained on one corpus's clips."""

    def __init__(self, clips: list, normalise: str = "walker", C: float = REGULARISATION_C, source: str = "") -> None:
        self.scales = {s: RbfStyleObserver.fit(clips, s, normalise, C) for s in SCALES}
        self.normalise = normalise
        self.source = source

    def read_theme(self, motion: Motion, theme: str, reference: Motion | np.ndarray | None = None) -> dict:
        """Reading of ``motion`` on ``theme``'s scale: {"scale", "target", "p_target", "top", "p"}."""
        if theme not in THEME_SCALE:
            raise ValueError(f"unknown theme {theme!r}; expected one of {sorted(THEME_SCALE)}")
        scale, target = THEME_SCALE[theme]
        r = self.scales[scale].read(motion, reference)
        return {"scale": scale, "target": target, "p_target": r["p"][target], "top": r["top"], "p": r["p"]}

    def heldout(self, clips: list) -> dict:
        """{scale: :meth:`RbfStyleObserver.heldout`} on ``clips``' held-out (val, test) takes."""
        refs = dataset_references(clips)
        return {s: obs.heldout(clips, references=refs) for s, obs in self.scales.items()}


def train_observers(corpus_path: str | Path | None = None, normalise: str = "walker"
                    ) -> tuple[RbfStyleObservers, list]:
    """Observers trained on the corpus's walks (default ``var/mocap/bandai-namco.npz``); returns them and the
    corpus's gait walks (for their held-out takes).

    Raises:
        FileNotFoundError: without the corpus (build it as docs/corpus.md says).
    """
    path = Path(corpus_path) if corpus_path is not None else DEFAULT_PATH
    if not path.is_file():
        raise FileNotFoundError(f"real corpus {path} not found; build it as docs/corpus.md says")
    clips = load_real_corpus(path, skeleton="gait", contents=["walk"])
    return RbfStyleObservers(clips, normalise, source=f"{path.name}: walks, training split"), clips
