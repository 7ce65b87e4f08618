"""Per-clip quality checks of stimulus motions (issue 14): foot skate, floor penetration, jerk, bone length
error, figure height in frame, and a synthetic observer's reading of the emotion.

Public interface:
    motion_metrics(motion) -> dict          the motion measures (units in the keys)
    evaluate(motion, ...) -> QAResult       measures + failed checks against thresholds
    resolve_thresholds(plan_qa) -> dict     QA_THRESHOLDS (study_protocol) overridden by a plan's ``qa:`` block
    GaitObserver                            logistic regression on the 18 gait affective features (synthetic)
    GestureObserver                         multinomial logistic regression over the 11 gesture emotions on gesture
                                            motion descriptors (synthetic; gesture_observer.py)

Pure numpy/scikit-learn; no Django, no VTK.
"""
from .checks import QAResult, QAThresholdError, evaluate, failed_checks, qa_columns, resolve_thresholds
from .metrics import motion_metrics

__all__ = ["QAResult", "QAThresholdError", "evaluate", "failed_checks", "motion_metrics", "qa_columns",
           "resolve_thresholds"]
