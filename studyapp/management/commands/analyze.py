"""Export a study's CSVs and write the analysis report (analysis.report.write_report) into --out."""
from django.core.management.base import BaseCommand, CommandError

from studyapp.data.export import run_report
from studyapp.management.cli import study_by_slug


class Command(BaseCommand):
    """``manage.py analyze STUDY --out DIR``: the study's CSV exports and the papers' statistics (report.json, tables,
    figures, report.html) in one folder."""

    help = "Run the statistics of the papers on STUDY (slug): report.json, tables, figures, report.html in --out."

    def add_arguments(self, parser):
        """STUDY (slug) and the required --out folder."""
        parser.add_argument("study", help="study slug")
        parser.add_argument("--out", required=True, help="output folder (created if missing)")

    def handle(self, *args, study, out, **options):
        """Write the exports and the report into --out and list what the report holds; a missing analysis library or
        exports that do not validate end the command with an error naming the CSV folder."""
        obj = study_by_slug(study)
        try:
            result = run_report(obj, out)
        except ImportError as exc:
            raise CommandError(f"the analysis library is not available ({exc}); the CSVs are in {out}/data") from exc
        except ValueError as exc:          # analysis.io.ValidationError lists file, line and column
            raise CommandError(f"the exports of {study!r} did not validate (CSVs in {out}/data):\n{exc}") from exc
        self.stdout.write(self.style.SUCCESS(f"Report written to {out} (open {out}/report.html)"))
        if isinstance(result, dict):
            for key, value in result.items():
                size = f"{len(value)} records" if isinstance(value, list) else type(value).__name__
                self.stdout.write(f"  {key}: {size}")
