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

Walkers (:func:`walker_of`): a clip's walker is its performer where its Motion's metadata names one (the BML walks
of Emotion-Gait, :mod:`generation.mocap.emotion_gait_bml`: 30 actors, each with one neutral walk), else its dataset
(Bandai Namco). :func:`walker_references` gives every walker's reference, the mean descriptor of its neutral walks
(style ``normal`` or ``neutral``). The BML emotion observer (:func:`train_bml_observer`) therefore reads a walk
relative to the same actor's neutral walk; :func:`heldout_by_walker` is its recall on actors it was not trained on
(k folds over performers, every actor held out once).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generation.core.features import np_gait_affective_features
from generation.core.motion import Motion
from generation.core.skeleton import GAIT_JOINTS
from generation.core.splits import SPLITS
from generation.core.windows import windows
from generation.mocap.emotion_gait_bml import DATASET as BML_DATASET
from generation.mocap.real_corpus import DEFAULT_BML_PATH, DEFAULT_PATH, load_real_corpus
from generation.mocap.style_scales import NEUTRAL_CLASS, NEUTRAL_STYLES, SCALES, THEME_SCALE, class_recall, scale_clips

WINDOW_S = 2.0
HOP_S = 0.5
FEATURE_CLIP = 10.0
REGULARISATION_C = 0.1
NORMALISE = ("walker", "none")
BML_FOLDS = 5


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


def walker_of(clip) -> str:
    """The walker whose neutral walk a clip is read against: the ``performer`` of its Motion's metadata where set
    (BML), else its dataset (Bandai Namco, whose takes have no actor ids)."""
    performer = (getattr(clip.motion, "metadata", None) or {}).get("performer")
    return str(performer) if performer else clip.dataset


def walker_references(clips: list, splits: tuple[str, ...] = ("train",)) -> dict[str, np.ndarray]:
    """{walker (:func:`walker_of`): (44,) mean descriptor of its neutral walks (style ``normal`` or ``neutral``,
    content ``walk``) in ``splits`` (default the training split)}: the walker reference of real takes."""
    normal: dict[str, list[Motion]] = {}
    for c in clips:
        if c.content == "walk" and c.style in NEUTRAL_STYLES and c.split in splits:
            normal.setdefault(walker_of(c), []).append(c.motion)
    return {w: reference_descriptor(normal[w]) for w in sorted(normal)}


def dataset_references(clips: list, splits: tuple[str, ...] = ("train",)) -> dict[str, np.ndarray]:
    """:func:`walker_references` (for the Bandai corpus, whose walker is the dataset: {dataset: (44,)})."""
    return walker_references(clips, splits)


