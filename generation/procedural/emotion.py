"""Emotion representations and their mapping to procedural motion parameters.

Gait (seed 000, section 3.2.2): an emotion is a vector over (happy, sad, angry, neutral) whose
entries are the relative counts of annotators who chose each term (l1-normalised).

Gestures (seed 003, section 3.1): a categorical emotion term is mapped to valence, arousal and
dominance in [0, 1] with the NRC-VAD lexicon (Mohammad, ACL 2018): :data:`protocol.vocabulary.GESTURE_VAD`, which
cites it.

The parameter mappings are hand-made from the literature the papers cite, not learned:
- gait: arousal goes with speed, cadence and arm swing; sadness with a bowed head and trunk,
  contracted arms and a slow, short stride; anger with a fast, heavy, expanded gait and a forward
  lean; happiness with a fast, bouncy, expanded gait, head up (seed 000 section 3.2.3; seed 004
  Table III: happy = increased shoulder/wrist/knee swing and head up; sad = shoulders, head and neck
  tilted down, decreased shoulder and wrist swing; energetic = increased knee/elbow/shoulder swing,
  head up; tired = head and shoulders down, decreased ankle swing);
- gestures: arousal drives speed, amplitude and head movement, dominance drives expansion and an
  upright (vs collapsed) trunk and head, valence tilts the head up or down (seed 003 section 4.3,
  which notes that valence has no consistent body signature, so its weight is small).
"""
from __future__ import annotations

import numpy as np

from protocol.vocabulary import GAIT_EMOTIONS, GESTURE_VAD

from .gesture import GESTURE_KINDS, GestureParams
from .walk import WalkParams


def vad_for(word: str) -> tuple[float, float, float]:
    """(valence, arousal, dominance) of an emotion word; KeyError listing the known words."""
    key = word.strip().lower()
    if key not in GESTURE_VAD:
        raise KeyError(f"no NRC-VAD entry for {word!r}; known words: {sorted(GESTURE_VAD)}")
    return GESTURE_VAD[key]


