"""Paths and defaults of the gesture network (seed 003)."""
from __future__ import annotations

import hashlib
from collections.abc import Mapping
from pathlib import Path

from protocol.vocabulary import GENDERS, HANDEDNESS  # noqa: F401 - the attribute one-hot orders
from protocol.vocabulary import GESTURE_TASKS as TASKS  # noqa: F401

PACKAGE_DIR = Path(__file__).resolve().parent
GENERATION_DIR = PACKAGE_DIR.parent
PROJECT_DIR = GENERATION_DIR.parent

SENTENCES_CSV = GENERATION_DIR / "data" / "sentences_synthetic.csv"
DEFAULT_WEIGHTS = GENERATION_DIR / "data" / "weights" / "gesture_net_default.pt"
# Caches and checkpoints live under var/ (git-ignored); a command line takes another folder from --var-dir or
# GESTURE_VAR_DIR (var_dir) and passes it down as ``cache_dir``.
DEFAULT_VAR_DIR = PROJECT_DIR / "var" / "gesture"
VAR_DIR_ENV_VAR = "GESTURE_VAR_DIR"


def var_dir(environ: Mapping[str, str] | None = None) -> Path:
    """The folder of the gesture caches and checkpoints: ``environ["GESTURE_VAR_DIR"]`` when ``environ`` is given
    and sets it, else :data:`DEFAULT_VAR_DIR` (``<repo>/var/gesture``). Only command lines pass an environment;
    library functions take the folder as an argument (``cache_dir``)."""
    value = (environ or {}).get(VAR_DIR_ENV_VAR)
    return Path(value) if value else DEFAULT_VAR_DIR


# The network runs at a low frame rate (the 2-core CPU budget) and output is resampled (slerp).
TRAIN_FPS = 10.0
# Gesture length follows the sentence: seconds per word, plus rest lead-in and lead-out.
SECONDS_PER_WORD = 0.4
LEAD_IN_S = 0.5
LEAD_OUT_S = 1.0
MAX_SECONDS = 12.0
MIN_SECONDS = 2.5


def gesture_seconds(n_words: int) -> float:
    """Duration in seconds of the gesture for a sentence of ``n_words`` words (rest lead-in/out included)."""
    if n_words < 1:
        raise ValueError(f"a sentence needs at least one word, got {n_words}")
    return float(min(MAX_SECONDS, max(MIN_SECONDS, LEAD_IN_S + SECONDS_PER_WORD * n_words + LEAD_OUT_S)))


def gesture_frames(n_words: int, fps: float = TRAIN_FPS) -> int:
    """Number of frames at ``fps`` of the gesture for a sentence of ``n_words`` words."""
    return int(round(gesture_seconds(n_words) * fps))


def generator_fingerprint() -> str:
    """Hash of the procedural gesture generator's source and the corpus code, so cached pairs (and the observer
    fitted on them) are rebuilt when it changes."""
    base = Path(__file__).resolve().parent.parent
    digest = hashlib.sha1()
    for name in ("procedural/gesture.py", "procedural/emotion.py", "gesture/data.py", "gesture/config.py"):
        f = base / name
        if f.is_file():
            digest.update(f.read_bytes())
    return digest.hexdigest()
