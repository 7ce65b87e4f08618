"""Render a whole stimulus plan: resolve generators, hash, skip what exists, render the rest in worker processes.

Resumable: a clip is done when its files (mp4, png, and webm when asked) exist under their final names and
its record ``<records_dir>/<clip_id>.json`` is there; the record is written last, after the files were
renamed into place. Clips already done are skipped, so running the same plan twice renders nothing the
second time, and a crash loses at most the clips in progress.

Records name the condition of a clip: the folder they live in must never be served to participants (the
command puts them in ``<MEDIA_ROOT>/clip_records``; the study app serves only catalogued clip files, by
opaque keys).
"""
from __future__ import annotations

import dataclasses
import json
import multiprocessing as mp
import os
import queue as queue_mod
import threading
import time
import traceback
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

from generation.mocap.real_corpus import DEFAULT_CORPORA, RealCorpora
from generation.plans.clipgen import make_motion, write_motion_bvh
from generation.plans.schema import ClipEntry, Plan, intent_fields
from generation.quality.checks import QAResult, failed_checks
from generation.render.clip import clip_files_complete, render_clip
from generation.render.offscreen import prepare_render_process

from .jobs import Job, plan_jobs
from .plan_qa import clip_qa, intended_emotion, observer_for

__all__ = ["BatchResult", "Job", "base_record", "plan_jobs", "render_job", "render_job_on_worker", "run_plan"]

#: Version of the stored clip records: 2, they carry the quality record ``qa`` and ``qa_flag``; 3, a gait clip's
#: ``qa`` carries the realism measures. A record of an older version than REMEASURED_FROM is rendered again.
RECORD_VERSION = 3
#: The oldest record version whose clip files are kept: its gait clips have their quality record measured again
#: (:func:`_stale_qa`), its other clips are complete.
REMEASURED_FROM = 2


@dataclass
class BatchResult:
    records: list[dict] = field(default_factory=list)
    rendered: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    failed: list[tuple[str, str]] = field(default_factory=list)   # (entry label, message)
    seconds: float = 0.0


def _json_safe(obj):
    try:
        return json.loads(json.dumps(obj, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o)))
    except (TypeError, ValueError):
        return str(obj)


def base_record(job: Job, plan: Plan, pair_ids: dict[str, str], media_prefix: str, webm: bool) -> dict:
    """The catalogue record of a job without the rendered facts (duration)."""
    e, r = job.entry, job.run_entry
    rec = {"clip_id": job.clip_id, "modality": e.modality, "origin": e.origin, **intent_fields(e),
           "duration_s": None, "video": f"{media_prefix}{job.clip_id}.mp4",
           "webm": f"{media_prefix}{job.clip_id}.webm" if webm else "", "poster": f"{media_prefix}{job.clip_id}.png",
           "plan": plan.name, "loop": e.loop, "source_clip_id": pair_ids.get(e.pair, "") if e.pair else ""}
    rec["metadata"] = {
        "entry_id": e.id, "plan": plan.name, "generator": r.generator, "requested_generator": e.generator,
        "generator_version": job.generator_version, "inputs": r.inputs.as_dict(), "seed": e.seed,
        "sections": list(e.sections), "render": e.render.content_dict(), "note": e.note,
        "pair": e.pair, "source_clip_id": rec["source_clip_id"],
    }
    if job.fallback_reason:
        rec["metadata"]["fallback_for"] = e.generator
        rec["metadata"]["fallback_reason"] = job.fallback_reason
    return rec


def _write_json_atomic(obj: dict, path: Path) -> None:
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    tmp.write_text(json.dumps(obj, indent=1, sort_keys=True), encoding="utf-8")
    os.replace(tmp, path)


