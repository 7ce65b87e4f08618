"""``manage.py train_gait``: train the seed 000 gait network (thin wrapper over generation.gait.train)."""
from __future__ import annotations

from django.core.management.base import BaseCommand

from generation.gait.train import build_parser, run
from studyapp.management.cli import mirror_arguments, mirrored_namespace


class Command(BaseCommand):
    help = ("Train the seed 000 emotive gait network on the synthetic gait corpus; the same options as "
            "`python -m generation.gait.train`.")

    def add_arguments(self, parser):
        mirror_arguments(parser, build_parser())

    def handle(self, *args, **options):
        ns = mirrored_namespace(build_parser(), options)
        if ns.set is None:
            ns.set = []
        run(ns, log=lambda msg: self.stdout.write(msg))
