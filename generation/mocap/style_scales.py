"""The style scales of the real Bandai Namco walks (Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0) on which
seed 004's themes are judged: each scale's classes and the corpus styles that make them, the datasets that hold
them, and where each theme sits on its scale. Read by the style observers of ``generation.quality`` and
``generation.rbf`` alike, so both judge a theme against the same real walks.
"""
from __future__ import annotations

#: scale -> {class: corpus styles}
SCALES: dict[str, dict[str, tuple[str, ...]]] = {
    "energy": {"energetic": ("active",), "normal": ("normal",), "tired": ("tired", "exhausted")},
    "gender": {"feminine": ("feminine",), "normal": ("normal",), "masculine": ("masculinity", "masculine")},
    "emotion": {"happy": ("happy",), "sad": ("sad",), "angry": ("angry",), "neutral": ("normal",)},
}
#: scale -> the corpus datasets whose walks it is trained on (dataset 2 has no emotion styles)
SCALE_DATASETS = {"energy": ("bandai-namco-1", "bandai-namco-2"), "gender": ("bandai-namco-1", "bandai-namco-2"),
                  "emotion": ("bandai-namco-1",)}
#: seed 004 theme -> (scale, class on that scale)
THEME_SCALE = {"happy": ("emotion", "happy"), "sad": ("emotion", "sad"), "energetic": ("energy", "energetic"),
               "tired": ("energy", "tired"), "feminine": ("gender", "feminine"), "masculine": ("gender", "masculine")}
#: scale -> its unstyled class
NEUTRAL_CLASS = {"energy": "normal", "gender": "normal", "emotion": "neutral"}
