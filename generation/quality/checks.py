"""Quality checks of one clip against thresholds: the record that goes into clips.csv (``qa_*`` columns), the
Clip row (``qa``, ``qa_flag``) and the render record (``record["qa"]``).

Checks (names in :data:`protocol.vocabulary.QA_CHECKS`), each against
:data:`protocol.vocabulary.QA_THRESHOLDS` or a plan's
``qa:`` overrides (a threshold set to null switches its check off):

- ``foot_skate``: mean foot slide in contact > ``foot_skate_cm_s``;
- ``penetration``: a foot joint deeper than ``penetration_cm`` below the floor;
- ``jerk``: mean joint jerk > ``jerk`` m/s^3;
- ``bone_error``: a bone length off by more than ``bone_error_mm``;
- ``figure_height``: smallest projected figure height / frame height < ``figure_height_frac_walk`` (or
  ``..._seated``), when the render's camera is known;
- ``observer``: a gait with a dominant intended emotion (a share of at least 0.5) that the gait observer reads as
  another emotion with probability >= ``observer_mismatch_p_real`` (the real-capture observer) or
  ``observer_mismatch_p`` (the synthetic one); or a gesture whose synthetic gesture
  observer (:mod:`generation.quality.gesture_observer`) reads an arousal at least ``gesture_arousal_gap`` away from
  the intended ``emotion_label``'s (NRC-VAD arousal, 0..1; the observed arousal is the arousal of the 11 emotions
  weighted by the observer's probabilities). The gesture rule reads arousal, not the top label: the 11 categories
  overlap in VAD (afraid and disgusted differ by at most 0.04 in each dimension) and the observer confuses such
  neighbours on generated gestures far more often than it misreads their arousal (figures in
  docs/benchmarks/motion_quality.md, "Gesture observer").

- ``realism``: a gait clip whose realism measures (:mod:`generation.quality.realism`: foot speed near the floor,
  foot-skating ratio, toe skim, stance knee flexion, pelvis bounce, walking-speed variability) leave the real
  corpus's own ranges (:mod:`generation.quality.realism_ranges`; bounds ``<measure>_min``/``<measure>_max``).

The gait observer is by default the real-capture observer (:mod:`generation.quality.real_observer`, trained on
real captured walks); the synthetic one (trained on the procedural corpus) is chosen with the plan's
``qa: {observer: synthetic}`` (:func:`gait_observer_kind`) or, for plans that name none, by the caller (the
``QA_GAIT_OBSERVER`` setting of the web app, ``--observer`` of the command line). The gesture observer is
synthetic. The observers and their cache: :mod:`generation.quality.observers`.
Observers are stand-ins for participants; a clip's record keeps the top label (``observed``), its probability
(``observed_p``), which observer read it (``observer``: real, synthetic or synthetic-gesture) and, for gestures,
the observed arousal (``observed_arousal``; in the record and Clip.qa, not a clips.csv column). Gesture clips
shorter than 2.5 s (the network's shortest gesture; the shortest training gesture is 2.7 s) get no reading: their
descriptors are outside what it was fitted on.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from generation.core.motion import Motion
from generation.core.skeleton import GAIT_JOINTS
from protocol.vocabulary import GAIT_EMOTIONS, GESTURE_VAD, QA_CHECKS, QA_COLUMNS, QA_OBSERVERS, QA_THRESHOLDS

from .calibrated_observer import advisory_reason
from .metrics import motion_metrics
from .realism import MEASURES, realism_measures
from .realism_ranges import out_of_range, realism_thresholds

DOMINANT_SHARE = 0.5
#: The key of a plan's ``qa:`` block that names the gait observer (the other keys are thresholds).
OBSERVER_KEY = "observer"


class QAThresholdError(ValueError):
    """A ``qa:`` block that cannot be used; the message names the key."""


@dataclass
class QAResult:
    """The quality record of one clip: ``values`` (keys of the qa_ columns without the prefix; None = not
    measured) and ``flags`` (failed checks, in QA_CHECKS order)."""

    values: dict = field(default_factory=dict)
    flags: list[str] = field(default_factory=list)

    @property
    def flag(self) -> str:
        return ";".join(self.flags)

    def as_dict(self) -> dict:
        """JSON-safe record: the values plus ``flag``."""
        return {**self.values, "flag": self.flag}

    @classmethod
    def from_dict(cls, qa: dict) -> QAResult:
        values = {k: v for k, v in qa.items() if k != "flag"}
        flag = qa.get("flag") or ""
        return cls(values, [f for f in flag.split(";") if f])


def check_gait_observer(kind, where: str = "gait observer") -> str:
    """``kind`` when it names a gait observer (:data:`protocol.vocabulary.QA_OBSERVERS`: real, real-perceived or
    synthetic), else
    QAThresholdError naming ``where`` (the plan field, setting or option it came from)."""
    if kind not in QA_OBSERVERS:
        raise QAThresholdError(f"{where}: expected one of {', '.join(QA_OBSERVERS)}, got {kind!r}")
    return kind


def gait_observer_kind(plan_qa: dict | None, default: str = "real") -> str:
    """The gait observer that reads a plan's clips: its ``qa: {observer: ...}``, else ``default`` (the caller's
    setting)."""
    kind = (plan_qa or {}).get(OBSERVER_KEY)
    return check_gait_observer(default if kind is None else kind,
                               "the default gait observer" if kind is None else f"field 'qa.{OBSERVER_KEY}'")


def resolve_thresholds(plan_qa: dict | None = None) -> dict:
    """The numeric thresholds: QA_THRESHOLDS plus the realism bounds (realism_ranges.json), overridden by a plan's
    ``qa:`` block (its ``observer`` key names the gait observer, not a threshold: :func:`gait_observer_kind`);
    unknown keys and bad values raise QAThresholdError."""

    out = {**QA_THRESHOLDS, **realism_thresholds()}
    if plan_qa is None:
        return out
    if not isinstance(plan_qa, dict):
        raise QAThresholdError(f"field 'qa': expected a mapping of thresholds, got {plan_qa!r}")
    for key, value in plan_qa.items():
        if key == OBSERVER_KEY:
            check_gait_observer(value, f"field 'qa.{key}'")
            continue
        if key not in out:
            raise QAThresholdError(f"field 'qa.{key}': unknown threshold; expected one of {sorted(out)}")
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))
                                  or not math.isfinite(value) or value < 0):
            raise QAThresholdError(f"field 'qa.{key}': expected a number >= 0 or null (check off), got {value!r}")
        out[key] = None if value is None else float(value)
    return out


def _dominant(intended) -> str | None:
    """The intended emotion with a share >= DOMINANT_SHARE of a gait emotion vector, or None."""
    if intended is None:
        return None
    vec = np.asarray(intended, dtype=float)
    if vec.shape != (len(GAIT_EMOTIONS),) or not np.isfinite(vec).all() or vec.sum() <= 0:
        return None
    vec = vec / vec.sum()
    k = int(np.argmax(vec))
    return GAIT_EMOTIONS[k] if vec[k] >= DOMINANT_SHARE else None


def _over(value, limit) -> bool:
    return limit is not None and value is not None and value > limit


def evaluate(motion: Motion, thresholds: dict | None = None, figure_height_frac: float | None = None,
             seated: bool = False, intended=None, observer=None) -> QAResult:
    """Measure ``motion`` and check it.

    Args:
        motion: the clip's motion as rendered (after resampling and cutting), metres, floor at y = 0.
        thresholds: from :func:`resolve_thresholds` (default: QA_THRESHOLDS).
        figure_height_frac: smallest projected figure height / frame height over the frames (None: not checked).
        seated: the clip shows a seated body (the seated figure-height threshold applies).
        intended: the gait emotion vector (GAIT_EMOTIONS order) or the gesture emotion label (GESTURE_EMOTIONS)
            the clip should show, or None.
        observer: a gait observer for gait motions (21 joints: the real-capture
            :class:`generation.quality.real_observer.RealGaitObserver` or the synthetic
            :class:`generation.quality.observer.GaitObserver`) or a
            :class:`generation.quality.gesture_observer.GestureObserver` for gesture motions (23 joints, at least
            as long as its ``min_seconds``, 2.5 s): an :class:`generation.quality.observers.Observer`, which says
            which motions it ``reads`` and ``read`` gives their reading. None or an observer of the other
            skeleton: no reading.

    Gait-skeleton motions also get the realism measures (:data:`generation.quality.realism.MEASURES`; None for
    other skeletons).
    """
    values = {k: round(v, 4) for k, v in motion_metrics(motion).items()}
    values["figure_height_frac"] = None if figure_height_frac is None else round(float(figure_height_frac), 4)
    values["observed"], values["observed_p"], values["observer"] = None, None, None
    if observer is not None and observer.reads(motion):
        values.update(observer.read(motion))
    gait = motion.skeleton.joints == GAIT_JOINTS and motion.num_frames >= 2
    realism = realism_measures(motion) if gait else dict.fromkeys(MEASURES)
    values.update({k: None if v is None else round(v, 4) for k, v in realism.items()})
    values["seated"] = bool(seated)
    flags = failed_checks(values, thresholds, intended)
    if values.get("observer_heldout_recall"):
        note = observer_advisory(values, thresholds, intended)
        values["observer_flag"] = note or ("exclusionary" if "observer" in flags else "none")
    return QAResult(values, flags)


def failed_checks(values: dict, thresholds: dict | None = None, intended=None) -> list[str]:
    """The checks (QA_CHECKS order) that measured ``values`` (as in :attr:`QAResult.values`) fail; also used to
    re-check a stored record against a plan's changed thresholds without measuring again."""
    th = resolve_thresholds(None) if thresholds is None else thresholds
    failed = {
        "foot_skate": _over(values.get("foot_skate_cm_s"), th["foot_skate_cm_s"]),
        "penetration": _over(values.get("penetration_cm"), th["penetration_cm"]),
        "jerk": _over(values.get("jerk"), th["jerk"]),
        "bone_error": _over(values.get("bone_error_mm"), th["bone_error_mm"]),
    }
    need = th["figure_height_frac_seated" if values.get("seated") else "figure_height_frac_walk"]
    frac = values.get("figure_height_frac")
    failed["figure_height"] = need is not None and frac is not None and frac < need
    if isinstance(intended, str):
        failed["observer"] = _gesture_mismatch(values, intended, th["gesture_arousal_gap"])
    else:
        # a calibrated observer's mismatch for a class it does not recognise on held-out real actors is advisory
        failed["observer"] = (_gait_mismatch(values, th, intended)
                              and advisory_reason(values, _dominant(intended)) is None)

    failed["realism"] = bool(out_of_range(values, th))
    return [c for c in QA_CHECKS if failed[c]]


