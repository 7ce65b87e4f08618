"""``manage.py train_gesture``: train the Text2Gestures network (thin wrapper over generation.gesture.train).

Same options as ``python -m generation.gesture.train``, including ``--config small|paper``,
``--device auto|cpu|cuda[:N]``, ``--amp`` and ``--var-dir`` (default ``$GESTURE_VAR_DIR``, else var/gesture);
``--soft-labels`` reads the rated clips' motions from ``--motions``, else this app's ``MEDIA_ROOT/motions``.
"""
from __future__ import annotations

from pathlib import Path

from django.conf import settings
from django.core.management.base import BaseCommand, CommandError

from generation.gesture.train import build_parser, config_from_args, soft_label_data, train
from generation.mocap.gesture_corpus import load_gesture_corpus
from studyapp.management.cli import mirror_arguments, mirrored_namespace


class Command(BaseCommand):
    """``manage.py train_gesture``: train the seed 003 gesture network with the options of ``python -m
    generation.gesture.train``."""

    help = ("Train the seed 003 gesture network on the synthetic sentence/procedural-gesture corpus; "
            "the same options as `python -m generation.gesture.train` (--config small|paper, "
            "--device auto|cpu|cuda[:N], --amp).")

    def add_arguments(self, parser):
        """The library parser's options, mirrored, plus --corpus (an imported gesture corpus to train on)."""
        mirror_arguments(parser, build_parser())
        parser.add_argument("--corpus", help="train on an imported gesture corpus (python -m generation.mocap corpus "
                                             "--skeleton gesture) instead of the synthetic one")

    def handle(self, *args, **options):
        """Train on the synthetic corpus, the rated clips' soft labels (--soft-labels, motions from MEDIA_ROOT/motions
        by default) or an imported corpus (--corpus; not with --soft-labels), and print epochs, seconds, device, best
        selection score and where the weights went."""
        ns = mirrored_namespace(build_parser(), options)
        if ns.motions is None:
            ns.motions = Path(settings.MEDIA_ROOT) / "motions"
        try:
            cfg = config_from_args(ns)
        except ValueError as exc:  # unknown preset, unavailable device
            raise CommandError(str(exc)) from exc
        data = provenance = None
        if ns.soft_labels:
            if options.get("corpus"):
                raise CommandError("--soft-labels and --corpus: choose one training set")
            try:
                data, provenance = soft_label_data(cfg, ns, log=self.stdout.write)
            except ValueError as exc:
                raise CommandError(str(exc)) from exc
        elif options.get("corpus"):

            try:
                data = load_gesture_corpus(options["corpus"], seed=cfg.seed, cache_dir=ns.var_dir)
            except ValueError as exc:
                raise CommandError(str(exc)) from exc
        summary = train(cfg, data=data, progress=not ns.quiet, provenance=provenance, cache_dir=ns.var_dir)
        self.stdout.write(f"trained {summary['epochs_run']} epochs in {summary['seconds']:.0f} s on "
                          f"{summary['device']}; best selection score {summary['best_val']:.5f}; "
                          f"weights -> {summary['out']}")
