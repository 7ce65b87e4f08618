"""Inverse kinematics: FK -> IK reproduces positions; bone-length fitting."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from generation.core.ik import bend_limb_to_target, fit_positions_to_skeleton, inverse_kinematics, matrix_to_quaternion
from generation.core.kinematics import np_forward_kinematics
from generation.core.motion import MotionFormatError
from generation.core.quaternion import np_qangle, np_qnormalize, np_qto_matrix
from generation.core.skeleton import gait_skeleton, gesture_skeleton

torch.set_num_threads(1)


def random_motion(skeleton, T, seed):
    rng = np.random.default_rng(seed)
    q = np_qnormalize(rng.normal(size=(T, skeleton.num_joints, 4)))
    root = rng.normal(size=(T, 3))
    return q, root


@pytest.mark.parametrize("make", [lambda: gait_skeleton(), lambda: gesture_skeleton(1.62, "female"),
                                  lambda: gait_skeleton(2.0, "female")])
def test_fk_then_ik_reproduces_positions(make):
    sk = make()
    q, root = random_motion(sk, 200, seed=sk.num_joints)
    P = np_forward_kinematics(q, root, sk)
    motion, report = inverse_kinematics(P, sk, fps=25.0, metadata={"k": 1})
    assert report.max_error_m < 1e-5
    assert np.abs(motion.positions() - P).max() < 1e-5
    assert motion.fps == 25.0 and motion.metadata == {"k": 1}
    # the root has 3 non-collinear children, so its full orientation is recovered
    assert np_qangle(motion.rotations[:, 0], q[:, 0]).max() < 1e-6
    assert np.allclose(np.linalg.norm(motion.rotations, axis=-1), 1.0)


def test_ik_keeps_twist_continuous_on_smooth_motion():
    sk = gesture_skeleton()
    T = 120
    t = np.linspace(0, 2 * np.pi, T)
    # smooth arm and spine motion from slowly varying local rotations
    axis = np.stack([np.sin(t), np.cos(t), 0.3 + 0 * t], -1)
    angle = 0.8 * np.sin(t)
    from generation.core.quaternion import np_qfrom_axis_angle
    q = np.tile([1.0, 0, 0, 0], (T, sk.num_joints, 1))
    for j in range(1, sk.num_joints):
        q[:, j] = np_qfrom_axis_angle(axis, angle * (0.5 + 0.1 * (j % 5)))
    P = np_forward_kinematics(q, np.zeros((T, 3)), sk)
    motion, report = inverse_kinematics(P, sk)
    assert report.max_error_m < 1e-5
    # frame-to-frame rotation change stays small for every joint (no flips)
    step = np_qangle(motion.rotations[1:], motion.rotations[:-1])
    assert step.max() < 0.2


def test_ik_on_stretched_positions_reports_error():
    sk = gait_skeleton()
    q, root = random_motion(sk, 10, seed=3)
    P = np_forward_kinematics(q, root, sk) * 1.1
    _, report = inverse_kinematics(P, sk)
    assert report.max_error_m > 0.01 and len(report.per_joint_max_m) == 21


def test_ik_rejects_bad_input():
    sk = gait_skeleton()
    with pytest.raises(MotionFormatError, match=r"\(T, 21, 3\)"):
        inverse_kinematics(np.zeros((4, 23, 3)), sk)
    bad = np.zeros((2, 21, 3))
    bad[0, 3, 1] = np.nan
    with pytest.raises(MotionFormatError, match="NaN"):
        inverse_kinematics(bad, sk)


def test_fit_positions_to_skeleton_restores_lengths_and_directions():
    sk = gait_skeleton()
    q, root = random_motion(sk, 50, seed=5)
    P = np_forward_kinematics(q, root, sk)
    rng = np.random.default_rng(6)
    noisy = P + rng.normal(scale=0.02, size=P.shape)
    fitted, before, after = fit_positions_to_skeleton(noisy, sk)
    assert before > 0.01 and after < 1e-9
    lengths = np.linalg.norm(fitted[:, 1:] - fitted[:, list(sk.parents[1:])], axis=-1)
    np.testing.assert_allclose(lengths, np.broadcast_to(sk.bone_lengths()[1:], lengths.shape), atol=1e-9)
    # directions kept below single-child joints (left_shoulder -> left_elbow)
    j, p = 14, sk.parents[14]
    d_in = noisy[:, j] - noisy[:, p]
    d_out = fitted[:, j] - fitted[:, p]
    cos = (d_in * d_out).sum(-1) / np.linalg.norm(d_in, axis=-1) / np.linalg.norm(d_out, axis=-1)
    np.testing.assert_allclose(cos, 1.0, atol=1e-9)
    # then IK is exact
    _, report = inverse_kinematics(fitted, sk)
    assert report.max_error_m < 1e-5
    # already-fitting positions are unchanged
    same, b2, a2 = fit_positions_to_skeleton(P, sk)
    assert b2 < 1e-9 and np.abs(same - P).max() < 1e-9


def test_matrix_to_quaternion_roundtrip():
    q = np_qnormalize(np.random.default_rng(7).normal(size=(500, 4)))
    back = matrix_to_quaternion(np_qto_matrix(q))
    assert np_qangle(back, q).max() < 1e-7


def test_bend_limb_to_target_reaches_target_and_keeps_lengths():
    sk = gait_skeleton()
    q, root = random_motion(sk, 40, seed=8)
    P = np_forward_kinematics(q, root, sk)
    hip, knee, heel, toe = (sk.index(n) for n in ("left_hip", "left_knee", "left_heel", "left_toe"))
    rng = np.random.default_rng(9)
    target = P[:, hip] + rng.normal(size=(40, 3)) * 0.25
    out = bend_limb_to_target(P, sk, "left_heel", target)
    reach = np.linalg.norm(target - P[:, hip], axis=-1)
    ok = reach < 0.8
    np.testing.assert_allclose(out[ok, heel], target[ok], atol=1e-9)
    lengths = sk.bone_lengths()
    np.testing.assert_allclose(np.linalg.norm(out[:, knee] - out[:, hip], axis=-1), lengths[knee], atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(out[:, heel] - out[:, knee], axis=-1), lengths[heel], atol=1e-9)
    np.testing.assert_allclose(out[:, toe] - out[:, heel], P[:, toe] - P[:, heel], atol=1e-12)  # foot moved rigidly
    np.testing.assert_allclose(np.delete(out, [knee, heel, toe], 1), np.delete(P, [knee, heel, toe], 1))
    # reaching for where the heel already is changes nothing
    np.testing.assert_allclose(bend_limb_to_target(P, sk, "left_heel", P[:, heel]), P, atol=1e-9)