def load_done_record(clip_id: str, clips_dir: Path, records_dir: Path, webm: bool) -> dict | None:
    """The stored record of a complete clip, or None when the clip must be (re)rendered."""
    rec_path = records_dir / f"{clip_id}.json"
    if not rec_path.is_file() or not clip_files_complete(clips_dir, clip_id, webm):
        return None
    try:
        rec = json.loads(rec_path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not REMEASURED_FROM <= rec.get("record_version", 0) <= RECORD_VERSION or rec.get("clip_id") != clip_id:
        return None
    return rec


# ---- worker side -------------------------------------------------------------------------------
_PROGRESS_QUEUE = None


def _exit_with_parent(parent_pid: int) -> None:
    """Stop this worker when the command that started it dies (no orphan renders after a crash)."""
    while True:
        time.sleep(1.0)
        if os.getppid() != parent_pid:
            os._exit(1)


def _init_worker(progress_queue, threads: int, parent_pid: int | None = None) -> None:
    """Set up a render worker (a spawned process, or a Dask worker once): its progress queue, its exit with the
    parent, the environment its C libraries read when they load (:func:`prepare_render_process`: headless GL,
    ``threads`` per worker) and torch's threads."""
    global _PROGRESS_QUEUE
    _PROGRESS_QUEUE = progress_queue
    if parent_pid is not None:
        threading.Thread(target=_exit_with_parent, args=(parent_pid,), daemon=True).start()
    prepare_render_process(threads)
    try:
        import torch  # heavy: loaded in render workers only, to cap their threads

        torch.set_num_threads(threads)
    except ImportError:  # pragma: no cover - torch is a project dependency
        pass


def render_job(job: Job, record: dict, clips_dir: str, records_dir: str) -> dict:
    """Make the motion, render its files, write the record last. Runs in a worker (or inline)."""
    t0 = time.perf_counter()
    motion = make_motion(job.run_entry, requested=job.entry.generator, fallback_reason=job.fallback_reason,
                         device=job.device)
    write_motion_bvh(motion, Path(clips_dir).parent / "motions", job.clip_id)
    t_gen = time.perf_counter() - t0
    q = _PROGRESS_QUEUE
    progress = None
    if q is not None:
        def progress(done, total):
            if done == total or done % 10 == 0:
                q.put((job.clip_id, job.entry.id, done, total))
    result = render_clip(motion, clips_dir, job.clip_id, job.run_entry.render, progress=progress)
    record = dict(record)
    record["duration_s"] = round(result.duration_s, 4)
    record["metadata"] = dict(record["metadata"])
    record["metadata"]["motion"] = _json_safe({k: v for k, v in motion.metadata.items() if k != "entry_id"})
    record["metadata"]["synthetic"] = bool(motion.metadata.get("synthetic", False))
    record["metadata"]["n_frames"] = result.n_frames
    record["metadata"]["fps"] = result.fps
    record["metadata"]["camera"] = _json_safe(result.camera)  # rule (fixed/follow), figure height fractions
    record["body"] = _json_safe(result.body)  # the human body shown, its licence and citation (None otherwise)
    t_qa = time.perf_counter()
    _add_qa(record, job, motion, result.camera)
    record["metadata"]["timing_s"] = {"generate": round(t_gen, 3), "qa": round(time.perf_counter() - t_qa, 3),
                                      "total": round(time.perf_counter() - t0, 3)}
    record["record_version"] = RECORD_VERSION
    _write_json_atomic(record, Path(records_dir) / f"{job.clip_id}.json")
    return record


def _add_qa(record: dict, job: Job, motion, camera: dict) -> None:
    """Measure the clip's quality (:mod:`generation.quality`) into ``record["qa"]`` and ``record["qa_flag"]``."""
    observer = observer_for(job.run_entry.modality, job.gait_observer, job.corpora)
    result, _ = clip_qa(motion, job.run_entry.render, job.qa_thresholds, intended_emotion(job.run_entry.inputs),
                        observer, camera_info=camera)
    record["qa"] = _json_safe(result.as_dict())
    record["qa_flag"] = result.flag


def _stale_qa(done: dict, job: Job) -> bool:
    """Whether a stored gait clip's quality record is measured again: its record is of a version before 3 (no
    realism measures) or it was read by another gait observer than the plan's (``qa: {observer: ...}``; real by
    default)."""
    if job.run_entry.modality != "gait":
        return False
    old = done.get("record_version", 0) < 3
    return old or (done.get("qa") or {}).get("observer") != job.gait_observer


def _remeasure_qa(done: dict, job: Job, batch: _Batch) -> None:
    """Make the clip's motion again (no video) and replace the stored record's quality record, on disk too; the
    render's camera (figure height) is kept. A motion that cannot be made keeps the old record and says why."""
    try:
        motion = make_motion(job.run_entry, requested=job.entry.generator, fallback_reason=job.fallback_reason,
                             device=job.device)
        _add_qa(done, job, motion, (done.get("metadata") or {}).get("camera"))
        done["record_version"] = RECORD_VERSION
    except Exception as exc:  # noqa: BLE001 - the clip's files are fine; only its quality record stays old
        batch.emit("warn", {"clip_id": job.clip_id, "entry": job.entry.id,
                            "message": f"quality record not re-measured ({type(exc).__name__}: {exc})"})
        return
    _write_json_atomic(done, batch.records_dir / f"{job.clip_id}.json")


def _recheck_qa(rec: dict, done: dict, job: Job) -> None:
    """A stored record's quality values, re-checked against the plan's current thresholds."""
    stored = QAResult.from_dict(done.get("qa") or {})
    flags = failed_checks(stored.values, job.qa_thresholds, intended_emotion(job.run_entry.inputs))
    rec["qa"] = QAResult(stored.values, flags).as_dict()
    rec["qa_flag"] = ";".join(flags)


# ---- orchestration -----------------------------------------------------------------------------
@dataclass
class _Batch:
    """The state of one :func:`run_plan` call: where files go, the records so far (clip id -> record, in plan
    order) and the outcome."""

    clips_dir: Path
    records_dir: Path
    emit: Callable[[str, dict], None]
    result: BatchResult
    by_id: dict[str, dict] = field(default_factory=dict)

    def job_args(self, job: Job) -> tuple:
        """The arguments of :func:`render_job` for ``job``."""
        return job, self.by_id[job.clip_id], str(self.clips_dir), str(self.records_dir)

    def finished(self, job: Job, rec: dict) -> None:
        self.by_id[job.clip_id] = rec
        self.result.rendered.append(job.clip_id)
        self.emit("done", {"clip_id": job.clip_id, "entry": job.entry.id, "duration_s": rec["duration_s"]})

    def failed(self, job: Job, exc: BaseException) -> None:
        self.by_id.pop(job.clip_id, None)
        msg = f"{job.entry.where}: {type(exc).__name__}: {exc}"
        self.result.failed.append((job.entry.where, msg))
        self.emit("fail", {"entry": job.entry.where, "error": msg, "traceback": "".join(
            traceback.format_exception(type(exc), exc, exc.__traceback__))[-2000:]})


def _select_todo(batch: _Batch, jobs: list[Job], plan: Plan, media_prefix: str, webm: bool) -> list[Job]:
    """Record every job in ``batch.by_id``; skip (and report) the clips already complete, return the rest."""
    pair_ids = {j.entry.id: j.clip_id for j in jobs}
    todo = []
    for job in jobs:
        if job.clip_id in batch.by_id:      # two entries that render identical files (ids differ only)
            continue
        if webm or job.run_entry.render.webm:
            job.run_entry = _with_webm(job.run_entry)
        rec = base_record(job, plan, pair_ids, media_prefix, job.run_entry.render.webm)
        done = load_done_record(job.clip_id, batch.clips_dir, batch.records_dir, job.run_entry.render.webm)
        if done is not None:
            # Same files; refresh the plan-dependent fields (another plan may share this clip).
            for key in ("duration_s", "body"):
                rec[key] = done.get(key)
            rec["metadata"] = {**done.get("metadata", {}), **rec["metadata"]}
            if _stale_qa(done, job):
                _remeasure_qa(done, job, batch)
            _recheck_qa(rec, done, job)
            batch.by_id[job.clip_id] = rec
            batch.result.skipped.append(job.clip_id)
            batch.emit("skip", {"clip_id": job.clip_id, "entry": job.entry.id})
        else:
            batch.by_id[job.clip_id] = rec
            todo.append(job)
    return todo


def _remove_stale(todo: list[Job], clips_dir: Path, records_dir: Path) -> None:
    """Delete leftovers of a crashed run (hidden temporary names) of the clips about to be made."""
    for job in todo:
        for stale in (*clips_dir.glob(f".{job.clip_id}.tmp*"), *records_dir.glob(f".{job.clip_id}.json.tmp*")):
            stale.unlink(missing_ok=True)


def _render_serial(batch: _Batch, todo: list[Job]) -> None:
    """Render ``todo`` one after another in this process; frame progress goes straight to ``batch.emit``."""
    global _PROGRESS_QUEUE
    _PROGRESS_QUEUE = _DirectProgress(batch.emit)
    try:
        for job in todo:
            batch.emit("start", {"clip_id": job.clip_id, "entry": job.entry.id})
            try:
                rec = render_job(*batch.job_args(job))
            except Exception as exc:  # noqa: BLE001 - one bad clip must not stop the plan
                batch.failed(job, exc)
                continue
            batch.finished(job, rec)
    finally:
        _PROGRESS_QUEUE = None


def _render_pool(batch: _Batch, todo: list[Job], workers: int, threads_per_worker: int) -> None:
    """Render ``todo`` in ``workers`` spawned processes, relaying their frame progress to ``batch.emit``."""
    ctx = mp.get_context("spawn")
    manager = ctx.Manager()
    progress_q = manager.Queue()
    try:
        with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_init_worker,
                                 initargs=(progress_q, threads_per_worker, os.getpid())) as pool:
            pending = {pool.submit(render_job, *batch.job_args(job)): job for job in todo}
            started: set[str] = set()
            while pending:
                done_set, _ = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
                _drain(progress_q, batch.emit, started)
                for fut in done_set:
                    job = pending.pop(fut)
                    try:
                        batch.finished(job, fut.result())
                    except Exception as exc:  # noqa: BLE001
                        batch.failed(job, exc)
            _drain(progress_q, batch.emit, started)
    finally:
        manager.shutdown()


