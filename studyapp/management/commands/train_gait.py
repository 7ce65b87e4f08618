"""``manage.py train_gait``: train the seed 000 gait network (thin wrapper over generation.gait.train).

    python manage.py train_gait [--config small|paper] [--device auto|cpu|cuda[:N]] [--amp] [--resume] ...
"""
from __future__ import annotations

from django.conf import settings
from django.core.management.base import BaseCommand, CommandError

from generation.gait.train import build_parser, run, with_edge_paths
from generation.mocap.real_corpus import RealCorpora
from studyapp.management.cli import mirror_arguments, mirrored_namespace


class Command(BaseCommand):
    """``manage.py train_gait``: train the seed 000 gait network with the options of ``python -m
    generation.gait.train``."""

    help = ("Train the seed 000 emotive gait network on the synthetic gait corpus; the same options as "
            "`python -m generation.gait.train` (--config small|paper, --device auto|cpu|cuda[:N], --amp).")

    def add_arguments(self, parser):
        """The options of the library's own parser, mirrored."""
        mirror_arguments(parser, build_parser())

    def handle(self, *args, **options):
        """Train with the mirrored options, the edge paths taken from the settings' REAL_CORPUS and MEDIA_ROOT; bad
        options rejected by the library end the command with an error."""
        ns = mirrored_namespace(build_parser(), options)
        if ns.set is None:
            ns.set = []
        with_edge_paths(ns, RealCorpora.of(settings.REAL_CORPUS).bandai, settings.MEDIA_ROOT)
        try:
            run(ns, log=lambda msg: self.stdout.write(msg))
        except SystemExit as exc:   # the library reports bad options (--device, --config, --set) this way
            raise CommandError(str(exc)) from None
