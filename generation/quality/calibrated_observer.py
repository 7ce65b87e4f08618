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

**Shipped parameters**: both fitted observers ship as small JSON files in ``generation/data/observers/``
(:func:`shipped_path`; format in :func:`observer_parameters`, licences and provenance in that folder's README.md),
so a machine without the corpora still gates with the calibrated observer and its advisory classes
(:func:`load_calibrated_observer`). Rebuild them from the corpora with
``python -m generation.quality.calibrated_observer export --out generation/data/observers/``.
"""
from __future__ import annotations

import argparse
import json
import os
import re
from collections import Counter
from dataclasses import astuple
from pathlib import Path

import numpy as np

from generation.core.digest import cached_file_sha256, file_sha256
from generation.core.motion import Motion
from generation.mocap.emotion_gait_bml import DATASET as BML_DATASET
from generation.mocap.real_corpus import RealCorpora, load_real_corpus, read_meta
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS

from . import real_observer as ro
from .pickle_cache import load_or_build

ADVISORY_RECALL = 0.6
LABEL_VARIANTS = ("acted", "perceived")
SHIPPED_DIR = ro.REPO_ROOT / "generation" / "data" / "observers"
"""Where the fitted observers' parameter files ship (:func:`shipped_path`)."""
PARAMETERS_FORMAT = "calibrated-gait-observer parameters 1"
"""The ``format`` of a parameter file (:func:`observer_parameters`); bump when its fields change."""
PARAMETERS_LICENCE = ("derived from the Bandai Namco Research Motion Dataset (CC BY-NC 4.0) and the BML walks with "
                      "Emotion-Gait labels (research use only, with citation): non-commercial research use only; "
                      "cite Kobayashi et al. 2023, Ma, Paterson & Pollick 2006 and Bhattacharya et al. 2020 (see "
                      "README.md beside this file)")
"""The licence of the parameter files (README.md in :data:`SHIPPED_DIR` has the full notice)."""


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


class StandardisedSoftmax:
    """The fitted classifier as plain arrays (what a parameter file keeps): standardise the descriptors, then a
    multinomial logistic regression, as the scikit-learn pipeline of :func:`real_observer._fit` computes it.

    Args:
        mean, scale: (D,) the scaler's mean and scale (descriptor units).
        coef: (K, D) and intercept: (K,) the logistic regression's weights on standardised descriptors.
        classes: (K,) the class indices into GAIT_EMOTIONS, in coef's row order.
    """

    def __init__(self, mean, scale, coef, intercept, classes):
        self.mean = np.asarray(mean, dtype=np.float64)
        self.scale = np.asarray(scale, dtype=np.float64)
        self.coef = np.asarray(coef, dtype=np.float64)
        self.intercept = np.asarray(intercept, dtype=np.float64)
        self.classes_ = np.asarray(classes, dtype=np.int64)
        d, k = self.mean.shape[0], self.classes_.shape[0]
        if self.scale.shape != (d,) or self.coef.shape != (k, d) or self.intercept.shape != (k,) or k < 3:
            raise ValueError(f"classifier parameters do not fit together: mean {self.mean.shape}, scale "
                             f"{self.scale.shape}, coef {self.coef.shape}, intercept {self.intercept.shape}, "
                             f"classes {self.classes_.shape} (a multinomial model of 3 or more classes)")

    @classmethod
    def of_pipeline(cls, clf) -> StandardisedSoftmax:
        """The arrays of a fitted StandardScaler + LogisticRegression pipeline (:func:`real_observer._fit`)."""
        scaler, logreg = clf[0], clf[-1]
        return cls(scaler.mean_, scaler.scale_, logreg.coef_, logreg.intercept_, clf.classes_)

    def predict_proba(self, X: np.ndarray) -> np.ndarray:
        """(W, K) class probabilities of (W, D) descriptors: softmax of the standardised linear scores."""
        z = (np.asarray(X, dtype=np.float64) - self.mean) / self.scale
        scores = z @ self.coef.T + self.intercept
        scores -= scores.max(axis=1, keepdims=True)
        e = np.exp(scores)
        return e / e.sum(axis=1, keepdims=True)


class CalibratedGaitObserver(ro.WindowedGaitObserver):
    """Emotion classifier on real walks of both corpora, with its recall on held-out real actors.

    Args:
        train: CorpusClips to fit on (gait skeleton; those without a label of :func:`clip_label` are ignored).
        heldout: CorpusClips of actors never in ``train`` (the BML test performers), read for the reference.
        labels: "acted" or "perceived" (BML labels; Bandai takes are acted).
        source: where the clips came from (for the record).
        C: inverse regularisation strength.

    :meth:`from_parameters` makes one from a parameter file's contents instead (no training); its ``clf`` is then a
    :class:`StandardisedSoftmax` and ``parameters_sha256`` names the file.
    """

    parameters_sha256: str | None = None   # the shipped parameter file's SHA-256 when loaded from one

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
        # the record's ``observer`` value and the gate's observer kind (protocol.vocabulary.QA_OBSERVERS)
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

    @classmethod
    def from_parameters(cls, params: dict, sha256: str | None = None) -> CalibratedGaitObserver:
        """The observer a parameter file describes (:func:`observer_parameters`; no training): the same readings,
        held-out reference and advisory classes as the fitted one. ``sha256`` names the file it came from.

        Raises ValueError for a file of another format or descriptor version (its weights would read other
        descriptors: re-export it) or with classifier arrays that do not fit together."""
        if params.get("format") != PARAMETERS_FORMAT:
            raise ValueError(f"calibrated observer parameters: format {params.get('format')!r}, expected "
                             f"{PARAMETERS_FORMAT!r}")
        if params.get("descriptor_version") != ro.DESCRIPTOR_VERSION:
            raise ValueError(f"calibrated observer parameters: descriptor version {params.get('descriptor_version')!r}"
                             f", the code's is {ro.DESCRIPTOR_VERSION!r}; re-export them (python -m "
                             "generation.quality.calibrated_observer export)")
        if params.get("labels") not in LABEL_VARIANTS:
            raise ValueError(f"calibrated observer parameters: labels must be one of {LABEL_VARIANTS}")
        c = params["classifier"]
        obs = cls.__new__(cls)
        obs.clf = StandardisedSoftmax(c["scaler_mean"], c["scaler_scale"], c["coef"], c["intercept"],
                                      [GAIT_EMOTIONS.index(e) for e in c["classes"]])
        obs.variant = params["labels"]
        obs.kind = "real" if obs.variant == "acted" else "real-perceived"
        obs.C = float(params["C"])
        obs.source = params.get("source", "")
        obs.train_takes = Counter({k: int(v) for k, v in params["train_takes"].items()})
        obs.train_performers = list(params["train_performers"])
        obs.heldout_performers = list(params["heldout_performers"])
        obs.heldout_confusion = np.asarray(params["heldout_confusion"], dtype=int).reshape(4, 4)
        obs.heldout_n = {e: int(params["heldout_n"][e]) for e in GAIT_EMOTIONS}
        obs.heldout_recall = {e: params["heldout_recall"][e] for e in GAIT_EMOTIONS}
        obs.parameters_sha256 = sha256
        return obs

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
    bandai, bml = astuple(RealCorpora.of(bandai_path, bml_path))
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
                     bml_path: str | Path | None = None, shipped_dir: str | Path = SHIPPED_DIR) -> str | None:
    """Key of what the observer comes from, with the label variant: both corpus files' versions (path,
    modification time) when both are there, else the shipped parameter file's SHA-256 (``shipped:...``); None
    when there is neither (then there is no calibrated observer)."""
    bandai, bml = astuple(RealCorpora.of(bandai_path, bml_path))
    if bandai.is_file() and bml.is_file():
        return f"{labels}:{bandai}:{bandai.stat().st_mtime_ns}:{bml}:{bml.stat().st_mtime_ns}"
    shipped = shipped_path(labels, shipped_dir)
    if shipped.is_file():
        return f"{labels}:shipped:{shipped}:{cached_file_sha256(shipped)}"
    return None


