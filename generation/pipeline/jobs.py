"""Jobs of a plan: each entry resolved to the generator that will run (or its fallback), hashed to its clip id,
with the plan's quality thresholds, the gait observer that reads it (and the real-capture corpora it is trained on)
and the torch device of the network generators."""
from __future__ import annotations

from dataclasses import dataclass, field

from generation.mocap.real_corpus import DEFAULT_CORPORA, RealCorpora
from generation.plans.clipgen import ClipGenerationError, generator_version, resolve
from generation.plans.schema import ClipEntry, Plan, clip_hash
from generation.quality.checks import gait_observer_kind, resolve_thresholds


@dataclass
class Job:
    """One clip to make: the plan entry, the entry that will run (maybe a fallback) and the clip id."""

    entry: ClipEntry
    run_entry: ClipEntry
    clip_id: str
    generator_version: str
    fallback_reason: str | None = None
    qa_thresholds: dict | None = None  # the plan's quality thresholds (resolved); None = protocol.vocabulary defaults
    # torch device of the network generators, fixed where the jobs are planned and carried to every worker
    # (local processes and Dask workers on other machines alike)
    device: str = "cpu"
    # the gait observer that reads the clip (real, real-perceived or synthetic): the plan's ``qa: {observer: ...}``,
    # else the caller's choice
    gait_observer: str = "real"
    # where the real-capture corpora of the real gait observers are, fixed where the jobs are planned (the command
    # line's or the settings' choice), so a worker never looks it up itself
    corpora: RealCorpora = field(default_factory=RealCorpora)


def plan_jobs(plan: Plan, limit: int | None = None, device: str = "cpu", gait_observer: str = "real",
              corpora: RealCorpora = DEFAULT_CORPORA) -> tuple[list[Job], list[tuple[str, str]]]:
    """Jobs for the plan's entries (first ``limit``) with the network generators on ``device`` and the plan's gait
    observer (``gait_observer`` when the plan names none) of the real corpora ``corpora``, and (entry, message)
    for entries that cannot run."""
    thresholds = resolve_thresholds(plan.qa)
    observer = gait_observer_kind(plan.qa, gait_observer)
    jobs, failures = [], []
    for entry in plan.entries[:limit] if limit else plan.entries:
        try:
            run_entry, reason = resolve(entry)
        except ClipGenerationError as exc:
            failures.append((entry.where, str(exc)))
            continue
        version = generator_version(run_entry.generator, run_entry.inputs)
        jobs.append(Job(entry, run_entry, clip_hash(run_entry, run_entry.generator, version), version, reason,
                        thresholds, device, observer, corpora))
    return jobs, failures
