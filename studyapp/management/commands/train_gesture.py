"""``manage.py train_gesture``: train the Text2Gestures network (thin wrapper over generation.gesture.train)."""
from __future__ import annotations

from django.core.management.base import BaseCommand

from generation.gesture.train import build_parser, config_from_args, train


class Command(BaseCommand):
    help = ("Train the seed 003 gesture network on the synthetic sentence/procedural-gesture corpus; "
            "the same options as `python -m generation.gesture.train`.")

    def add_arguments(self, parser):
        for action in build_parser()._actions:
            if action.dest == "help":
                continue
            kwargs = {"dest": action.dest, "default": action.default, "help": action.help}
            if action.const is True and action.nargs == 0:
                kwargs["action"] = "store_true"
            else:
                kwargs["type"] = action.type
            parser.add_argument(*action.option_strings, **kwargs)

    def handle(self, *args, **options):
        import argparse

        names = {a.dest for a in build_parser()._actions if a.dest != "help"}
        ns = argparse.Namespace(**{k: v for k, v in options.items() if k in names})
        summary = train(config_from_args(ns), progress=not ns.quiet)
        self.stdout.write(f"trained {summary['epochs_run']} epochs in {summary['seconds']:.0f} s; best val loss "
                          f"{summary['best_val']:.5f}; weights -> {summary['out']}")
