"""``manage.py train_gesture``: train the Text2Gestures network (thin wrapper over generation.gesture.train)."""
from __future__ import annotations

from django.core.management.base import BaseCommand

from generation.gesture.train import build_parser, config_from_args, train
from studyapp.management.cli import mirror_arguments, mirrored_namespace


class Command(BaseCommand):
    help = ("Train the seed 003 gesture network on the synthetic sentence/procedural-gesture corpus; "
            "the same options as `python -m generation.gesture.train`.")

    def add_arguments(self, parser):
        mirror_arguments(parser, build_parser())

    def handle(self, *args, **options):
        ns = mirrored_namespace(build_parser(), options)
        summary = train(config_from_args(ns), progress=not ns.quiet)
        self.stdout.write(f"trained {summary['epochs_run']} epochs in {summary['seconds']:.0f} s; best val loss "
                          f"{summary['best_val']:.5f}; weights -> {summary['out']}")
