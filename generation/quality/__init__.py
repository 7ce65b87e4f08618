"""Per-clip quality checks of stimulus motions: foot skate, floor penetration, jerk, bone length error, figure
height in frame, realism against real capture, and an observer's reading of the emotion.

Public interface:
    motion_metrics(motion) -> dict          the motion measures (units in the keys)
    evaluate(motion, ...) -> QAResult       measures + failed checks against thresholds
    resolve_thresholds(plan_qa) -> dict     QA_THRESHOLDS (protocol.vocabulary) overridden by a plan's ``qa:`` block
    gait_observer_kind(plan_qa, default)    the gait observer a plan names (``qa: {observer: ...}``), else default
    observers.Observer, OBSERVERS           the observer protocol (``reads``, ``read(motion) -> reading``) and the
                                            process's observers, each loaded once per corpus version
    realism.realism_measures(motion)        foot skate / skating ratio / toe skim with height-only contact, stance
                                            knee flexion, pelvis bounce, speed variability (realism.py)
    realism_ranges.realism_thresholds()     the real corpus's ranges of those measures (realism_ranges.json)
    RealGaitObserver                        logistic regression over the 4 gait emotions trained on real captured
                                            walks (real_observer.py; the gate's gait observer only when neither
                                            both corpora nor the shipped calibrated parameters are there)
    CalibratedGaitObserver                  the same trained on both real corpora, with its recall on held-out real
                                            actors per class and advisory flags below 0.6 (calibrated_observer.py;
                                            the gate's gait observer: trained when both corpora are built, else
                                            read from its parameters in generation/data/observers/)
    GaitObserver                            logistic regression on the 18 gait affective features (synthetic)
    GestureObserver                         multinomial logistic regression over the 11 gesture emotions on gesture
                                            motion descriptors (synthetic; gesture_observer.py)

Pure numpy/scikit-learn; no Django, no VTK.
"""
from .checks import (
    QAResult,
    QAThresholdError,
    evaluate,
    failed_checks,
    gait_observer_kind,
    qa_columns,
    resolve_thresholds,
)
from .metrics import motion_metrics

__all__ = ["QAResult", "QAThresholdError", "evaluate", "failed_checks", "gait_observer_kind", "motion_metrics",
           "qa_columns", "resolve_thresholds"]
