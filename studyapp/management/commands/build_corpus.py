"""``manage.py build_corpus``: build the SYNTHETIC procedural training corpora (thin wrapper over
``generation.procedural.corpus``)."""
from __future__ import annotations

from django.core.management.base import BaseCommand, CommandError

from generation.procedural.corpus import DEFAULT_DIR, build_and_save


class Command(BaseCommand):
    """``manage.py build_corpus``: the synthetic gait corpus (and with --gestures the demo gesture corpus) on disk."""

    help = ("Build the synthetic (procedural, simulated-annotator) gait training corpus "
            "var/corpus/gait_corpus_synthetic.npz; the same as `python -m generation.procedural.corpus`.")

    def add_arguments(self, parser):
        """The options of ``python -m generation.procedural.corpus``: --out, --seed, --num sequences, --frames per
        sequence (30 fps) and --gestures."""
        parser.add_argument("--out", default=str(DEFAULT_DIR), help="output folder (default var/corpus)")
        parser.add_argument("--seed", type=int, default=0)
        parser.add_argument("--num", type=int, default=1000, help="gait sequences (default 1000)")
        parser.add_argument("--frames", type=int, default=240, help="frames per gait sequence at 30 fps")
        parser.add_argument("--gestures", action="store_true", help="also build the 88-sequence demo gesture corpus")

    def handle(self, *args, **options):
        """Build and save the corpora, echoing progress to stdout; invalid sizes end the command with an error."""
        try:
            build_and_save(options["out"], options["seed"], options["num"], options["frames"], options["gestures"],
                           echo=self.stdout.write)
        except ValueError as exc:
            raise CommandError(str(exc)) from None
