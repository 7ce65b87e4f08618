"""The one vocabulary of data splits: every corpus (procedural, gesture, real capture) and the networks' sentence
choice name their parts with these."""
from __future__ import annotations

#: Training, validation and held-out test parts, in that order.
SPLITS = ("train", "val", "test")