def load_calibrated_observer(labels: str = "acted", bandai_path: str | Path | None = None,
                             bml_path: str | Path | None = None,
                             shipped_dir: str | Path = SHIPPED_DIR) -> CalibratedGaitObserver | None:
    """The calibrated observer of the corpora (default: the built ones), from its cache file in var/quality/ (named
    by the corpora's digests) or trained; without both corpus files, the fitted one shipped in ``shipped_dir``
    (:func:`load_shipped_observer`); None when neither is there."""
    bandai, bml = astuple(RealCorpora.of(bandai_path, bml_path))
    if not (bandai.is_file() and bml.is_file()):
        return load_shipped_observer(labels, shipped_dir)
    sha = file_sha256(bandai)[:8] + file_sha256(bml)[:8]
    return load_or_build(ro.CACHE_DIR / f"calibrated_gait_observer_v{ro.DESCRIPTOR_VERSION}_{labels}_{sha}.pkl",
                         CalibratedGaitObserver, lambda: train_calibrated_observer(labels, bandai, bml))


# ---- the shipped parameter files --------------------------------------------------------------------------------

def shipped_path(labels: str = "acted", folder: str | Path = SHIPPED_DIR) -> Path:
    """The parameter file of the ``labels`` variant in ``folder``: ``calibrated_gait_observer_<labels>.json``."""
    if labels not in LABEL_VARIANTS:
        raise ValueError(f"labels must be one of {LABEL_VARIANTS}, got {labels!r}")
    return Path(folder) / f"calibrated_gait_observer_{labels}.json"