def _gait_mismatch(values: dict, th: dict, intended) -> bool:
    """Whether the gait observer reads a dominant intended emotion as another with at least the mismatch p."""
    dominant = _dominant(intended)
    observed, p = values.get("observed"), values.get("observed_p")
    real = str(values.get("observer", "")).startswith("real")
    limit = th.get("observer_mismatch_p_real") if real else th["observer_mismatch_p"]
    return (limit is not None and dominant is not None and observed is not None and p is not None
            and observed != dominant and p >= limit)


def observer_advisory(values: dict, thresholds: dict | None = None, intended=None) -> str | None:
    """The reason a gait observer mismatch is only advisory (the observer's held-out real recall of the intended
    or observed class is below 0.6: :func:`generation.quality.calibrated_observer.advisory_reason`), or None when
    there is no mismatch or it excludes."""
    if isinstance(intended, str):
        return None
    th = resolve_thresholds(None) if thresholds is None else thresholds
    if not _gait_mismatch(values, th, intended):
        return None
    return advisory_reason(values, _dominant(intended))


def _gesture_mismatch(values: dict, intended: str, gap) -> bool:
    """Whether the gesture observer's arousal is at least ``gap`` away from the intended gesture emotion's NRC-VAD
    arousal (False when the check is off, the label unknown or the clip was not observed)."""
    observed = values.get("observed_arousal")
    if gap is None or observed is None or intended not in GESTURE_VAD:
        return False
    return abs(observed - GESTURE_VAD[intended][1]) >= gap


def qa_columns(qa: dict | None) -> dict:
    """The qa_ columns of clips.csv from a record's ``qa`` dict (as :meth:`QAResult.as_dict`); blanks when absent."""
    qa = qa or {}
    return {col: qa.get(col.removeprefix("qa_")) for col in QA_COLUMNS}