# ---- gait --------------------------------------------------------------------------------------
def normalize_emotion(vec) -> np.ndarray:
    """l1-normalise a (..., 4) non-negative (happy, sad, angry, neutral) vector.

    Accepts a sequence, an array, or a dict with some of the keys of :data:`GAIT_EMOTIONS`.
    Raises ValueError for a wrong length, unknown key, negative or non-finite entries, or an
    all-zero vector.
    """
    if isinstance(vec, dict):
        unknown = set(vec) - set(GAIT_EMOTIONS)
        if unknown:
            raise ValueError(f"unknown gait emotion(s) {sorted(unknown)}; expected keys from {GAIT_EMOTIONS}")
        vec = [vec.get(k, 0.0) for k in GAIT_EMOTIONS]
    arr = np.asarray(vec, dtype=np.float64)
    if arr.ndim == 0 or arr.shape[-1] != len(GAIT_EMOTIONS):
        raise ValueError(f"gait emotion vector must have {len(GAIT_EMOTIONS)} entries {GAIT_EMOTIONS}, "
                         f"got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise ValueError(f"gait emotion vector has NaN or infinite entries: {arr.tolist()}")
    if (arr < 0).any():
        raise ValueError(f"gait emotion vector entries must be non-negative, got {arr.tolist()}")
    total = arr.sum(-1, keepdims=True)
    if (total <= 0).any():
        raise ValueError("gait emotion vector sums to zero; at least one entry must be positive")
    return arr / total


# Prototype gaits for the pure emotions (values for a 1.75 m body). Neutral is the default walk.
_GAIT_PROTOTYPES = {
    "neutral": WalkParams.neutral(),
    "happy": WalkParams(cadence_spm=124.0, stride_m=1.52, arm_swing_rad=0.52, elbow_bend_rad=0.40,
                        torso_pitch_rad=-0.03, head_pitch_rad=-0.14, shoulder_raise_m=0.0, knee_lift_rad=1.25,
                        lateral_sway_m=0.035, arm_abduction_rad=0.24, bounce_m=0.045, step_width_m=0.16,
                        toe_out_rad=0.12, pelvis_rotation_rad=0.09, head_nod_rad=0.05, knee_bend_m=0.005),
    "sad": WalkParams(cadence_spm=86.0, stride_m=1.02, arm_swing_rad=0.08, elbow_bend_rad=0.12,
                      torso_pitch_rad=0.24, head_pitch_rad=0.62, shoulder_raise_m=-0.02, knee_lift_rad=0.75,
                      lateral_sway_m=0.03, arm_abduction_rad=0.0, bounce_m=0.008, step_width_m=0.14,
                      toe_out_rad=0.08, pelvis_rotation_rad=0.03, head_nod_rad=0.01, knee_bend_m=0.02),
    "angry": WalkParams(cadence_spm=128.0, stride_m=1.58, arm_swing_rad=0.50, elbow_bend_rad=0.85,
                        torso_pitch_rad=0.16, head_pitch_rad=0.08, shoulder_raise_m=0.025, knee_lift_rad=1.1,
                        lateral_sway_m=0.02, arm_abduction_rad=0.30, bounce_m=0.018, step_width_m=0.20,
                        toe_out_rad=0.10, pelvis_rotation_rad=0.08, head_nod_rad=0.015, knee_bend_m=0.012),
}

# Per-individual variation (standard deviations), applied as multiplicative noise on the mixture.
_GAIT_JITTER = {
    "cadence_spm": 5.0, "stride_m": 0.06, "arm_swing_rad": 0.04, "elbow_bend_rad": 0.05, "torso_pitch_rad": 0.02,
    "head_pitch_rad": 0.04, "shoulder_raise_m": 0.004, "knee_lift_rad": 0.06, "lateral_sway_m": 0.005,
    "arm_abduction_rad": 0.03, "bounce_m": 0.005, "step_width_m": 0.015, "toe_out_rad": 0.03,
    "pelvis_rotation_rad": 0.01, "head_nod_rad": 0.005, "knee_bend_m": 0.003,
}


def gait_params_for_emotion(vec4, rng: np.random.Generator | None = None, jitter: float = 1.0) -> WalkParams:
    """Walk parameters expressing a (happy, sad, angry, neutral) emotion vector.

    The vector is l1-normalised, then each parameter is the same convex combination of the
    prototype gaits (so mixtures vary continuously between pure emotions). With ``rng``, each
    parameter gets Gaussian individual variation (standard deviations in ``_GAIT_JITTER`` times
    ``jitter``), clipped to the valid ranges.
    """
    w = normalize_emotion(vec4)
    if w.ndim != 1:
        raise ValueError(f"gait_params_for_emotion takes one vector of 4, got shape {w.shape}")
    out = {}
    for name in _GAIT_JITTER:
        value = sum(float(w[i]) * getattr(_GAIT_PROTOTYPES[e], name) for i, e in enumerate(GAIT_EMOTIONS))
        if rng is not None and jitter > 0:
            value += rng.normal(0.0, _GAIT_JITTER[name] * jitter)
        lo, hi = WalkParams._LIMITS[name]
        out[name] = float(np.clip(value, lo, hi))
    return WalkParams(**out).validate()


# How annotators who do not pick the intended term spread their labels (rows: intended emotion,
# columns: chosen term, order GAIT_EMOTIONS). High-arousal emotions are confused with each other,
# low-arousal ones with neutral (the arousal axis is what gaits convey best; seed 000 section 3.1).
_CONFUSION = np.array([
    [0.00, 0.10, 0.40, 0.50],   # happy   -> angry or neutral
    [0.10, 0.00, 0.20, 0.70],   # sad     -> mostly neutral
    [0.50, 0.10, 0.00, 0.40],   # angry   -> happy or neutral
    [0.35, 0.45, 0.20, 0.00],   # neutral -> sad or happy
])


def simulate_annotators(true_vec, n_annotators: int = 10, rng: np.random.Generator | None = None,
                        confusion: float = 0.25) -> np.ndarray:
    """Simulated annotation of a gait: l1-normalised relative counts of the terms chosen (seed 000 3.2.2).

    Each of ``n_annotators`` picks one term from p = (1 - confusion) * m + confusion * m C, where m
    is the normalised true emotion vector and C the confusion matrix above; the result is the
    count of each term divided by ``n_annotators``. Synthetic: no person annotated anything.
    Returns a (4,) float array summing to 1.
    """
    if int(n_annotators) < 1:
        raise ValueError(f"n_annotators must be at least 1, got {n_annotators}")
    if not 0.0 <= confusion <= 1.0:
        raise ValueError(f"confusion must be in [0, 1], got {confusion}")
    rng = rng if rng is not None else np.random.default_rng()
    m = normalize_emotion(true_vec)
    p = (1.0 - confusion) * m + confusion * (m @ _CONFUSION)
    counts = rng.multinomial(int(n_annotators), p / p.sum())
    return counts / float(n_annotators)


# ---- gestures ----------------------------------------------------------------------------------
def _check_unit(name: str, x: float) -> float:
    x = float(x)
    if not np.isfinite(x) or not 0.0 <= x <= 1.0:
        raise ValueError(f"{name} must be in [0, 1] (normalised VAD), got {x}")
    return x


def gesture_params_for_vad(v: float, a: float, d: float, rng: np.random.Generator | None = None,
                           kind: str | None = None, handedness: str = "right", jitter: float = 1.0) -> GestureParams:
    """Seated-gesture parameters expressing valence ``v``, arousal ``a``, dominance ``d`` (all in [0, 1]).

    - arousal: speed 0.55-1.75 (tempo multiplier), amplitude 0.45-1.35, head movement 0.04-0.24 rad;
    - dominance: expansion -1 (arms close, contracted) .. +1 (spread arms), trunk slump (+ = collapsed
      forward) and head pitch;
    - valence: a small head pitch term (chin up for pleasant, down for unpleasant).

    ``kind`` (beat, pointing, descriptive) is drawn when None: beats are more likely at high arousal.
    ``rng`` adds small individual variation.
    """
    v, a, d = _check_unit("valence", v), _check_unit("arousal", a), _check_unit("dominance", d)
    if kind is None:
        if rng is None:
            kind = "beat" if a >= 0.6 else "descriptive"
        else:
            p_beat = 0.2 + 0.4 * a
            kind = str(rng.choice(GESTURE_KINDS, p=[p_beat, 0.25, 0.75 - p_beat]))
    noise = (lambda s: rng.normal(0.0, s * jitter)) if (rng is not None and jitter > 0) else (lambda s: 0.0)
    params = GestureParams(
        kind=kind,
        speed=float(np.clip(0.55 + 1.2 * a + noise(0.05), 0.3, 2.5)),
        amplitude=float(np.clip(0.45 + 0.9 * a + noise(0.05), 0.2, 1.6)),
        expansion=float(np.clip(2.4 * (d - 0.45) + noise(0.06), -1.0, 1.0)),
        handedness=handedness,
        head_motion=float(np.clip(0.04 + 0.2 * a + noise(0.01), 0.0, 0.4)),
        head_pitch=float(np.clip(0.9 * (0.45 - d) + 0.4 * (0.5 - v) + noise(0.02), -0.3, 0.8)),
        torso_lean=float(np.clip(0.9 * (0.45 - d) + noise(0.015), -0.2, 0.5)),
    )
    return params.validate()
