"""Quality measures of generated gestures against ground truth (seed 003 section 5.3, Table 1)."""
from __future__ import annotations

import numpy as np

from generation.core.kinematics import np_forward_kinematics
from generation.core.quaternion import np_qangle, np_qnormalize
from generation.core.skeleton import gesture_skeleton

# neck, head, shoulders, elbows, wrists: the 8 upper-body joints seed 003 compares Yoon et al. on
UPPER_BODY = (5, 6, 8, 9, 10, 12, 13, 14)


def sequence_pose_error(pred: np.ndarray, true: np.ndarray, gender: str, root: np.ndarray) -> dict[str, float]:
    """Normalised pose error of one sequence.

    Args:
        pred, true: (T, 23, 4) local rotations; gender picks the body; root (3,) the seated root position, metres.

    Returns:
        {"all": mean over frames and joints of the joint distance / the ground truth's bounding-box diagonal,
         "upper": the same over the 8 upper-body joints, "rotation_deg": mean geodesic joint-rotation error}.
    """
    sk = gesture_skeleton(build=gender)
    roots = np.repeat(np.asarray(root, dtype=np.float64)[None], len(true), 0)
    P = np_forward_kinematics(np.asarray(pred, dtype=np.float64), roots, sk)
    G = np_forward_kinematics(np.asarray(true, dtype=np.float64), roots, sk)
    flat = G.reshape(-1, 3)
    diag = float(np.linalg.norm(flat.max(0) - flat.min(0)))
    d = np.linalg.norm(P - G, axis=-1)
    return {"all": float(d.mean() / diag), "upper": float(d[:, UPPER_BODY].mean() / diag),
            "rotation_deg": float(np.degrees(np_qangle(np_qnormalize(pred), true)).mean())}


def dataset_pose_error(pred: list[np.ndarray], data, idx) -> dict[str, float]:
    """Seed 003 Table 1: the mean over sequences ``idx`` of :func:`sequence_pose_error` (pred[k] for idx[k]),
    plus the mean :func:`upper_body_acceleration` of the predictions."""
    rows, accel = [], []
    for p, i in zip(pred, idx):
        L = int(data.lengths[i])
        rows.append(sequence_pose_error(p[:L], data.rotations[i, :L], str(data.gender[i]), data.root[i]))
        accel.append(upper_body_acceleration(p[:L], str(data.gender[i]), data.root[i], data.fps))
    return {"pose_error": float(np.mean([r["all"] for r in rows])),
            "pose_error_upper": float(np.mean([r["upper"] for r in rows])),
            "rotation_error_deg": float(np.mean([r["rotation_deg"] for r in rows])),
            "acceleration": float(np.mean(accel)), "n": len(rows)}


def upper_body_acceleration(rotations: np.ndarray, gender: str, root: np.ndarray, fps: float) -> float:
    """Mean magnitude (m/s^2) of the second time difference of the 8 upper-body joint positions: a jerkiness
    measure (seed 003 Fig. 5 reads smoothness off the end-effector trajectories). rotations (T, 23, 4)."""
    sk = gesture_skeleton(build=gender)
    roots = np.repeat(np.asarray(root, dtype=np.float64)[None], len(rotations), 0)
    P = np_forward_kinematics(np.asarray(rotations, dtype=np.float64), roots, sk)[:, UPPER_BODY]
    if len(P) < 3:
        return 0.0
    return float(np.linalg.norm(np.diff(P, n=2, axis=0), axis=-1).mean() * fps * fps)
