"""Write a study's responses.csv, clips.csv and participants.csv (DESIGN.md formats) into a folder."""
from django.core.management.base import BaseCommand, CommandError

from studyapp.export import write_study_csvs
from studyapp.models import Study


class Command(BaseCommand):
    help = "Export responses.csv, clips.csv and participants.csv of STUDY (its slug) into --out."

    def add_arguments(self, parser):
        parser.add_argument("study", help="study slug")
        parser.add_argument("--out", required=True, help="output folder (created if missing)")

    def handle(self, *args, study, out, **options):
        obj = Study.objects.filter(slug=study).first()
        if obj is None:
            known = list(Study.objects.values_list("slug", flat=True))
            raise CommandError(f"no study with slug {study!r}; known: {known}")
        for kind, path in write_study_csvs(obj, out).items():
            self.stdout.write(f"{kind}: {path}")
