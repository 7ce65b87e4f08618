"""Render a stimulus plan into clips, write <MEDIA_ROOT>/clips.csv and the Clip rows.

    python manage.py generate_clips --plan demo [--workers 2] [--webm] [--limit K] [--contact-sheet [PNG]]
                                   [--scheduler tcp://HOST:PORT]

Thin wrapper over :mod:`generation.pipeline.runner`: the plan is validated before anything renders, clips whose
files are complete are skipped (resumable), files are written under temporary names and renamed. Every clip gets
a quality record (generation.quality; the real gait observers are trained on the corpora of the settings
REAL_CORPUS and BML_CORPUS); the command ends with a summary of clips per flag. With ``--scheduler``
the clips render on a Dask distributed cluster whose workers share this media folder.
"""
from __future__ import annotations

import json
import os
import time
from pathlib import Path

from django.conf import settings
from django.core.management.base import BaseCommand, CommandError
from django.db import DEFAULT_DB_ALIAS, connections
from django.db.migrations.executor import MigrationExecutor
from tqdm import tqdm

from generation.core.device import resolve_device
from generation.mocap.real_corpus import RealCorpora
from generation.pipeline.plan_qa import summary_line, unread_line
from generation.pipeline.runner import run_plan
from generation.plans.catalogue import write_clips_csv
from generation.plans.planned import planned_clip_rows
from generation.plans.schema import PlanError, load_plan
from generation.quality.checks import QAThresholdError, gait_observer_kind
from generation.render import contact_sheet, prepare_render_process
from protocol.coverage import coverage_lines, presets_of_plan
from protocol.titles import clip_titles
from studyapp.data.catalogue import clip_label, retire_superseded, upsert_clips


def _require_migrated_database() -> None:
    """CommandError before anything renders when the database lacks migrations (the Clip rows are written after
    the whole plan has rendered, which can take many minutes)."""
    connection = connections[DEFAULT_DB_ALIAS]
    executor = MigrationExecutor(connection)
    pending = executor.migration_plan(executor.loader.graph.leaf_nodes())
    if pending:
        raise CommandError(f"the database {connection.settings_dict['NAME']} has {len(pending)} unapplied "
                           "migration(s): run `python manage.py migrate` first, or pass --no-db to write only the "
                           "files and clips.csv")