def corpus_provenance(path: str | Path) -> dict:
    """What a parameter file says of one corpus it was fitted on: file name, SHA-256, and the corpus's own dataset,
    licence, citation, source and the contents it holds (its ``meta_json``)."""
    meta = read_meta(path)
    out = {"file": Path(path).name, "sha256": file_sha256(path)}
    for key in ("dataset", "licence", "citation", "source_url", "contents", "tool_version"):
        if key in meta:
            out[key] = meta[key]
    return out


def observer_parameters(obs: CalibratedGaitObserver, corpora: dict | None = None) -> dict:
    """A fitted observer as a JSON-ready dict (the parameter file; :meth:`CalibratedGaitObserver.from_parameters`
    reads it back). Fields:

    - ``format`` (:data:`PARAMETERS_FORMAT`), ``descriptor_version`` (:data:`real_observer.DESCRIPTOR_VERSION`:
      the weights apply to these descriptors only), ``descriptors`` and ``classifier.model`` (what they compute);
    - ``kind`` (real / real-perceived), ``labels`` (acted / perceived), ``C``;
    - ``classifier``: ``classes`` (emotion names, in the row order of ``coef``), ``scaler_mean`` and
      ``scaler_scale`` (38 each, descriptor units), ``coef`` (4 x 38) and ``intercept`` (4);
    - ``heldout_performers``, ``heldout_n``, ``heldout_recall`` (per emotion; null where none is held out),
      ``heldout_confusion`` (rows: the walks' labels, columns: the top reading, GAIT_EMOTIONS order),
      ``advisory_recall`` and ``advisory_classes`` (as at export; the gate recomputes them from the recall);
    - ``train_takes`` ({dataset:emotion: walks}), ``train_performers``, ``source``;
    - ``corpora``: {bandai, bml: :func:`corpus_provenance`} (null for an observer not fitted on corpus files),
      ``licence`` (of these derived parameters) and ``fitted_with`` (library versions).
    """
    import sklearn  # only for its version; a heavy import the readers of the shipped files need not pay

    clf = obs.clf if isinstance(obs.clf, StandardisedSoftmax) else StandardisedSoftmax.of_pipeline(obs.clf)
    return {
        "format": PARAMETERS_FORMAT,
        "descriptor_version": ro.DESCRIPTOR_VERSION,
        "descriptors": ("generation.quality.real_observer.window_descriptors: per 2 s window (hop 0.5 s), the 18 "
                        "gait affective features' means (clipped to +-10) and standard deviations, root speed / "
                        "height (1/s) and root vertical peak-to-peak / height (38 values)"),
        "kind": obs.kind,
        "labels": obs.variant,
        "C": obs.C,
        "classifier": {
            "model": ("standardised multinomial logistic regression: p = softmax(((x - scaler_mean) / scaler_scale)"
                      " @ coef.T + intercept) per window; a motion's reading is the mean over its windows"),
            "classes": [GAIT_EMOTIONS[int(k)] for k in clf.classes_],
            "scaler_mean": clf.mean.tolist(),
            "scaler_scale": clf.scale.tolist(),
            "coef": clf.coef.tolist(),
            "intercept": clf.intercept.tolist(),
        },
        "heldout_performers": list(obs.heldout_performers),
        "heldout_n": dict(obs.heldout_n),
        "heldout_recall": dict(obs.heldout_recall),
        "heldout_confusion": np.asarray(obs.heldout_confusion).tolist(),
        "advisory_recall": ADVISORY_RECALL,
        "advisory_classes": list(obs.advisory_classes),
        "train_takes": dict(sorted(obs.train_takes.items())),
        "train_performers": list(obs.train_performers),
        "source": obs.source,
        "corpora": corpora,
        "licence": PARAMETERS_LICENCE,
        "fitted_with": {"scikit-learn": sklearn.__version__, "numpy": np.__version__},
    }


