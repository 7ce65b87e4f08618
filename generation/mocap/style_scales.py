"""The style scales of the real Bandai Namco walks (Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0) on which
seed 004's themes are judged: each scale's classes and the corpus styles that make them, the datasets that hold
them, and where each theme sits on its scale; which real walks belong to a scale (:func:`scale_clips`) and how a
scale's held-out readings add up per class (:func:`class_recall`). Read by the style observers of
``generation.quality`` and ``generation.rbf`` alike, so both judge a theme against the same real walks.

The emotion scale's classes are also those of the BML walks of Emotion-Gait (:mod:`generation.mocap.emotion_gait_bml`,
dataset ``emotion-gait-bml``, styles happy, sad, angry and neutral = the acted emotion; research use with citation),
whose clips carry a second label, the annotators' majority ``perceived_label`` (``labels="perceived"``).
"""
from __future__ import annotations

import numpy as np

#: scale -> {class: corpus styles}
SCALES: dict[str, dict[str, tuple[str, ...]]] = {
    "energy": {"energetic": ("active",), "normal": ("normal",), "tired": ("tired", "exhausted")},
    "gender": {"feminine": ("feminine",), "normal": ("normal",), "masculine": ("masculinity", "masculine")},
    "emotion": {"happy": ("happy",), "sad": ("sad",), "angry": ("angry",), "neutral": ("normal", "neutral")},
}
#: corpus styles of a walker's unstyled walk (Bandai Namco "normal", BML "neutral")
NEUTRAL_STYLES = ("normal", "neutral")
#: which label of a clip names its class: the corpus style (acted) or the BML annotators' majority (perceived)
LABELS = ("acted", "perceived")
#: scale -> the corpus datasets whose walks it is trained on (dataset 2 has no emotion styles)
SCALE_DATASETS = {"energy": ("bandai-namco-1", "bandai-namco-2"), "gender": ("bandai-namco-1", "bandai-namco-2"),
                  "emotion": ("bandai-namco-1",)}
#: seed 004 theme -> (scale, class on that scale)
THEME_SCALE = {"happy": ("emotion", "happy"), "sad": ("emotion", "sad"), "energetic": ("energy", "energetic"),
               "tired": ("energy", "tired"), "feminine": ("gender", "feminine"), "masculine": ("gender", "masculine")}
#: scale -> its unstyled class
NEUTRAL_CLASS = {"energy": "normal", "gender": "normal", "emotion": "neutral"}


def clip_style(clip, labels: str = "acted") -> str:
    """The style that names a clip's class: its corpus style (``acted``), or with ``labels="perceived"`` the
    ``perceived_label`` of its Motion's metadata where it has one (BML clips; others keep their acted style)."""
    if labels not in LABELS:
        raise ValueError(f"labels must be one of {list(LABELS)}, got {labels!r}")
    if labels == "perceived":
        return (getattr(clip.motion, "metadata", None) or {}).get("perceived_label", clip.style)
    return clip.style


def scale_clips(clips: list, scale: str, datasets: tuple[str, ...] | None = None, labels: str = "acted"
                ) -> list[tuple[object, str]]:
    """(clip, class) for the straight walks of ``clips`` in ``datasets`` (default :data:`SCALE_DATASETS`) that
    belong to one of ``scale``'s classes, by :func:`clip_style` of ``labels``."""
    if scale not in SCALES:
        raise ValueError(f"unknown style scale {scale!r}; expected one of {sorted(SCALES)}")
    style_class = {s: k for k, styles in SCALES[scale].items() for s in styles}
    if labels not in LABELS:
        raise ValueError(f"labels must be one of {list(LABELS)}, got {labels!r}")
    datasets = SCALE_DATASETS[scale] if datasets is None else datasets
    out = []
    for c in clips:
        style = clip_style(c, labels) if c.content == "walk" and c.dataset in datasets else None
        if style in style_class:
            out.append((c, style_class[style]))
    return out


def class_recall(rows: list[dict], classes) -> dict:
    """Per class of ``classes``, from readings ``rows`` ({"class", "top", "p": {class: probability}, ...}):
    {"recall": {class: share of its rows read as it, None without rows}, "takes": {class: n},
    "mean_p": {class: mean probability of the own class, None without rows}, "rows": rows}."""
    recall, takes, mean_p = {}, {}, {}
    for k in classes:
        mine = [r for r in rows if r["class"] == k]
        takes[k] = len(mine)
        recall[k] = (sum(r["top"] == k for r in mine) / len(mine)) if mine else None
        mean_p[k] = float(np.mean([r["p"][k] for r in mine])) if mine else None
    return {"recall": recall, "takes": takes, "mean_p": mean_p, "rows": rows}