class Command(BaseCommand):
    """``manage.py generate_clips --plan PLAN``: render a stimulus plan's clips, catalogue them in clips.csv and as Clip
    rows, and report their quality flags and the presets' coverage."""

    help = "Render the clips of a stimulus plan (built-in name or YAML/JSON file) and catalogue them."

    def add_arguments(self, parser):
        """The plan (built-in name or file) and the render options: workers or a Dask scheduler, WebM, a limit, the
        torch device of the network generators, a contact sheet, a progress file for the admin's render jobs, and
        --no-db."""
        parser.add_argument("--plan", required=True, help="built-in plan (demo, seed000, seed003, seed004) or a file")
        parser.add_argument("--workers", type=int, default=1, help="worker processes (default 1)")
        parser.add_argument("--webm", action="store_true", help="also write VP9 WebM files")
        parser.add_argument("--limit", type=int, default=None, help="only the first K entries of the plan")
        parser.add_argument("--contact-sheet", nargs="?", const="", default=None, metavar="PNG",
                            help="write a contact sheet of the plan's posters (default "
                                 "<DATA_DIR>/contact_sheets/<plan>.png)")
        parser.add_argument("--records-dir", default=None,
                            help="per-clip records (default <MEDIA_ROOT>/clip_records)")
        parser.add_argument("--no-db", action="store_true", help="do not write Clip rows (files and clips.csv only)")
        parser.add_argument("--no-progress", action="store_true", help="no progress bars")
        parser.add_argument("--device", default="cpu",
                            help="torch device of the network generators (gait_net, gesture_net): auto, cpu, cuda or "
                                 "cuda:N (default cpu: the same stimuli as on a machine without a GPU)")
        parser.add_argument("--progress-file", default=None, metavar="JSON",
                            help="keep the counts (total, to do, done, failed) in this JSON file while rendering, "
                                 "with finished: true at the end (the admin's render jobs read it)")
        parser.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                            help="render on a Dask distributed cluster (its workers must share MEDIA_ROOT) instead "
                                 "of local worker processes")

    def handle(self, *args, **opts):
        """Validate the options and the plan, render what is missing, write clips.csv and (unless --no-db) upsert the
        Clip rows and retire clips the plan no longer makes; then print the counts, the quality summary and each
        preset's coverage. Ends with CommandError when any clip failed, after cataloguing the others."""
        if opts["workers"] < 1:
            raise CommandError(f"--workers must be at least 1, got {opts['workers']}")
        if opts["limit"] is not None and opts["limit"] < 1:
            raise CommandError(f"--limit must be at least 1, got {opts['limit']}")
        try:
            plan = load_plan(opts["plan"])
        except PlanError as exc:
            raise CommandError(str(exc)) from None
        if not opts["no_db"]:
            _require_migrated_database()
        prepare_render_process()

        try:
            device = str(resolve_device(opts["device"]))
        except ValueError as exc:
            raise CommandError(f"--device: {exc}") from None
        try:
            gait_observer = gait_observer_kind(plan.qa, settings.QA_GAIT_OBSERVER)
        except QAThresholdError as exc:
            raise CommandError(f"QA_GAIT_OBSERVER: {exc}") from None
        media_root = Path(settings.MEDIA_ROOT)
        clips_dir = media_root / "clips"
        records_dir = Path(opts["records_dir"]) if opts["records_dir"] else media_root / "clip_records"
        bars = _Bars(self.stdout, disabled=opts["no_progress"])
        progress = ProgressFile(opts["progress_file"], self.stdout) if opts["progress_file"] else None

        def on_event(kind: str, info: dict) -> None:
            bars.event(kind, info)
            if progress is not None:
                progress.event(kind, info)

        try:
            result = run_plan(plan, clips_dir, records_dir, media_prefix="clips/", workers=opts["workers"],
                              webm=opts["webm"], limit=opts["limit"], on_event=on_event,
                              scheduler=opts["scheduler"], device=device, gait_observer=gait_observer,
                              corpora=RealCorpora.of(settings.REAL_CORPUS, settings.BML_CORPUS))
        except OSError as exc:  # e.g. no Dask scheduler at that address
            raise CommandError(f"cannot render: {exc}") from None
        finally:
            bars.close()
        for _where, msg in result.failed:
            self.stderr.write(f"FAILED {msg}")
        records = result.records
        titles = clip_titles(records)
        for rec in records:
            rec["title"] = titles[rec["clip_id"]]
        csv_path = media_root / "clips.csv"
        if records:
            write_clips_csv(records, csv_path)
        if records and not opts["no_db"]:
            upsert_clips(records)
            complete = opts["limit"] is None and not result.failed
            entries = None if complete else {str(r.get("metadata", {}).get("entry_id")) for r in records}
            retired = retire_superseded(plan.name, {r["clip_id"] for r in records}, entries)
            if retired:
                self.stdout.write(f"retired {retired} superseded clip(s) of plan {plan.name} (kept for earlier "
                                  "answers, left out of new assignments)")
        self.stdout.write(f"plan {plan.name}: {len(result.rendered)} rendered, {len(result.skipped)} already done, "
                          f"{len(result.failed)} failed, {result.seconds:.1f} s; catalogue {csv_path}")
        if records:
            self.stdout.write(f"plan {plan.name}: " + summary_line(r.get("qa_flag", "") for r in records))
            if unread := unread_line(records, gait_observer):
                self.stdout.write(f"plan {plan.name}: {unread}")
            flags = {str(r.get("metadata", {}).get("entry_id")): r.get("qa_flag", "") for r in records}
            rows = planned_clip_rows(plan)
            for preset in presets_of_plan(plan.name):
                for line in coverage_lines(preset, rows, flags, plan.name):
                    self.stdout.write(f"plan {plan.name}, preset {preset}: {line}")
        if opts["contact_sheet"] is not None and records:
            out = Path(opts["contact_sheet"]) if opts["contact_sheet"] else (
                Path(settings.DATA_DIR) / "contact_sheets" / f"{plan.name}.png")
            labels = [clip_label(r) for r in records]
            contact_sheet([clips_dir / f"{r['clip_id']}.png" for r in records], labels, out)
            self.stdout.write(f"contact sheet {out}")
        if progress is not None:
            progress.finish(len(result.rendered), len(result.skipped), len(result.failed),
                            sorted(r["clip_id"] for r in records))
        if result.failed:
            raise CommandError(f"{len(result.failed)} clip(s) of plan {plan.name} failed (see above); the others "
                               "are catalogued; rerun to retry only the missing ones")