def _compact_json(obj) -> str:
    """Indented JSON with every list of numbers on one line (floats as Python's repr: they read back exactly)."""
    text = json.dumps(obj, indent=2, ensure_ascii=False)
    return re.sub(r"\[[-0-9.eE+,\s]*\]",
                  lambda m: "[" + ", ".join(x.strip() for x in m.group(0)[1:-1].split(",")) + "]", text) + "\n"


def write_parameters(path: str | Path, params: dict) -> Path:
    """Write a parameter dict as ``path`` (parent folders created, atomically). Returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(_compact_json(params), encoding="utf-8")
    tmp.replace(path)
    return path


def read_parameters(path: str | Path) -> CalibratedGaitObserver:
    """The observer of the parameter file at ``path`` (``parameters_sha256`` = the file's SHA-256)."""
    path = Path(path)
    return CalibratedGaitObserver.from_parameters(json.loads(path.read_text(encoding="utf-8")), file_sha256(path))


def load_shipped_observer(labels: str = "acted", folder: str | Path = SHIPPED_DIR) -> CalibratedGaitObserver | None:
    """The fitted ``labels`` observer shipped in ``folder`` (default generation/data/observers/); None when its file
    is missing. Its ``source`` says that it comes from the file and which."""
    path = shipped_path(labels, folder)
    if not path.is_file():
        return None
    obs = read_parameters(path)
    obs.source = (f"{obs.source}; fitted parameters shipped in {path.name} (sha256 {obs.parameters_sha256[:12]}), "
                  "the corpora are not built here")
    return obs


def export_observers(out_dir: str | Path = SHIPPED_DIR, bandai_path: str | Path | None = None,
                     bml_path: str | Path | None = None, labels=LABEL_VARIANTS
                     ) -> list[tuple[Path, CalibratedGaitObserver]]:
    """Fit each ``labels`` variant on the corpora (fresh, not from the cache) and write its parameter file into
    ``out_dir``. Returns (path, observer) per variant."""
    bandai, bml = astuple(RealCorpora.of(bandai_path, bml_path))
    corpora = {"bandai": corpus_provenance(bandai), "bml": corpus_provenance(bml)}
    out = []
    for lab in labels:
        obs = train_calibrated_observer(lab, bandai, bml)
        out.append((write_parameters(shipped_path(lab, out_dir), observer_parameters(obs, corpora)), obs))
    return out


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m generation.quality.calibrated_observer",
                                 description="The gait observers calibrated on real walks of many actors.")
    sub = ap.add_subparsers(dest="command", required=True)
    ex = sub.add_parser("export", help="fit the observers on both corpora and write their parameter files")
    ex.add_argument("--out", type=Path, default=SHIPPED_DIR, help="folder (default generation/data/observers/)")
    ex.add_argument("--bandai", type=Path, help="Bandai Namco corpus (default $REAL_CORPUS, else "
                                                "var/mocap/bandai-namco.npz)")
    ex.add_argument("--bml", type=Path, help="BML corpus (default $BML_CORPUS, else var/mocap/emotion-gait-bml.npz)")
    ex.add_argument("--labels", nargs="+", choices=LABEL_VARIANTS, default=list(LABEL_VARIANTS))
    return ap


def main(argv=None) -> int:
    """``export``: 0 when every file was written, 2 when a corpus file is missing."""
    args = build_parser().parse_args(argv)
    env = RealCorpora.from_environ(os.environ)
    corpora = RealCorpora.of(args.bandai or env.bandai, args.bml or env.bml)
    missing = [str(p) for p in (corpora.bandai, corpora.bml) if not p.is_file()]
    if missing:
        print(f"no corpus at {', '.join(missing)} (build them: python -m generation.mocap dataset bandai-namco / "
              "emotion-gait-bml, docs/mocap.md)")
        return 2
    for path, obs in export_observers(args.out, corpora.bandai, corpora.bml, args.labels):
        recall = ", ".join(f"{e} {r}" for e, r in obs.heldout_recall.items())
        print(f"{path}: {obs.variant} labels, held-out recall {recall}; advisory {list(obs.advisory_classes)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
