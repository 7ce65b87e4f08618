"""A gait observer calibrated on real walks of many actors: trained on both real corpora, it knows how often it
recognises each emotion on real actors it has never seen, and its flags say whether they can exclude a clip.

Training data (:func:`train_calibrated_observer`):

- the Bandai Namco corpus's dataset-1 happy, sad, angry and normal walks of the training split (acted styles;
  Kobayashi et al. 2023, CC BY-NC 4.0; :mod:`generation.quality.real_observer` uses the same takes);
- the BML walks of Emotion-Gait (:mod:`generation.mocap.emotion_gait_bml`) of the training and validation
  performers, labelled with the **acted** emotion (``labels="acted"``) or with the annotators' **perceived** one
  (``labels="perceived"``; the Bandai takes keep their acted style, they have no perceived label). Research use
  with citation of Ma, Paterson & Pollick (2006) and of STEP (Bhattacharya et al., AAAI 2020).

The descriptors and the classifier are the real-capture observer's (:func:`real_observer.window_descriptors`,
standardised logistic regression, each take weighted equally).

**Held-out reference**: the BML test performers (whole actors, never seen in training; 6 of 30) are read by the
fitted observer, per class: ``heldout_recall[e]`` is the share of held-out real walks labelled ``e`` (acted or
perceived, as the variant) whose top reading is ``e``; ``heldout_n[e]`` how many there are. A generated clip of
emotion ``e`` is judged against that real reference: it is "read as intended at least as often as held-out real
actors' walks of that emotion" when the share of the clips read as ``e`` is >= ``heldout_recall[e]``
(:func:`judge_against_reference`).

**Advisory flags**: where the held-out recall of a class is below :data:`ADVISORY_RECALL` (0.6), the observer
cannot tell that class from the others on real walks, so its mismatch flag for a clip intended as that class, or
read as that class, is advisory: the quality record keeps ``observer_flag: advisory`` and the reason, and the
``observer`` check does not fail (:func:`advisory_reason`, used by :func:`generation.quality.checks.failed_checks`).
"""
from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np

from generation.core.digest import file_sha256
from generation.core.motion import Motion
from generation.mocap.real_corpus import DEFAULT_BML_PATH, DEFAULT_PATH, load_real_corpus
from study_protocol import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS

from . import real_observer as ro
from .pickle_cache import load_or_build

ADVISORY_RECALL = 0.6
LABEL_VARIANTS = ("acted", "perceived")
BML_DATASET = "emotion-gait-bml"


def clip_label(clip, labels: str) -> str | None:
    """The gait emotion a corpus clip teaches: BML clips their acted or perceived label (metadata), Bandai
    dataset-1 takes their style's emotion (acted), others None."""
    if clip.dataset == BML_DATASET:
        key = "acted_label" if labels == "acted" else "perceived_label"
        value = clip.motion.metadata.get(key, clip.label)
        return value if value in GAIT_EMOTIONS else None
    if clip.dataset == ro.EMOTION_DATASET and clip.style in CAPTURE_GAIT_EMOTIONS:
        return CAPTURE_GAIT_EMOTIONS[clip.style]
    return None


class CalibratedGaitObserver(ro.WindowedGaitObserver):
    """Emotion classifier on real walks of both corpora, with its recall on held-out real actors.

    Args:
        train: CorpusClips to fit on (gait skeleton; those without a label of :func:`clip_label` are ignored).
        heldout: CorpusClips of actors never in ``train`` (the BML test performers), read for the reference.
        labels: "acted" or "perceived" (BML labels; Bandai takes are acted).
        source: where the clips came from (for the record).
        C: inverse regularisation strength.
    """


    def __init__(self, train, heldout, labels: str = "acted", source: str = "", C: float = 0.1):
        if labels not in LABEL_VARIANTS:
            raise ValueError(f"labels must be one of {LABEL_VARIANTS}, got {labels!r}")
        fit = [(c, clip_label(c, labels)) for c in train]
        fit = [(c, e) for c, e in fit if e is not None]
        missing = sorted(set(GAIT_EMOTIONS) - {e for _, e in fit})
        if missing:
            raise ValueError(f"calibrated observer: no training walks for {missing}")
        X, y, w = ro._take_windows([c.motion for c, _ in fit], [GAIT_EMOTIONS.index(e) for _, e in fit])
        self.clf = ro._fit(X, y, w, C)
        self.variant = labels
        # the record's ``observer`` value and the gate's observer kind (study_protocol.QA_OBSERVERS)
        self.kind = "real" if labels == "acted" else "real-perceived"
        self.C = C
        self.source = source
        self.train_takes = Counter(f"{c.dataset}:{e}" for c, e in fit)
        self.train_performers = sorted({c.motion.metadata.get("performer", c.dataset) for c, _ in fit})
        ref = [(c, clip_label(c, labels)) for c in heldout]
        ref = [(c, e) for c, e in ref if e is not None]
        self.heldout_performers = sorted({c.motion.metadata.get("performer", c.dataset) for c, _ in ref})
        overlap = set(self.heldout_performers) & set(self.train_performers) - {c.dataset for c, _ in fit}
        if overlap:
            raise ValueError(f"calibrated observer: held-out performers also in training: {sorted(overlap)}")
        cm = np.zeros((4, 4), int)
        for c, e in ref:
            cm[GAIT_EMOTIONS.index(e), int(self.proba(c.motion).argmax())] += 1
        self.heldout_confusion = cm
        self.heldout_n = {e: int(cm[i].sum()) for i, e in enumerate(GAIT_EMOTIONS)}
        self.heldout_recall = {e: (round(float(cm[i, i] / cm[i].sum()), 3) if cm[i].sum() else None)
                               for i, e in enumerate(GAIT_EMOTIONS)}

    @property
    def advisory_classes(self) -> tuple[str, ...]:
        """Classes whose held-out recall is below :data:`ADVISORY_RECALL` (or unknown)."""
        return tuple(e for e in GAIT_EMOTIONS
                     if self.heldout_recall[e] is None or self.heldout_recall[e] < ADVISORY_RECALL)

    def proba(self, motion: Motion) -> np.ndarray:
        """(4,) probabilities in GAIT_EMOTIONS order: the mean over the motion's 2 s windows."""
        p = self.clf.predict_proba(ro.window_descriptors(motion)).mean(0)
        out = np.zeros(len(GAIT_EMOTIONS))
        out[self.clf.classes_.astype(int)] = p
        return out

    def read(self, motion: Motion) -> dict:
        """The quality record's reading: ``observed``, ``observed_p``, ``observer`` (real), and beside it the
        observer's own held-out reference: ``observer_labels`` (acted/perceived), ``observer_heldout_recall``
        {emotion: recall on held-out real actors}, ``observer_heldout_n`` and ``observer_advisory_classes``."""
        label, p = self.observe(motion)
        return {"observed": label, "observed_p": round(p, 4), "observer": self.kind,
                "observer_labels": self.variant, "observer_heldout_recall": dict(self.heldout_recall),
                "observer_heldout_n": dict(self.heldout_n), "observer_advisory_classes": list(self.advisory_classes)}


