"""``manage.py train_gait``: train the seed 000 gait network (thin wrapper over generation.gait.train)."""
from __future__ import annotations

import argparse

from django.core.management.base import BaseCommand

from generation.gait.train import build_parser, run


class Command(BaseCommand):
    help = ("Train the seed 000 emotive gait network on the synthetic gait corpus; the same options as "
            "`python -m generation.gait.train`.")

    def add_arguments(self, parser):
        for action in build_parser()._actions:
            if action.dest == "help":
                continue
            kwargs = {"dest": action.dest, "default": action.default, "help": action.help}
            if action.const is True and action.nargs == 0:
                kwargs["action"] = "store_true"
            elif isinstance(action, argparse._AppendAction):
                kwargs["action"] = "append"
            else:
                kwargs["type"] = action.type
            parser.add_argument(*action.option_strings, **kwargs)

    def handle(self, *args, **options):
        names = {a.dest for a in build_parser()._actions if a.dest != "help"}
        ns = argparse.Namespace(**{k: v for k, v in options.items() if k in names})
        if ns.set is None:
            ns.set = []
        run(ns, log=lambda msg: self.stdout.write(msg))