class ProgressFile:
    """The render's counts in a JSON file, rewritten atomically on every event: ``total`` clips of the plan,
    ``todo`` (to render this run), ``skipped`` (already done), ``done`` and ``failed`` so far, and at the end
    ``finished: true`` with the clip ids catalogued. A line per finished clip goes to ``stream`` (the job's log)."""

    def __init__(self, path: str, stream):
        self.path = Path(path)
        self.stream = stream
        self.state = {"total": 0, "todo": 0, "skipped": 0, "done": 0, "failed": 0, "finished": False,
                      "started": time.time()}
        self.write()

    def write(self) -> None:
        """Replace the JSON file with the current state (through a temporary file and a rename, so a reader never sees
        half of it), stamping ``updated`` (Unix seconds)."""
        self.state["updated"] = time.time()
        tmp = self.path.with_name(f".{self.path.name}.tmp{os.getpid()}")
        tmp.write_text(json.dumps(self.state), encoding="utf-8")
        os.replace(tmp, self.path)

    def event(self, kind: str, info: dict) -> None:
        """Count a runner event: ``plan`` sets the totals, ``done`` and ``fail`` add one and log a line; other events
        are ignored."""
        if kind == "plan":
            self.state.update(total=info["total"], todo=info["todo"], skipped=info["skipped"])
        elif kind == "done":
            self.state["done"] += 1
            self.stream.write(f"rendered {info.get('entry', '')} ({self.state['done']} of {self.state['todo']})")
        elif kind == "fail":
            self.state["failed"] += 1
            self.stream.write(f"failed {info.get('entry', '')}: {info.get('error', '')}")
        else:
            return
        self.stream.flush()
        self.write()

    def finish(self, rendered: int, skipped: int, failed: int, clip_ids: list[str]) -> None:
        """Store the final counts and the catalogued clip ids and mark the render finished."""
        self.state.update(done=rendered, skipped=skipped, failed=failed, finished=True, clip_ids=clip_ids)
        self.write()


class _Bars:
    """tqdm bars: one for the plan, one per clip being rendered."""

    def __init__(self, stream, disabled: bool = False):
        self.disabled = disabled
        self.overall = None
        self.clips: dict[str, object] = {}
        self.positions: dict[str, int] = {}
        self.free_positions: list[int] = []
        self.next_position = 1

    def event(self, kind: str, info: dict) -> None:
        if self.disabled:
            return

        if kind == "plan":
            self.overall = tqdm(total=info["todo"], desc=f"clips ({info['skipped']} already done)", unit="clip",
                                position=0, leave=True)
        elif kind == "start":
            pos = self.free_positions.pop(0) if self.free_positions else self.next_position
            if pos == self.next_position:
                self.next_position += 1
            self.positions[info["clip_id"]] = pos
            self.clips[info["clip_id"]] = tqdm(total=1, desc=str(info["entry"])[:28], unit="frame", position=pos,
                                               leave=False)
        elif kind == "frames":
            bar = self.clips.get(info["clip_id"])
            if bar is None:
                self.event("start", info)
                bar = self.clips[info["clip_id"]]
            bar.total = info["total"]
            bar.n = info["done"]
            bar.refresh()
        elif kind in ("done", "fail"):
            bar = self.clips.pop(info.get("clip_id", ""), None)
            if bar is not None:
                self.free_positions.append(self.positions.pop(info["clip_id"]))
                bar.close()
            if self.overall is not None:
                self.overall.update(1)

    def close(self) -> None:
        for bar in self.clips.values():
            bar.close()
        if self.overall is not None:
            self.overall.close()
