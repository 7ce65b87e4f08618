"""Import a researcher's own videos and motion files into the clip catalogue (origin ``imported``).

    python manage.py import_clips MANIFEST.csv [--dry-run] [--report PATH] [--keep-audio] [--webm]
                                  [--max-duration S] [--max-size-mb MB] [--name NAME] [--remove-after DIR]

Thin wrapper over :mod:`generation.imports`: every manifest row is checked, its file probed (videos) or imported and
rendered (BVH), and committed all-or-nothing with its Clip row; the report ``import_report.csv`` (row, path,
status, clip_id, message) goes beside the manifest unless ``--report`` says elsewhere. ``--dry-run`` checks every
row and writes nothing (the report is printed, and written only where ``--report`` names a file). The manifest
format is in docs/study.md ("Bring your own stimuli").
"""
from __future__ import annotations

import contextlib
import shutil
from pathlib import Path

from django.conf import settings
from django.core.management.base import BaseCommand, CommandError
from django.db import DatabaseError, transaction

from generation.imports import ImportSettings, ManifestError, import_manifest, write_report
from generation.imports.run import REPORT_NAME, RowRefused
from generation.imports.video import VideoLimits
from generation.render.offscreen import prepare_render_process
from generation.render.settings import RenderSettings, RenderSettingsError
from studyapp.data.catalogue import retire_replaced, upsert_clips
from studyapp.data.clip_import import UploadError, collection_plan
from studyapp.models import Clip

from .generate_clips import _require_migrated_database


def plan_name(manifest: Path, name: str | None = None) -> str:
    """The collection of a manifest's clips, their catalogue ``plan``: ``import:<name>``, by default
    ``import:<folder>/<stem>`` (the admin passes ``upload/<user>/<collection>``)."""
    try:
        return collection_plan(name or f"{manifest.resolve().parent.name}/{manifest.stem}")
    except UploadError as exc:
        raise CommandError(f"{exc} (--name)") from None


def refuse_other_collections(record: dict) -> None:
    """RowRefused when the row's clip (the same file with the same settings) belongs to another collection: a
    clip has one collection, whose manifest alone relabels or retires it."""
    owner = Clip.objects.filter(clip_id=record["clip_id"]).values_list("plan", flat=True).first()
    if owner is not None and owner != record["plan"]:
        raise RowRefused(f"the same file is already clip {record['clip_id']} of the collection {owner!r}; a clip "
                         "belongs to one collection (select that clip in a pool by its id, or import the file "
                         "from that collection)")


@contextlib.contextmanager
def catalogue_step(record: dict, notes: list):
    """The Clip row of one imported clip, in one transaction with its files (generation.imports.run.commit_row);
    the older clip of the same collection and manifest path is retired when the file changed."""
    with transaction.atomic():
        refuse_other_collections(record)
        upsert_clips([record])
        retired = retire_replaced(record["plan"], record["metadata"]["entry_id"], record["clip_id"])
        if retired:
            notes.append(f"the file changed: retired {', '.join(retired)} (kept for earlier answers)")
        yield


def _collection_check():
    """refuse_other_collections when the catalogue can be read (a dry run may run before ``migrate``), else None."""
    try:
        Clip.objects.exists()
    except DatabaseError:
        return None
    return refuse_other_collections


def _render_size(text: str | None) -> dict:
    if not text:
        return {}
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise CommandError(f"--render-size: expected WIDTHxHEIGHT, e.g. 1280x720, got {text!r}") from None
    return {"width": w, "height": h}


