"""Named weights of the gait network: ``real`` (trained on real capture, the default) and ``procedural``.

- ``real``: ``gait_net_real.pt``, pretrained on the forward locomotion of the Bandai Namco Research Motion Dataset
  (datasets 1 and 2) and fine-tuned on dataset 1's happy, sad, angry and normal walks (Kobayashi et al. 2023,
  arXiv:2306.08861; licence CC BY-NC 4.0, which the weights, derived from the data, keep). Model card:
  docs/gait_real_model_card.md.
- ``procedural``: ``gait_net_default.pt``, trained on the SYNTHETIC procedural gait corpus
  (docs/benchmarks/gait.md).

Plans choose with the gait_net entry field ``weights: real | procedural``; clip metadata records the name.
"""
from __future__ import annotations

from pathlib import Path

WEIGHTS_DIR = Path(__file__).resolve().parent.parent / "data" / "weights"
NAMED_WEIGHTS = {"real": "gait_net_real.pt", "procedural": "gait_net_default.pt"}
"""Weights name -> file in :data:`WEIGHTS_DIR`."""
DEFAULT_WEIGHTS_NAME = "real"


def weights_path(name: str | None = None) -> Path:
    """The file of the named weights (None: :data:`DEFAULT_WEIGHTS_NAME`); ValueError for an unknown name."""
    name = DEFAULT_WEIGHTS_NAME if name is None else name
    if name not in NAMED_WEIGHTS:
        raise ValueError(f"unknown gait weights {name!r}: use one of {', '.join(NAMED_WEIGHTS)}")
    return WEIGHTS_DIR / NAMED_WEIGHTS[name]


def is_real(info: dict) -> bool:
    """Whether a weights file's record (``LoadedGaitNet.info``) says it was trained on real capture."""
    return str(info.get("trained_on", "")).startswith("real capture")
