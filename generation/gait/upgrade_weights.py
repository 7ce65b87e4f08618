"""Rewrite gait network weights of format ``gait_net/2`` as the current format, with their typed training record.

    python -m generation.gait.upgrade_weights FILE [FILE ...]

A ``gait_net/2`` file says what it was trained on only in the prose of ``trained_on``; the one reader of that prose
(:func:`generation.gait.weights.training_data_of`) turns it into a :class:`~generation.gait.weights.TrainingData`
here, and the file is written again by the training command's own writer, so it carries the record from then on.
The weights, the normaliser, the configuration and every other field (history, ``initialised_from``, parameter
count) are kept: the network computes exactly what it did. A file already in the current format is left alone.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .config import GaitNetConfig
from .train import CHECKPOINT_FORMAT, load_checkpoint, save_checkpoint
from .weights import training_data_of

#: Fields :func:`save_checkpoint` writes itself; every other field of the old payload is passed through.
_WRITTEN_BY_SAVE = ("format", "config", "normalizer", "model", "training_data", "trained_on", "corpus")


def upgrade_weights(path: str | Path) -> bool:
    """Rewrite ``path`` in :data:`CHECKPOINT_FORMAT` with its typed training record; returns whether it changed
    (False: already current). ValueError for a file that is not a readable gait network checkpoint."""
    model, norm, payload = load_checkpoint(path)
    if payload.get("format") == CHECKPOINT_FORMAT:
        return False
    extra = {key: value for key, value in payload.items() if key not in _WRITTEN_BY_SAVE}
    save_checkpoint(Path(path), model, norm, GaitNetConfig.from_dict(payload["config"]),
                    training_data=training_data_of(payload), **extra)
    return True


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m generation.gait.upgrade_weights",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("files", nargs="+", type=Path, help="gait network weights files (.pt)")
    args = parser.parse_args(argv)
    status = 0
    for path in args.files:
        try:
            changed = upgrade_weights(path)
        except (ValueError, FileNotFoundError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            status = 2
            continue
        print(f"{path}: {'rewritten as ' + CHECKPOINT_FORMAT if changed else 'already ' + CHECKPOINT_FORMAT}")
    return status


if __name__ == "__main__":
    raise SystemExit(main())
