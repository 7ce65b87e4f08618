"""Build a study's analysis-report zip into REPORTS_DIR/<study id>/<data version>/ (studyapp.staff.reports).

The staff "Build report" button runs this as a detached process with --data-version and --lock-fd (the lock it took
for the version). Run by hand it computes the current data version and takes the lock itself:

    manage.py build_report 3            # study id (or slug)
"""
from __future__ import annotations

import os

from django.core.management.base import BaseCommand, CommandError

from studyapp.models import Study
from studyapp.staff import reports


def find_study(ref: str) -> Study:
    """The study whose id (all digits) or slug is ``ref``; CommandError when there is none."""
    study = (Study.objects.filter(pk=int(ref)).first() if ref.isdigit() else None) or \
        Study.objects.filter(slug=ref).first()
    if study is None:
        raise CommandError(f"no study with id or slug {ref!r}")
    return study


class Command(BaseCommand):
    """``manage.py build_report STUDY``: the analysis-report zip of a study's current data, as the staff "Build report"
    button starts it."""

    help = "Build STUDY's analysis report zip for its current data (kept in REPORTS_DIR until the data change)."

    def add_arguments(self, parser):
        """STUDY (id or slug), --data-version and --lock-fd (passed by the staff page's detached run) and --force."""
        parser.add_argument("study", help="study id or slug")
        parser.add_argument("--data-version", default="", help="data version to build (default: the current one)")
        parser.add_argument("--lock-fd", type=int, default=-1,
                            help="open fd of the version's build.lock, already flock()ed by the caller")
        parser.add_argument("--force", action="store_true", help="rebuild even when the zip exists")

    def handle(self, *args, study, data_version, lock_fd, force, **options):
        """Build the zip for the data version unless it already exists (or --force), holding the version's build lock,
        taken here when no --lock-fd was passed and closed at the end; a failed build reports the error the build left
        behind."""
        obj = find_study(study)
        version = data_version or reports.data_version(obj)
        folder = reports.version_dir(obj.pk, version)
        if (folder / reports.REPORT_NAME).exists() and not force:
            self.stdout.write(f"Report for data version {version} already built: {folder / reports.REPORT_NAME}")
            return
        if lock_fd < 0:
            try:
                lock_fd = reports.acquire_lock(folder)
            except reports.BuildRunning as exc:
                raise CommandError(str(exc)) from exc
        try:
            path = reports.build_report(obj, version, lock_fd)
        except Exception as exc:
            error = folder / reports.ERROR_NAME
            raise CommandError(f"report build failed: {error.read_text().strip() if error.exists() else exc}") from exc
        finally:
            os.close(lock_fd)
        self.stdout.write(self.style.SUCCESS(f"Report written to {path}"))
