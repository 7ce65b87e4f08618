"""SYNTHETIC answers: how the simulator (:mod:`analysis.simulate`) answers each section type, one answer model per
registered section type (``protocol.section_types``; its declaration's ``simulator`` says the same in words).

An answer model is ``model(rng, section, shown, clips, m, effects) -> [answers per question]``: the section
(:class:`analysis.design.SectionDesign`), the items shown (:class:`Shown`), the clip table, the
:class:`analysis.simulate.PerceptionModel` and per-participant effects (``likert``, ``theme``: (P,) arrays); it
returns one array per question of the section (``section.questions`` order), aligned with ``shown``. A new section
type registers one with :func:`register_answer_model`.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from protocol.vocabulary import (
    FINAL_EMOTION_COLUMNS,
    GAIT_EMOTIONS,
    GESTURE_VAD,
    LIKERT_FEATURES,
    NEUTRAL_CHOICES,
)

E = len(GAIT_EMOTIONS)
NEUTRAL = GAIT_EMOTIONS.index("neutral")

AnswerModel = Callable[..., list]
"""``(rng, section, shown, clips, m, effects) -> list of (N,) answer arrays``."""


@dataclass
class Shown:
    """The clips one section shows: parallel arrays over shown items (participant index, clip row, 0-based position)
    and, for a section with drawn choices, the offered categories as (N, n_options) indices into ``labels``."""

    p: np.ndarray
    clip: np.ndarray
    pos: np.ndarray
    options: np.ndarray | None = None
    labels: tuple[str, ...] = ()


def categorical(rng, probs: np.ndarray) -> np.ndarray:
    """One draw per row of ``probs`` (N, K) (rows sum to 1) -> (N,) indices."""
    c = np.cumsum(probs, axis=1)
    u = rng.random((probs.shape[0], 1)) * c[:, -1:]
    return np.minimum((u >= c).sum(axis=1), probs.shape[1] - 1)


def gait_answers(rng, intended: np.ndarray, m) -> np.ndarray:
    """(N, 4) intended vectors -> (N,) answer strings like "happy;neutral"."""
    p = (1 - m.emotion_noise) * intended + m.emotion_noise / E
    first = categorical(rng, p)
    p2 = p + 1e-9  # a second label is possible even when the intended vector has one non-zero component
    p2[np.arange(len(p)), first] = 0
    second = categorical(rng, p2 / p2.sum(axis=1, keepdims=True))
    two = rng.random(len(p)) < m.multi_select_prob
    lo, hi = np.minimum(first, second), np.maximum(first, second)
    names = np.asarray(GAIT_EMOTIONS, dtype=object)
    table = np.array([[names[i] if i == j else f"{names[i]};{names[j]}" for j in range(E)] for i in range(E)],
                     dtype=object)
    return np.where(two, table[lo, hi], names[first])


def intended_vectors(clips: pd.DataFrame, columns) -> np.ndarray:
    """(n_clips, 4) intended vectors from ``columns``; a clip without one counts as pure neutral."""
    v = clips[list(columns)].to_numpy(float)
    blank = ~np.isfinite(v).all(axis=1) | (np.nan_to_num(v).sum(axis=1) <= 0)
    v = np.nan_to_num(v)
    v[blank] = np.eye(E)[NEUTRAL]
    return v / v.sum(axis=1, keepdims=True)


def likert_mean_matrix(likert_means: dict) -> np.ndarray:
    """(emotions, features) mean ratings in GAIT_EMOTIONS x LIKERT_FEATURES order; ValueError naming a gait emotion
    the perception model has no means for (or one it has that the vocabulary lacks) and a row of the wrong length."""
    missing = [e for e in GAIT_EMOTIONS if e not in likert_means]
    extra = [e for e in likert_means if e not in GAIT_EMOTIONS]
    if missing or extra:
        raise ValueError(f"likert_means: no means for gait emotion(s) {missing}" if missing else
                         f"likert_means: {extra} are not gait emotions ({', '.join(GAIT_EMOTIONS)})")
    bad = [e for e in GAIT_EMOTIONS if len(likert_means[e]) != len(LIKERT_FEATURES)]
    if bad:
        raise ValueError(f"likert_means: {bad} need one mean per feature ({', '.join(LIKERT_FEATURES)})")
    return np.array([likert_means[e] for e in GAIT_EMOTIONS], float)


# ---- the built-in models ------------------------------------------------------------------------------------------
def gait_emotions(rng, sec, shown: Shown, clips, m, effects) -> list[np.ndarray]:
    """emotion_choice and emotion_transition: the first question from the intended vector, a second from final_*."""
    cols = (GAIT_EMOTIONS, FINAL_EMOTION_COLUMNS)[:len(sec.questions)]
    return [gait_answers(rng, intended_vectors(clips, c)[shown.clip], m) for c in cols]


def affect_likert(rng, sec, shown: Shown, clips, m, effects) -> list[np.ndarray]:
    """Each feature 0..4: round(intended @ likert_means + participant bias + N(0, likert_sd)), clipped."""
    means = likert_mean_matrix(m.likert_means)  # (emotions, features)
    mu = intended_vectors(clips, GAIT_EMOTIONS)[shown.clip] @ means + effects["likert"][shown.p][:, None]
    lik = np.clip(np.rint(mu + rng.normal(0, m.likert_sd, mu.shape)), 0, 4).astype(int)
    return [lik[:, LIKERT_FEATURES.index(q)] for q in sec.questions]


def naturalness(rng, sec, shown: Shown, clips, m, effects) -> list[np.ndarray]:
    """1..5 drawn from the shares of ``naturalness_probs`` for the clip's (modality, origin)."""
    n = len(shown.clip)
    keys = list(zip(clips["modality"].to_numpy()[shown.clip], clips["origin"].to_numpy()[shown.clip], strict=True))
    probs = np.array([m.naturalness_probs[k] for k in keys], float).reshape(n, -1)
    return [categorical(rng, probs) + 1]


