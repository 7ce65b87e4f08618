"""The observers of the quality gate: one protocol and one cache.

An observer stands in for a participant: it reads a clip's motion and says which emotion it shows. Four are
declared: the gait observer calibrated on both real corpora
(:class:`generation.quality.calibrated_observer.CalibratedGaitObserver`, kinds ``real`` with acted labels and
``real-perceived``; trained on the corpora when both are built, else read from its fitted parameters shipped in
generation/data/observers/), the Bandai-only real-capture gait observer
(:class:`generation.quality.real_observer.RealGaitObserver`, kind ``real`` when neither is there), the synthetic
gait observer (:class:`generation.quality.observer.GaitObserver`, ``synthetic``) and the synthetic gesture observer
(:class:`generation.quality.gesture_observer.GestureObserver`, ``synthetic-gesture``). Each module gives its
observer's version key (``observer_version``: which corpus it is trained on, or which shipped parameter file it
reads) and a loader (from its pickle or parameter file, or trained); :class:`Observers` keeps one of each per
version in memory, and :data:`OBSERVERS` is the process's.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Protocol, runtime_checkable

from generation.core.motion import Motion
from generation.mocap.real_corpus import DEFAULT_CORPORA, RealCorpora

from . import calibrated_observer, gesture_observer, observer, real_observer
from .checks import check_gait_observer


@runtime_checkable
class Observer(Protocol):
    """What the quality gate asks of an observer."""

    kind: str      # the record's ``observer`` value: real, synthetic or synthetic-gesture
    source: str    # what it was trained on, for the logs and the benchmarks

    def reads(self, motion: Motion) -> bool:
        """Whether the gate asks it about ``motion`` (its skeleton, long enough)."""

    def read(self, motion: Motion) -> dict:
        """The reading that goes into the quality record: ``observed``, ``observed_p``, ``observer`` (gestures
        also ``observed_arousal``)."""


class Observers:
    """The observers of one process, each loaded once per version of what it is trained on.

    Args:
        shipped_dir: where the calibrated observers' shipped parameter files are (default
            generation/data/observers/; a test names another).
    """

    def __init__(self, shipped_dir: str | Path = calibrated_observer.SHIPPED_DIR) -> None:
        self._loaded: dict[tuple, Observer | None] = {}
        self.shipped_dir = Path(shipped_dir)

    def _get(self, name: str, version: str | None, load: Callable[[], Observer | None]) -> Observer | None:
        if version is None:
            return None
        key = (name, version)
        if key not in self._loaded:
            self._loaded[key] = load()
        return self._loaded[key]

    def gait(self, kind: str = "real", corpus_path: str | Path | None = None,
             corpora: RealCorpora = DEFAULT_CORPORA) -> Observer | None:
        """The ``kind`` gait observer; None when it cannot be built here. ``real``: the observer calibrated on both
        real corpora of ``corpora`` (acted labels) when both are built, else the same read from its shipped
        parameter file (``shipped_dir``), else the Bandai-only one of ``corpora.bandai``; ``real-perceived``: the
        calibrated one with perceived labels (from the corpora, else shipped, else None); ``synthetic``: the
        procedural-corpus one. ``corpus_path`` names the one corpus file instead: real kinds then give the
        Bandai-only observer of that file, ``synthetic`` the one of that procedural corpus."""
        kind = check_gait_observer(kind)
        if kind == "synthetic":
            return self._get("synthetic", observer.observer_version(corpus_path),
                             lambda: observer.load_observer(corpus_path))
        if corpus_path is not None:
            return self._real(corpus_path)
        labels = "acted" if kind == "real" else "perceived"
        calibrated = self._get(f"calibrated-{labels}",
                               calibrated_observer.observer_version(labels, corpora.bandai, corpora.bml,
                                                                    self.shipped_dir),
                               lambda: calibrated_observer.load_calibrated_observer(labels, corpora.bandai,
                                                                                    corpora.bml, self.shipped_dir))
        if calibrated is not None or kind == "real-perceived":
            return calibrated
        return self._real(corpora.bandai)

    def _real(self, corpus_path: str | Path | None) -> Observer | None:
        return self._get("real", real_observer.observer_version(corpus_path),
                         lambda: real_observer.load_real_observer(corpus_path))

    def gesture(self) -> Observer | None:
        """The synthetic gesture observer of the current gesture corpus; None when it cannot be built here."""
        return self._get("synthetic-gesture", gesture_observer.observer_version(),
                         gesture_observer.load_gesture_observer)

    def for_modality(self, modality: str, gait_kind: str = "real",
                     corpora: RealCorpora = DEFAULT_CORPORA) -> Observer | None:
        """The observer that reads clips of ``modality`` ("gait": the ``gait_kind`` one of the real corpora
        ``corpora``; "gesture"); None for other modalities."""
        if modality == "gait":
            return self.gait(gait_kind, corpora=corpora)
        if modality == "gesture":
            return self.gesture()
        return None

    def clear(self) -> None:
        """Forget every loaded observer (their pickle files stay)."""
        self._loaded.clear()


#: The observers of this process.
OBSERVERS = Observers()