def advisory_reason(values: dict, dominant: str | None) -> str | None:
    """Why an observer mismatch on this record is advisory (None when it may exclude): the intended or the
    observed class has a held-out real recall below :data:`ADVISORY_RECALL` (values from
    :meth:`CalibratedGaitObserver.read`; records of other observers have no recall and are never advisory)."""
    recall = values.get("observer_heldout_recall")
    if not recall:
        return None
    weak = []
    for e in dict.fromkeys(x for x in (dominant, values.get("observed")) if x):
        r = recall.get(e)
        if r is None or r < ADVISORY_RECALL:
            weak.append(f"{e} {'unknown' if r is None else f'{r:.2f}'}")
    if not weak:
        return None
    return (f"advisory: held-out real-actor recall of {', '.join(weak)} is below {ADVISORY_RECALL} "
            f"({values.get('observer_labels', '')} labels)")


def judge_against_reference(read_as_intended: dict[str, float], heldout_recall: dict[str, float | None]
                            ) -> dict[str, bool | None]:
    """{emotion: generated clips read as intended at least as often as held-out real actors' walks} (None where
    either share is unknown)."""
    out = {}
    for e in GAIT_EMOTIONS:
        g, r = read_as_intended.get(e), heldout_recall.get(e)
        out[e] = None if g is None or r is None else bool(g >= r)
    return out


def split_clips(bandai_path: str | Path | None = None, bml_path: str | Path | None = None):
    """(train, heldout) CorpusClips: Bandai dataset-1 emotion walks of the training split and BML train + val
    performers; held out: the BML test performers."""
    bandai = Path(bandai_path) if bandai_path is not None else DEFAULT_PATH
    bml = Path(bml_path) if bml_path is not None else DEFAULT_BML_PATH
    train = [c for c in load_real_corpus(bandai, skeleton="gait", split="train", contents="walk")
             if c.dataset == ro.EMOTION_DATASET and c.style in CAPTURE_GAIT_EMOTIONS]
    train += load_real_corpus(bml, skeleton="gait", split=("train", "val"))
    heldout = load_real_corpus(bml, skeleton="gait", split="test")
    return train, heldout


def train_calibrated_observer(labels: str = "acted", bandai_path: str | Path | None = None,
                              bml_path: str | Path | None = None) -> CalibratedGaitObserver:
    """The observer fitted on both corpora's training data (see the module docstring)."""
    train, heldout = split_clips(bandai_path, bml_path)
    n_bml = sum(c.dataset == BML_DATASET for c in train)
    source = (f"real capture: Bandai Namco dataset 1 training takes ({len(train) - n_bml}) + BML training/"
              f"validation actors ({n_bml} walks), {labels} labels; held out: {len(heldout)} BML walks of "
              "6 test actors")
    return CalibratedGaitObserver(train, heldout, labels, source)


def observer_version(labels: str = "acted", bandai_path: str | Path | None = None,
                     bml_path: str | Path | None = None) -> str | None:
    """Key of the two corpus files' versions (path, modification time) and the label variant; None when either
    corpus file is missing (then there is no calibrated observer)."""
    bandai = Path(bandai_path) if bandai_path is not None else DEFAULT_PATH
    bml = Path(bml_path) if bml_path is not None else DEFAULT_BML_PATH
    if not (bandai.is_file() and bml.is_file()):
        return None
    return f"{labels}:{bandai}:{bandai.stat().st_mtime_ns}:{bml}:{bml.stat().st_mtime_ns}"


def load_calibrated_observer(labels: str = "acted", bandai_path: str | Path | None = None,
                             bml_path: str | Path | None = None) -> CalibratedGaitObserver | None:
    """The calibrated observer of the corpora (default: the built ones), from its cache file in var/quality/ (named
    by the corpora's digests) or trained; None when either corpus file is missing."""
    bandai = Path(bandai_path) if bandai_path is not None else DEFAULT_PATH
    bml = Path(bml_path) if bml_path is not None else DEFAULT_BML_PATH
    if not (bandai.is_file() and bml.is_file()):
        return None
    sha = file_sha256(bandai)[:8] + file_sha256(bml)[:8]
    return load_or_build(ro.CACHE_DIR / f"calibrated_gait_observer_v{ro.DESCRIPTOR_VERSION}_{labels}_{sha}.pkl",
                         CalibratedGaitObserver, lambda: train_calibrated_observer(labels, bandai, bml))