@dataclass
class RbfStyleObserver:
    """One scale's classifier (standardised multinomial logistic regression over windows).

    Attributes:
        scale: key of :data:`SCALES`; classes: the classifier's column order; normalise: ``walker`` (descriptors
        minus the walker's neutral descriptor) or ``none``; train_takes: training takes per class; datasets: the
        corpus datasets trained on (None: the scale's default); labels: ``acted`` (corpus style) or ``perceived``
        (:func:`generation.mocap.style_scales.clip_style`).
    """

    scale: str
    classes: tuple[str, ...]
    clf: object
    normalise: str = "walker"
    train_takes: dict = field(default_factory=dict)
    datasets: tuple[str, ...] | None = None
    labels: str = "acted"

    @classmethod
    def fit(cls, clips: list, scale: str, normalise: str = "walker", C: float = REGULARISATION_C,
            train_splits: tuple[str, ...] = ("train",), datasets: tuple[str, ...] | None = None,
            labels: str = "acted") -> RbfStyleObserver:
        """Train on the takes of ``train_splits`` (every take once, every class once in total) of ``datasets``
        (default :data:`SCALE_DATASETS`), each read relative to its walker's (:func:`walker_of`) neutral walks of
        ``train_splits``; classes by ``labels``.

        Raises:
            ValueError: when a class has no training take, or a walker has no training neutral walk to refer to.
        """
        from sklearn.linear_model import LogisticRegression
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler

        if normalise not in NORMALISE:
            raise ValueError(f"normalise must be one of {list(NORMALISE)}, got {normalise!r}")
        train = [(c, k) for c, k in scale_clips(clips, scale, datasets, labels) if c.split in train_splits]
        classes = tuple(SCALES[scale])
        counts = {k: sum(1 for _, kk in train if kk == k) for k in classes}
        missing = [k for k, n in counts.items() if n == 0]
        if missing:
            raise ValueError(f"style observer {scale}: no training takes for {missing}")
        refs = walker_references(clips, train_splits) if normalise == "walker" else {}
        X, y, w = [], [], []
        for clip, k in train:
            d = window_descriptors(clip.motion)
            if normalise == "walker":
                if walker_of(clip) not in refs:
                    raise ValueError(f"style observer {scale}: walker {walker_of(clip)} has no training normal walk")
                d = d - refs[walker_of(clip)]
            X.append(d)
            y.append(np.full(len(d), classes.index(k)))
            w.append(np.full(len(d), 1.0 / (len(d) * counts[k])))
        X, y, w = np.concatenate(X), np.concatenate(y), np.concatenate(w)
        clf = make_pipeline(StandardScaler(), LogisticRegression(max_iter=5000, C=C))
        clf.fit(X, y, logisticregression__sample_weight=w * len(w) / w.sum())
        return cls(scale, classes, clf, normalise, counts, datasets, labels)

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
        :data:`SCALE_DATASETS`; classes by this observer's ``labels``); each take's reference is its walker's
        (:func:`walker_of`) training neutral walks (``references``, default :func:`walker_references` of ``clips``).

        Returns {"recall": {class: share of its held-out takes whose mean probability is highest for it, None
        without takes}, "takes": {class: n}, "mean_p": {class: mean own-class probability}, "rows": [per take]}.
        """
        refs = references if references is not None else walker_references(clips)
        rows = []
        for clip, k in scale_clips(clips, self.scale, datasets, self.labels):
            walker = walker_of(clip)
            if clip.split not in splits or (self.normalise == "walker" and walker not in refs):
                continue
            r = self.read(clip.motion, refs.get(walker))
            rows.append({"name": clip.name, "dataset": clip.dataset, "walker": walker, "class": k, "top": r["top"],
                         "p": r["p"]})
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


def walker_folds(walkers, k: int = BML_FOLDS) -> list[tuple[str, ...]]:
    """``k`` disjoint folds of the distinct ``walkers`` (sorted; walker i goes to fold i mod k), each a tuple of
    walker names; every walker is in exactly one fold.

    Raises:
        ValueError: for k < 2 or fewer walkers than folds.
    """
    names = sorted(set(walkers))
    if k < 2 or len(names) < k:
        raise ValueError(f"need k >= 2 folds and at least k walkers, got k={k} and {len(names)} walkers")
    return [tuple(names[i::k]) for i in range(k)]


def heldout_by_walker(clips: list, scale: str = "emotion", datasets: tuple[str, ...] = (BML_DATASET,),
                      labels: str = "acted", k: int = BML_FOLDS, C: float = REGULARISATION_C) -> dict:
    """Recall on walkers never trained on: for each of :func:`walker_folds`, an observer fitted on the other folds'
    walkers' clips (all splits) reads the fold's clips, each relative to its own walker's neutral walk.

    A held-out neutral walk read relative to itself has the window-to-window spread only (its mean descriptor is
    the reference), so its recall is high by construction; ``neutral_other_reference`` reads the same walks relative
    to the mean neutral descriptor of the fold's training walkers instead (no walker normalisation for them).

    Returns :func:`class_recall` of all held-out readings (rows carry ``fold``), plus "folds": [{"heldout": walkers,
    "trained_on": walkers}] and "neutral_other_reference": {"recall", "takes", "mean_p"} of the neutral class.
    """
    names = sorted({walker_of(c) for c, _ in scale_clips(clips, scale, datasets, labels)})
    neutral = NEUTRAL_CLASS[scale]
    rows, other, folds = [], [], []
    for i, held in enumerate(walker_folds(names, k)):
        train = [c for c in clips if walker_of(c) not in held]
        test = [c for c in clips if walker_of(c) in held]
        obs = RbfStyleObserver.fit(train, scale, "walker", C, SPLITS, datasets, labels)
        out = obs.heldout(test, SPLITS, walker_references(test, SPLITS), datasets)
        rows += [{**r, "fold": i} for r in out["rows"]]
        pooled = np.mean(list(walker_references(train, SPLITS).values()), axis=0)
        for clip, cls in scale_clips(test, scale, datasets, labels):
            if cls == neutral:
                r = obs.read(clip.motion, pooled)
                other.append({"class": cls, "top": r["top"], "p": r["p"]})
        folds.append({"heldout": list(held),
                      "trained_on": sorted({walker_of(c) for c, _ in scale_clips(train, scale, datasets, labels)})})
    res = class_recall(rows, tuple(SCALES[scale]))
    o = class_recall(other, tuple(SCALES[scale]))
    res["folds"] = folds
    res["neutral_other_reference"] = {key: o[key][neutral] for key in ("recall", "takes", "mean_p")}
    return res


def load_bml_walks(corpus_path: str | Path | None = None) -> list:
    """The BML walks of Emotion-Gait on the gait skeleton (default ``var/mocap/emotion-gait-bml.npz``).

    Raises:
        FileNotFoundError: without the corpus (build it as docs/mocap.md, "A positions-only dataset", says).
    """
    path = Path(corpus_path) if corpus_path is not None else DEFAULT_BML_PATH
    if not path.is_file():
        raise FileNotFoundError(f"BML corpus {path} not found; build it as docs/mocap.md says "
                                "(A positions-only dataset)")
    return load_real_corpus(path, skeleton="gait")


def train_bml_observer(clips: list, labels: str = "acted", C: float = REGULARISATION_C) -> RbfStyleObserver:
    """The emotion observer (happy, sad, angry, neutral) trained on every BML actor's walks (all splits), each
    relative to the same actor's neutral walk; :func:`heldout_by_walker` is its recall on unseen actors."""
    return RbfStyleObserver.fit(clips, "emotion", "walker", C, SPLITS, (BML_DATASET,), labels)