class Command(BaseCommand):
    """``manage.py import_clips MANIFEST.csv``: a researcher's own videos and motion files into the catalogue, with a
    per-row report."""

    help = "Import videos and motion files named in a manifest CSV as clips with origin 'imported'."

    def add_arguments(self, parser):
        """The manifest, --dry-run and --report, the video limits (seconds, MiB), audio and WebM delivery, the
        collection name, the render size and observer of motion files, ffmpeg threads and the upload folder to remove
        afterwards."""
        parser.add_argument("manifest", help="the manifest CSV (paths in it are relative to its folder)")
        parser.add_argument("--dry-run", action="store_true", help="check every row, write nothing")
        parser.add_argument("--report", default=None, help=f"where the report goes (default: {REPORT_NAME} beside "
                                                           "the manifest)")
        parser.add_argument("--keep-audio", action="store_true",
                            help="keep videos' sound (default: stripped; the manifest's keep_audio column wins)")
        parser.add_argument("--webm", action="store_true", help="also deliver VP9 WebM files")
        parser.add_argument("--max-duration", type=float, default=VideoLimits.max_duration_s, metavar="S",
                            help=f"longest file accepted, seconds (default {VideoLimits.max_duration_s:g})")
        parser.add_argument("--max-size-mb", type=float, default=VideoLimits.max_bytes / 2**20, metavar="MB",
                            help=f"largest file accepted, MiB (default {VideoLimits.max_bytes / 2**20:g})")
        parser.add_argument("--name", default=None,
                            help="the collection of these clips, their catalogue plan import:<name> (default: "
                                 "import:<folder>/<manifest stem>); a changed file retires only the older clip of "
                                 "the same collection and path")
        parser.add_argument("--render-size", default=None, metavar="WxH",
                            help="frame size of rendered motion files (default 1280x720, as generated clips)")
        parser.add_argument("--no-observer", action="store_true",
                            help="no observer reading in the quality record of motion files")
        parser.add_argument("--threads", type=int, default=0, help="ffmpeg threads per encode (0: ffmpeg decides)")
        parser.add_argument("--remove-after", default=None, metavar="DIR",
                            help="a folder holding the manifest (an upload) to remove when the command ends, "
                                 "whether it imported, failed or was a dry run")

    def handle(self, *args, **opts):
        """Run the import; the --remove-after folder (which must hold the manifest) is removed whatever the outcome."""
        folder = Path(opts["remove_after"]).resolve() if opts.get("remove_after") else None
        if folder is not None and not Path(opts["manifest"]).resolve().is_relative_to(folder):
            raise CommandError(f"--remove-after {folder}: the manifest is not inside it")
        try:
            self._import(opts)
        finally:
            if folder is not None:
                shutil.rmtree(folder, ignore_errors=True)

    def _import(self, opts):
        manifest = Path(opts["manifest"])
        if not manifest.is_file():
            raise CommandError(f"{manifest}: no such manifest")
        if opts["max_duration"] <= 0 or opts["max_size_mb"] <= 0:
            raise CommandError("--max-duration and --max-size-mb must be positive")
        try:
            render = RenderSettings.from_dict(_render_size(opts["render_size"]))
        except RenderSettingsError as exc:
            raise CommandError(f"--render-size: {exc}") from None
        if not opts["dry_run"]:
            _require_migrated_database()
        prepare_render_process()
        config = ImportSettings(limits=VideoLimits(opts["max_duration"], int(opts["max_size_mb"] * 2**20)),
                                keep_audio=opts["keep_audio"], webm=opts["webm"], render=render,
                                observer=not opts["no_observer"], threads=opts["threads"],
                                plan=plan_name(manifest, opts["name"]))

        def show(out):
            where = f"{out.path}: " if out.status == "ok" else ""
            self.stdout.write(f"row {out.row} {out.status:5s} {out.clip_id or '-':16s} {where}{out.message}")

        try:
            outcomes = import_manifest(manifest, Path(settings.MEDIA_ROOT), config, catalogue_step,
                                       dry_run=opts["dry_run"], on_row=show, check=_collection_check())
        except ManifestError as exc:
            raise CommandError(str(exc)) from None
        report = Path(opts["report"]) if opts["report"] else manifest.parent / REPORT_NAME
        written = not opts["dry_run"] or bool(opts["report"])
        if written:
            write_report(outcomes, report)
        ok = sum(o.status == "ok" for o in outcomes)
        self.stdout.write(summary_line(ok, len(outcomes), config.plan, report if written else None,
                                       opts["dry_run"]))
        if ok < len(outcomes):
            raise CommandError(failure_line(len(outcomes) - ok, ok, report if written else None, opts["dry_run"]))


def summary_line(ok: int, rows: int, plan: str, report: Path | None, dry_run: bool) -> str:
    """The command's last line: how many rows were imported (a dry run: checked and would import), the
    collection, and where the report is (a dry run without --report writes none)."""
    where = f"report {report}" if report else "no report written (the rows are above; --report PATH writes one)"
    if dry_run:
        return f"dry run: {ok} of {rows} row(s) checked and would import, nothing written; collection {plan}; {where}"
    return f"{ok} of {rows} row(s) imported; collection {plan}; {where}"


def failure_line(failed: int, ok: int, report: Path | None, dry_run: bool) -> str:
    """The command's error when rows failed: how many, where their causes are, what happened to the others."""
    where = f"see the report {report}" if report else "see the rows above"
    if dry_run:
        return f"{failed} row(s) failed the check ({where}); dry run: nothing was imported"
    return f"{failed} row(s) failed ({where}); " + (f"the other {ok} are imported" if ok else "nothing was imported")
