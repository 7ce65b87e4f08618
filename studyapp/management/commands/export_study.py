"""Write a study's responses.csv, clips.csv and participants.csv (DESIGN.md formats) into a folder."""
from django.core.management.base import BaseCommand

from studyapp.data.export import write_study_csvs
from studyapp.management.cli import study_by_slug


class Command(BaseCommand):
    """``manage.py export_study STUDY --out DIR``: responses.csv, clips.csv and participants.csv of one study."""

    help = "Export responses.csv, clips.csv and participants.csv of STUDY (its slug) into --out."

    def add_arguments(self, parser):
        """STUDY (slug) and the required --out folder."""
        parser.add_argument("study", help="study slug")
        parser.add_argument("--out", required=True, help="output folder (created if missing)")

    def handle(self, *args, study, out, **options):
        """Write the three CSVs into --out and print each one's path."""
        obj = study_by_slug(study)
        for kind, path in write_study_csvs(obj, out).items():
            self.stdout.write(f"{kind}: {path}")
