"""A researcher's motion file (BVH) -> a clip rendered like the generated ones, in a staging folder.

The file goes through the BVH importer with the rules of ``python -m generation.mocap import`` (units guessed from
the body height, up axis, rig auto-mapping; an error when the body's standing height is outside 1.2-2.3 m or the
solved body misses the file's joints by more than 3 cm: :func:`generation.mocap.import_file`), onto our gait or
gesture skeleton. The result is rendered with the platform's renderer (body mannequin, stick or points; the auto
camera rule; at most ``render.duration_s`` seconds, 10 s by default as for generated clips; a longer take is cut
there), its motion kept as ``<clip_id>.bvh`` and its quality record measured as for generated clips
(:func:`generation.pipeline.plan_qa.clip_qa`). A captured gesture is drawn as captured: standing, no chair.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from generation.core.motion import Motion
from generation.formats.bvh import write_bvh
from generation.mocap import ImportOptions, import_file
from generation.pipeline.plan_qa import clip_qa, observer_for
from generation.quality.checks import resolve_thresholds
from generation.render.clip import render_clip
from generation.render.settings import RenderSettings
from protocol.vocabulary import GAIT_EMOTIONS


class MotionImportError(ValueError):
    """A motion file that failed the importer's checks or could not be rendered; the message says why."""


@dataclass(frozen=True)
class StagedMotion:
    """Files made in the staging folder (mp4, png, optional webm, the motion's bvh) and the clip's facts:
    duration_s and n_frames as rendered, the importer's report row, the quality record (``qa``: QAResult.as_dict(),
    ``flag`` included; ``qa_flag``)
    and the camera record of the render."""

    mp4: Path
    poster: Path
    webm: Path | None
    bvh: Path
    duration_s: float
    n_frames: int
    import_row: dict
    qa: dict
    qa_flag: str
    camera: dict
    motion_metadata: dict


def render_settings(body: str, base: RenderSettings | None = None, webm: bool = False) -> RenderSettings:
    """The render settings of an imported motion: ``base`` (the platform's defaults) with its body and webm."""
    return dataclasses.replace(base or RenderSettings(), body=body, webm=webm)


def load_motion(path: Path, modality: str, max_duration_s: float) -> tuple[Motion, dict]:
    """The importer's Motion of ``path`` on the ``modality`` skeleton and its report row; MotionImportError with
    the importer's message (units, height, import error, rig) or for a take longer than ``max_duration_s``."""
    result = import_file(path, ImportOptions(skeleton=modality), given_as=path.name)
    if result.motion is None:
        raise MotionImportError(result.row["message"].replace(str(path), path.name))
    motion = result.motion
    if motion.num_frames < 2:
        raise MotionImportError(f"{path.name}: {motion.num_frames} frame(s): nothing to render")
    if motion.duration > max_duration_s:
        raise MotionImportError(f"{path.name}: {motion.duration:.1f} s long, longer than the limit of "
                                f"{max_duration_s:g} s")
    return motion, result.row


def stage_motion(path: Path, stage: Path, stem: str, modality: str, settings: RenderSettings,
                 max_duration_s: float = 300.0, labels: dict | None = None, observer: bool = True) -> StagedMotion:
    """Import, render and measure the motion file at ``path`` into ``stage/<stem>.mp4|.png|.bvh`` (+ ``.webm``).

    Args:
        path: a .bvh file (any rig the importer maps, any units it can guess).
        stage: an existing folder for the new files (the caller moves them into place or deletes them).
        stem: file stem, the clip id.
        modality: "gait" or "gesture": the skeleton it is solved onto.
        settings: render settings (:func:`render_settings`).
        labels: the manifest's labels (the observer check compares the gait vector or gesture label with what
            the observer reads).
        observer: read the clip with the modality's observer (the quality record's ``observed``).
    """
    motion, row = load_motion(path, modality, max_duration_s)
    motion.metadata = {**motion.metadata, "seated": False, "captured": True, "imported_file": path.name}
    bvh = stage / f"{stem}.bvh"
    write_bvh(motion, bvh)
    try:
        result = render_clip(motion, stage, stem, settings)
    except (RuntimeError, ValueError, OSError) as exc:
        raise MotionImportError(f"{path.name}: rendering failed ({type(exc).__name__}: {exc})") from exc
    labels = labels or {}
    intended = labels.get("emotion_label")
    if GAIT_EMOTIONS[0] in labels and f"final_{GAIT_EMOTIONS[0]}" not in labels:
        intended = [labels[e] for e in GAIT_EMOTIONS]
    qa_result, _ = clip_qa(motion, settings, resolve_thresholds(), intended,
                           observer_for(modality) if observer else None, camera_info=result.camera)
    meta = {k: v for k, v in motion.metadata.items() if k not in ("source_path",)}
    meta["source_duration_s"] = round(motion.duration, 4)
    return StagedMotion(result.mp4, result.poster, result.webm, bvh, round(result.duration_s, 4), result.n_frames,
                        row, qa_result.as_dict(), qa_result.flag, dict(result.camera),
                        meta)