_WORKER_READY = False


def render_job_on_worker(job: Job, record: dict, clips_dir: str, records_dir: str, threads: int = 1) -> dict:
    """:func:`render_job` on a Dask worker: sets the worker process up once (threads, headless GL), no progress
    queue (the scheduler reports clips as they finish)."""
    global _WORKER_READY
    if not _WORKER_READY:
        _init_worker(None, threads)
        _WORKER_READY = True
    return render_job(job, record, clips_dir, records_dir)


def _render_dask(batch: _Batch, todo: list[Job], scheduler, threads_per_worker: int) -> None:
    """Render ``todo`` on a Dask distributed cluster: ``scheduler`` is its address (``tcp://host:port``) or a
    ``distributed.Client``. Workers must see the same clips and records folders (a shared file system): they
    write the files, this process collects the records."""
    from distributed import Client, as_completed  # optional ([cluster] extra): only Dask rendering needs it

    client = scheduler if isinstance(scheduler, Client) else Client(scheduler, timeout=30)
    try:
        futures = {}
        for job in todo:
            fut = client.submit(render_job_on_worker, *batch.job_args(job), threads_per_worker, pure=False,
                                key=f"render-{job.clip_id}-{os.getpid()}-{time.time_ns()}")
            futures[fut] = job
        for fut in as_completed(futures):
            job = futures[fut]
            try:
                batch.finished(job, fut.result())
            except Exception as exc:  # noqa: BLE001 - one bad clip must not stop the plan
                batch.failed(job, exc)
    finally:
        if client is not scheduler:
            client.close()