def gesture_emotion(rng, sec, shown: Shown, clips, m, effects) -> list[np.ndarray]:
    """One of the offered categories, the nearer in NRC-VAD to the intended one the likelier (gesture_temperature)."""
    n = len(shown.clip)
    vad = np.array([GESTURE_VAD[c] for c in shown.labels])
    intended = clips["emotion_label"].fillna("").astype(str).to_numpy()[shown.clip]
    want = np.array([shown.labels.index(c or "neutral") for c in intended], dtype=int)
    w = np.exp(-np.linalg.norm(vad[shown.options] - vad[want][:, None, :], axis=2) / m.gesture_temperature)
    pick = shown.options[np.arange(n), categorical(rng, w / w.sum(axis=1, keepdims=True))]
    return [np.asarray(shown.labels, dtype=object)[pick]]


def neutral_validation(rng, sec, shown: Shown, clips, m, effects) -> list[np.ndarray]:
    """One of the seven choices with the shares of ``neutral_probs``; ValueError when they do not match the choices."""
    if len(m.neutral_probs) != len(NEUTRAL_CHOICES):
        raise ValueError(f"neutral_probs: give one share per choice ({', '.join(NEUTRAL_CHOICES)})")
    nv = categorical(rng, np.tile(np.asarray(m.neutral_probs, float), (len(shown.clip), 1)))
    return [np.asarray(NEUTRAL_CHOICES, dtype=object)[nv]]


def _themes(clips, shown: Shown) -> np.ndarray:
    return clips["theme"].fillna("").astype(str).to_numpy()[shown.clip]


def theme_rating(rng, sec, shown: Shown, clips, m, effects) -> list[np.ndarray]:
    """1..7 rising with the clip's weight and feature count, with participant and answer noise (module docstring of
    analysis.simulate)."""
    n, theme = len(shown.clip), _themes(clips, shown)
    wt, nf = clips["weight"].to_numpy(float)[shown.clip], clips["n_features"].to_numpy(float)[shown.clip]
    features = (1 - np.exp(-(nf - 1) / 3)) / (1 - np.exp(-3))
    mean = (m.theme_base + np.array([m.theme_offsets.get(x, 0.0) for x in theme])
            + m.weight_effect * (wt - 0.4) / 0.9 + m.feature_effect * features)
    lat = mean + effects["theme"][shown.p] + rng.normal(0, m.theme_noise_sd, n)
    return [np.clip(np.rint(lat), 1, 7).astype(int)]


def theme_inversion(rng, sec, shown: Shown, clips, m, effects) -> list[np.ndarray]:
    """-7..7 around the theme's ``inversion_mean`` with noise ``inversion_sd``."""
    theme = _themes(clips, shown)
    mean = np.array([m.inversion_mean[x] for x in theme])
    return [np.clip(np.rint(mean + rng.normal(0, m.inversion_sd, len(shown.clip))), -7, 7).astype(int)]


_MODELS: dict[str, AnswerModel] = {}


def register_answer_model(section_type: str, model: AnswerModel) -> AnswerModel:
    """The simulator answers sections of ``section_type`` with ``model``; returns it."""
    _MODELS[section_type] = model
    return model


def unregister_answer_model(section_type: str) -> None:
    """Remove a model (tests that register toy section types clean up with this)."""
    _MODELS.pop(section_type, None)


def answer_model(section_type: str) -> AnswerModel:
    """The model of ``section_type``; LookupError naming the type and the ones that have a model."""
    try:
        return _MODELS[section_type]
    except KeyError:
        raise LookupError(f"no answer model for section type {section_type!r} (analysis.answer_models has: "
                          f"{', '.join(_MODELS)})") from None


def has_answer_model(section_type: str) -> bool:
    """Whether the simulator can answer sections of ``section_type``."""
    return section_type in _MODELS


for _name, _model in (("emotion_choice", gait_emotions), ("emotion_transition", gait_emotions),
                      ("affect_likert", affect_likert), ("naturalness", naturalness),
                      ("gesture_emotion", gesture_emotion), ("neutral_validation", neutral_validation),
                      ("theme_rating", theme_rating), ("theme_inversion", theme_inversion)):
    register_answer_model(_name, _model)
