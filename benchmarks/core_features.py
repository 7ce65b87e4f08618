"""Speed and accuracy of the core motion code: affective/movement features, IK, BVH I/O, captured walks.

Prints a Markdown table. Single thread (OMP_NUM_THREADS=1, torch.set_num_threads(1)).

Usage: OMP_NUM_THREADS=1 python -m benchmarks.core_features
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import torch

from generation.core.features import (
    detect_foot_contacts,
    foot_skate,
    gait_affective_features,
    gesture_affective_features,
    movement_features,
    np_gait_affective_features,
)
from generation.core.ik import fit_positions_to_skeleton, inverse_kinematics
from generation.core.kinematics import np_forward_kinematics
from generation.core.motion import Motion
from generation.core.quaternion import np_qfrom_axis_angle, np_qnormalize
from generation.core.skeleton import gait_skeleton, gesture_skeleton
from generation.formats.bvh import read_bvh, write_bvh
from generation.mocap.captured import captured_walks, chain_clip_repeats

torch.set_num_threads(1)


def best_of(fn, repeats=5):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def random_rotations(sk, T, seed):
    rng = np.random.default_rng(seed)
    q = np_qfrom_axis_angle(rng.normal(size=(T, sk.num_joints, 3)), rng.uniform(-1.5, 1.5, (T, sk.num_joints)))
    q[:, 0] = np_qnormalize(rng.normal(size=(T, 4)))
    return q, rng.normal(size=(T, 3))


def main() -> None:
    rows = []
    T = 1000
    for name, sk, feat in (("gait", gait_skeleton(), gait_affective_features),
                           ("gesture", gesture_skeleton(), gesture_affective_features)):
        q, root = random_rotations(sk, T, 1)
        P = np_forward_kinematics(q, root, sk)
        Pt = torch.tensor(P)
        t = best_of(lambda: feat(Pt))                                           # noqa: B023
        rows.append((f"{name} affective features, torch float64, forward", f"{t * 1e3:.2f} ms / 1000 frames"))
        Pg = Pt.clone().requires_grad_(True)
        t = best_of(lambda: feat(Pg).sum().backward())                          # noqa: B023
        rows.append((f"{name} affective features, forward + backward", f"{t * 1e3:.2f} ms / 1000 frames"))
        t = best_of(lambda: inverse_kinematics(P, sk))                          # noqa: B023
        _, rep = inverse_kinematics(P, sk)
        rows.append((f"{name} IK (random poses, {sk.num_joints} joints)", f"{t * 1e3:.1f} ms / 1000 frames"))
        rows.append((f"{name} FK->IK position error", f"max {rep.max_error_m:.1e} m, mean {rep.mean_error_m:.1e} m"))
        noisy = P + np.random.default_rng(2).normal(scale=0.02, size=P.shape)
        t = best_of(lambda: fit_positions_to_skeleton(noisy, sk))               # noqa: B023
        _, before, after = fit_positions_to_skeleton(noisy, sk)
        rows.append((f"{name} fit_positions_to_skeleton (2 cm noise)",
                     f"{t * 1e3:.1f} ms / 1000 frames; bone-length deviation {before * 100:.1f} cm -> {after:.0e} m"))

    sk = gait_skeleton()
    walk = chain_clip_repeats(captured_walks()[0], 27)                                # ~1026 frames
    P = walk.positions()
    n = walk.num_frames
    t = best_of(lambda: movement_features(P, walk.fps, sk, root_rotations=walk.rotations[:, 0]))
    rows.append((f"movement features incl. contacts ({n}-frame captured walk)",
                 f"{t * 1e3 * 1000 / n:.1f} ms / 1000 frames"))
    t = best_of(lambda: detect_foot_contacts(P, walk.fps, sk))
    rows.append(("foot contact detection", f"{t * 1e3 * 1000 / n:.2f} ms / 1000 frames"))
    t = best_of(lambda: np_gait_affective_features(P))
    rows.append(("gait affective features, numpy twin", f"{t * 1e3 * 1000 / n:.2f} ms / 1000 frames"))

    q, root = random_rotations(sk, T, 3)
    m = Motion(sk, q, root, 30.0)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.bvh"
        tw = best_of(lambda: write_bvh(m, path), 3)
        tr = best_of(lambda: read_bvh(path), 3)
        back = read_bvh(path)
        leaf = {"left_toe": "left_heel_end", "right_toe": "right_heel_end", "head": "neck_end",
                "left_hand_index": "left_hand_end", "right_hand_index": "right_hand_end"}
        idx = [back.skeleton.index(leaf.get(j, j)) for j in sk.joints]
        err = np.abs(back.positions()[:, idx] - m.positions()).max()
    rows.append(("BVH write / read (21 joints)", f"{tw * 1e3:.0f} / {tr * 1e3:.0f} ms per 1000 frames"))
    rows.append(("BVH round-trip position error", f"{err:.1e} m"))

    t0 = time.perf_counter()
    walks = captured_walks()
    t_load = time.perf_counter() - t0
    rows.append(("captured_walks() (read 6 DeepMimic clips, retarget, ground)", f"{t_load * 1e3:.0f} ms"))
    for w in walks:
        Pw = w.positions()
        fs = foot_skate(Pw, w.fps, w.skeleton)
        speed = np.linalg.norm(Pw[-1, 0, [0, 2]] - Pw[0, 0, [0, 2]]) / w.duration
        rt = w.metadata["retarget"]
        rows.append((f"captured {Path(w.metadata['source']).stem} ({w.num_frames} f)",
                     f"foot skate mean {fs['mean_m_s'] * 100:.1f} cm/s, max {fs['max_m_s'] * 100:.1f} cm/s; "
                     f"contact {fs['contact_share'] * 100:.0f}% of foot-frames; speed {speed:.2f} m/s; "
                     f"retarget scale {rt['scale']:.3f}, mapped-joint offset max {rt['max_error_m'] * 100:.1f} cm"))

    print("| measurement | result |\n|---|---|")
    for k, v in rows:
        print(f"| {k} | {v} |")


if __name__ == "__main__":
    main()