def run_plan(plan: Plan, clips_dir: str | Path, records_dir: str | Path, media_prefix: str = "clips/",
             workers: int = 1, webm: bool = False, limit: int | None = None,
             on_event: Callable[[str, dict], None] | None = None, threads_per_worker: int = 1,
             scheduler=None, device: str = "cpu", gait_observer: str = "real",
             corpora: RealCorpora = DEFAULT_CORPORA) -> BatchResult:
    """Render every entry of ``plan`` that is not already complete.

    Args:
        plan: a validated plan.
        clips_dir: folder of the clip files (``<MEDIA_ROOT>/clips``).
        records_dir: folder of the per-clip records (never served: they name the conditions).
        media_prefix: prefix of file paths in records (relative to MEDIA_ROOT).
        workers: processes (spawned); 1 renders in this process.
        webm: also write VP9 WebM files.
        limit: only the first ``limit`` entries.
        on_event: progress callback ``on_event(kind, info)`` with kind in {"plan", "skip", "start", "frames",
            "done", "fail"} (the command draws tqdm bars from it).
        scheduler: a Dask distributed scheduler address (``tcp://host:port``) or Client: render there instead of
            in local processes (``workers`` is then ignored; the workers need the shared media folder).
        device: torch device of the network generators (gait_net, gesture_net), carried to every worker.
        gait_observer: the gait observer (:data:`protocol.vocabulary.QA_OBSERVERS`: real, real-perceived or synthetic)
            that reads the clips of a plan that names none.
        corpora: where the real-capture corpora of the real gait observers are (default: the built ones under
            ``var/mocap/``), carried to every worker.
    Returns a BatchResult with the records of every clip of the plan that exists now.
    """
    t0 = time.perf_counter()
    clips_dir, records_dir = Path(clips_dir), Path(records_dir)
    clips_dir.mkdir(parents=True, exist_ok=True)
    records_dir.mkdir(parents=True, exist_ok=True)
    emit = on_event or (lambda kind, info: None)
    jobs, failures = plan_jobs(plan, limit, device, gait_observer, corpora)
    batch = _Batch(clips_dir, records_dir, emit, BatchResult(failed=list(failures)))
    for where, msg in failures:
        emit("fail", {"entry": where, "error": msg})
    todo = _select_todo(batch, jobs, plan, media_prefix, webm)
    emit("plan", {"total": len(batch.by_id), "todo": len(todo), "skipped": len(batch.result.skipped)})
    _remove_stale(todo, clips_dir, records_dir)
    if workers > 1 or scheduler is not None:
        for modality in sorted({j.run_entry.modality for j in todo}):
            # train/cache the quality observers once, not in every worker
            observer_for(modality, todo[0].gait_observer, todo[0].corpora)
    if scheduler is not None:
        _render_dask(batch, todo, scheduler, threads_per_worker)
    elif workers <= 1 or len(todo) <= 1:
        _render_serial(batch, todo)
    else:
        _render_pool(batch, todo, workers, threads_per_worker)
    batch.result.records = list(batch.by_id.values())
    batch.result.seconds = time.perf_counter() - t0
    return batch.result


class _DirectProgress:
    """Queue stand-in for rendering in this process: progress goes straight to the callback."""

    def __init__(self, emit):
        self.emit = emit

    def put(self, item) -> None:
        clip_id, entry_id, done, total = item
        self.emit("frames", {"clip_id": clip_id, "entry": entry_id, "done": done, "total": total})


def _drain(q, emit, started: set | None = None) -> None:
    while True:
        try:
            clip_id, entry_id, done, total = q.get_nowait()
        except (queue_mod.Empty, EOFError, OSError):
            return
        if started is not None and clip_id not in started:
            started.add(clip_id)
            emit("start", {"clip_id": clip_id, "entry": entry_id})
        emit("frames", {"clip_id": clip_id, "entry": entry_id, "done": done, "total": total})


def _with_webm(entry: ClipEntry) -> ClipEntry:
    return dataclasses.replace(entry, render=dataclasses.replace(entry.render, webm=True))
