"""Benchmark of the motion-capture importer (generation.mocap): each naming convention's import.

For every convention of ``tests.mocap_conventions`` (gait and gesture skeletons) a 1000-frame procedural
motion (walk / seated gesture) is written as that rig would write it (its names, its extra joints, a T-pose rest,
centimetres) and imported back; plus a BVH from a body of other proportions and Emotion-Gait-style joint
positions (16 joints, z-up, millimetres, NPY). Reported: joints mapped, the importer's retarget error (our FK vs
the scaled source positions of mapped joints), the distance to the ground-truth positions, and the import time
per 1000 frames (read + map + IK, best of 3, one thread).

Writes a markdown section to ``docs/benchmarks/mocap.md`` (use --md to change) and prints it.
Usage: OMP_NUM_THREADS=1 python -m benchmarks.bench_mocap [--frames 1000]
"""
from __future__ import annotations

import argparse
import datetime
import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
import torch

from generation.core.skeleton import gait_skeleton
from generation.mocap.importer import ImportOptions, import_file
from generation.procedural.gesture import GestureParams, seated_gesture
from generation.procedural.walk import WalkParams, walk
from tests.mocap_conventions import CONVENTIONS, export_as

EG16 = ("root", "spine", "neck", "head", "left_shoulder", "left_elbow", "left_hand", "right_shoulder",
        "right_elbow", "right_hand", "left_hip", "left_knee", "left_heel", "right_hip", "right_knee", "right_heel")


def _timed(path: Path, options: ImportOptions, repeats: int = 3):
    best, result = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = import_file(path, options)
        best = min(best, time.perf_counter() - t0)
    if result.motion is None:
        raise RuntimeError(result.row["message"])
    return result, best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=1000)
    ap.add_argument("--md", type=Path, default=Path(__file__).resolve().parents[1] / "docs/benchmarks/mocap.md")
    args = ap.parse_args()
    torch.set_num_threads(1)
    T = args.frames
    sources = {
        "gait": walk(WalkParams(torso_pitch_rad=0.15, arm_swing_rad=0.5), n_frames=T),
        "gesture": seated_gesture([GestureParams(kind=k) for k in ("beat", "descriptive", "pointing")], n_frames=T),
    }
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for skeleton, motion in sources.items():
            truth = motion.positions()
            for conv in CONVENTIONS[skeleton]:
                path = export_as(motion, conv, tmp / f"{skeleton}_{conv}.bvh")
                result, secs = _timed(path, ImportOptions(skeleton=skeleton))
                gt = float(np.linalg.norm(result.motion.positions() - truth, axis=-1).max())
                rows.append((f"{conv} BVH (cm, T-pose rest)", skeleton, result, gt, secs))
        small = walk(WalkParams(), n_frames=T, skeleton=gait_skeleton(1.55, "female"))
        path = export_as(small, "mixamo", tmp / "small.bvh")
        result, secs = _timed(path, ImportOptions(skeleton="gait"))
        heels = [small.skeleton.index("left_heel"), small.skeleton.index("right_heel")]
        scale = result.motion.metadata["retarget"]["scale"]
        gt = float(np.linalg.norm(result.motion.positions()[:, heels] - small.positions()[:, heels] * scale,
                                  axis=-1).max())
        rows.append(("mixamo BVH of a 1.55 m female body (heels vs scaled source)", "gait", result, gt, secs))
        walk_pos = sources["gait"].positions()
        sk = sources["gait"].skeleton
        Q = walk_pos[:, [sk.index(n) for n in EG16]]
        z_up = Q @ np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]]).T
        np.save(tmp / "eg16.npy", (z_up * 1000).reshape(T, -1))
        result, secs = _timed(tmp / "eg16.npy", ImportOptions(skeleton="gait", layout="emotion-gait-16"))
        gt = float(np.linalg.norm(result.motion.positions()[:, [sk.index(n) for n in EG16]] - Q, axis=-1).max())
        rows.append(("Emotion-Gait 16-joint positions (NPY, z-up, mm)", "gait", result, gt, secs))

    date = datetime.date.today().isoformat()
    lines = ["## Motion-capture import (`python -m generation.mocap import`)", "",
             f"Machine: 2-core VM shared with other jobs, no GPU; date {date}; one thread (`OMP_NUM_THREADS=1`). "
             f"Each source: {T} frames at 30 fps of a procedural motion (walk for gait, three seated gestures for "
             "gesture) written as the rig would write it (`tests/mocap_conventions.py`: its joint names, its "
             "extra joints such as clavicles and `LHipJoint`, arms out in a T-pose rest, centimetres), then "
             "imported back. Produced by `benchmarks/bench_mocap.py`.", "",
             "| source | skeleton | mapped joints | unmapped | retarget max error (mm) "
             "| max error vs ground truth (mm) | units guessed | time per 1000 frames (s) |",
             "|---|---|---|---|---|---|---|---|"]
    for name, skeleton, result, gt, secs in rows:
        r, m = result.row, result.motion
        lines.append(f"| {name} | {skeleton} | {r['mapped_joints']}/{m.skeleton.num_joints} | "
                     f"{r['unmapped_joints'].replace(';', ', ') or '-'} | "
                     f"{m.metadata['retarget']['max_error_m'] * 1000:.3g} | {gt * 1000:.3g} | "
                     f"{m.metadata['unit_guess']} | {secs / m.num_frames * 1000:.3f} |")
    lines += ["", "The retarget error is the importer's own report (distance between our FK and the source positions "
              "scaled to our legs, over mapped joints): zero when the source has our proportions, a few centimetres "
              "for other bodies, where the feet are still placed exactly by the leg IK. Unmapped joints are "
              "interpolated (gesture `chest3` on Mixamo's three spine joints) or follow their parent (toes and "
              "hand tips of the 16-joint layout).", ""]
    text = "\n".join(lines)
    args.md.parent.mkdir(parents=True, exist_ok=True)
    args.md.write_text(text)
    print(text)


if __name__ == "__main__":
    main()
