"""Pose affective features (seed 000 / seed 003 definitions) and movement features."""
from __future__ import annotations

import re

import numpy as np
import pytest
import torch

from generation.core.features import (
    GAIT_FEATURE_NAMES,
    GESTURE_FEATURE_NAMES,
    detect_foot_contacts,
    foot_skate,
    gait_affective_features,
    gesture_affective_features,
    movement_features,
    np_gait_affective_features,
    np_gesture_affective_features,
)
from generation.core.kinematics import np_forward_kinematics
from generation.core.quaternion import np_qfrom_axis_angle, np_qnormalize
from generation.core.skeleton import gait_skeleton, gesture_skeleton

torch.set_num_threads(1)

# The definitions as written in REFERENCE.md, parsed independently of the module's tables.
GAIT_SPEC = """ang(17,9,13), ang(19,9,15), ang(13,14,15), ang(17,18,19), ang(12,11,13), ang(12,11,17),
ang(12,0,2), ang(12,0,6), ang(8,0,4), ang(1,2,3), ang(5,6,7)
d(16,11)/d(16,0), d(20,11)/d(20,0), d(16,20)/d(11,0), d(4,8)/d(11,0)
A(17,9,13)/A(17,0,13), A(19,9,15)/A(19,0,15), A(20,11,16)/A(8,0,4)"""
GESTURE_SPEC = """ang(0,2,6), ang(9,4,6), ang(13,4,6), ang(0,10,4), ang(0,14,4), ang(8,9,10), ang(12,13,14)
d(10,0)/d(10,4), d(10,0)/d(10,6), d(14,0)/d(14,4), d(14,0)/d(14,6), d(10,14)/d(0,6)
A(10,0,14)/A(10,4,14), A(6,10,0)/A(6,14,0), A(4,10,0)/A(4,14,0)"""


def reference_features(P: np.ndarray, spec: str, angle_scale: float) -> np.ndarray:
    """Straightforward per-feature evaluation with arccos and Heron-free cross products."""
    def ang(p, q, r):
        u, v = P[p] - P[q], P[r] - P[q]
        return np.arccos(np.clip(u @ v / np.linalg.norm(u) / np.linalg.norm(v), -1, 1)) * angle_scale

    def d(a, b):
        return np.linalg.norm(P[a] - P[b])

    def A(p, q, r):
        return 0.5 * np.linalg.norm(np.cross(P[p] - P[q], P[r] - P[q]))

    exprs = re.findall(r"(?:ang|d|A)\([\d,]+\)(?:/(?:d|A)\([\d,]+\))?", spec)
    return np.array([eval(e, {"ang": ang, "d": d, "A": A}) for e in exprs])


def random_poses(skeleton, n, seed=0, spread=0.5):
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=(n, skeleton.num_joints, 3))
    angle = rng.uniform(-spread, spread, size=(n, skeleton.num_joints))
    q = np_qfrom_axis_angle(axis, angle)
    q[:, 0] = np_qnormalize(rng.normal(size=(n, 4)))
    return np_forward_kinematics(q, rng.normal(size=(n, 3)), skeleton)


def yaw(points: np.ndarray, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return points @ R.T


def test_names_counts_and_kinds():
    assert len(GAIT_FEATURE_NAMES) == 18 and len(set(GAIT_FEATURE_NAMES)) == 18
    assert len(GESTURE_FEATURE_NAMES) == 15 and len(set(GESTURE_FEATURE_NAMES)) == 15
    assert sum(n.startswith("ang:") for n in GAIT_FEATURE_NAMES) == 11
    assert GAIT_FEATURE_NAMES[0] == "ang:right_shoulder-lower_back-left_shoulder"
    assert sum(n.startswith("ang:") for n in GESTURE_FEATURE_NAMES) == 7


@pytest.mark.parametrize("which", ["gait", "gesture"])
def test_match_reference_definitions(which):
    sk = gait_skeleton() if which == "gait" else gesture_skeleton()
    P = random_poses(sk, 20, seed=1)
    if which == "gait":
        got = np_gait_affective_features(P)
        want = np.stack([reference_features(p, GAIT_SPEC, 1.0) for p in P])
    else:
        got = np_gesture_affective_features(P)
        want = np.stack([reference_features(p, GESTURE_SPEC, 1 / np.pi) for p in P])
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-6)


def test_rest_pose_values():
    f = np_gait_affective_features(gait_skeleton().rest_positions())
    assert f[2] == pytest.approx(np.pi, abs=1e-5)      # straight left elbow
    assert f[3] == pytest.approx(np.pi, abs=1e-5)
    g = np_gesture_affective_features(gesture_skeleton().rest_positions())
    assert g[5] == pytest.approx(1.0, abs=1e-5)         # straight elbow, angle / pi
    assert np.all((g[:7] >= 0) & (g[:7] <= 1))


@pytest.mark.parametrize("which", ["gait", "gesture"])
def test_invariant_to_scale_translation_and_vertical_rotation(which):
    sk = gait_skeleton() if which == "gait" else gesture_skeleton()
    fn = np_gait_affective_features if which == "gait" else np_gesture_affective_features
    P = random_poses(sk, 30, seed=2)
    base = fn(P)
    np.testing.assert_allclose(fn(P * 2.7), base, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(fn(P + np.array([3.0, -1.0, 12.0])), base, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(fn(yaw(P, 1.234)), base, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(fn(yaw(P * 0.6, -2.0) + 5.0), base, rtol=1e-8, atol=1e-8)
    # and they do change with the pose
    assert np.abs(fn(random_poses(sk, 30, seed=3)) - base).max() > 0.1


def test_torch_batched_differentiable_and_equal_to_numpy():
    sk = gait_skeleton()
    P = torch.tensor(random_poses(sk, 6, seed=4).reshape(2, 3, 21, 3), requires_grad=True)
    f = gait_affective_features(P)
    assert f.shape == (2, 3, 18)
    f.sum().backward()
    assert torch.isfinite(P.grad).all() and P.grad.abs().sum() > 0
    np.testing.assert_allclose(f.detach().numpy(), np_gait_affective_features(P.detach().numpy()))
    small = torch.tensor(random_poses(gesture_skeleton(), 2, seed=5), requires_grad=True)
    assert torch.autograd.gradcheck(gesture_affective_features, (small,), eps=1e-6, atol=1e-5)


def test_straight_limb_gradient_is_finite():
    P = torch.tensor(gait_skeleton().rest_positions(), requires_grad=True)  # straight elbows: angle = pi
    gait_affective_features(P).sum().backward()
    assert torch.isfinite(P.grad).all()


def test_bad_shapes_rejected():
    with pytest.raises(ValueError, match=r"\(\.\.\., 21, 3\)"):
        gait_affective_features(torch.zeros(5, 23, 3))
    with pytest.raises(ValueError, match="23"):
        np_gesture_affective_features(np.zeros((5, 21, 3)))


# ---- contacts and movement features --------------------------------------------------------------

def stepping_sequence(T=120, fps=30.0, speed=1.2, period=30):
    """A synthetic walker on the gait skeleton: root moves along +z, feet alternately planted.

    Each foot is planted (on the ground, still) for the first half of its period and swings (lifted 10 cm,
    moving at twice the body speed) for the second half; the right foot is half a period behind the left.
    """
    sk = gait_skeleton()
    rest = sk.rest_positions()
    floor = -rest[:, 1].min()
    t = np.arange(T)
    P = np.tile(rest, (T, 1, 1))
    P[:, :, 1] += floor
    P[:, :, 2] += (speed * t / fps)[:, None]
    for side, shift in (("left", 0), ("right", period // 2)):
        idx = [sk.index(f"{side}_{n}") for n in ("knee", "heel", "toe")]
        phase = (t + shift) % period
        swing = phase >= period // 2
        # foot z: constant during stance, catching up during swing
        cycle_start = (t + shift) - phase
        stance_z = speed * (cycle_start + period // 2 - shift) / fps
        frac = np.clip((phase - period // 2) / (period // 2), 0, 1)
        z = np.where(swing, stance_z + frac * speed * period / fps, stance_z)
        for j in idx:
            P[:, j, 2] = rest[j, 2] + z
            P[:, j, 1] += np.where(swing, 0.10 * np.sin(np.pi * frac), 0.0)
    return P, sk, fps


def test_detect_foot_contacts_on_synthetic_steps():
    P, sk, fps = stepping_sequence()
    c = detect_foot_contacts(P, fps, sk)
    assert c.shape == (120, 2) and c.dtype == bool
    # planted half the time, alternating
    assert 0.35 < c[:, 0].mean() < 0.65 and 0.35 < c[:, 1].mean() < 0.65
    assert not (~c[:, 0] & ~c[:, 1]).any()  # one foot always down
    left_on = np.nonzero(c[1:, 0] & ~c[:-1, 0])[0] + 1
    assert np.all(np.diff(left_on) == 30)


def test_step_phase_and_frequency():
    P, sk, fps = stepping_sequence()
    mf = movement_features(P, fps, sk)
    c = detect_foot_contacts(P, fps, sk)
    left_on = np.nonzero(c[1:, 0] & ~c[:-1, 0])[0] + 1
    right_on = np.nonzero(c[1:, 1] & ~c[:-1, 1])[0] + 1
    np.testing.assert_allclose(mf["step_phase"][left_on], 0.0, atol=1e-9)
    np.testing.assert_allclose(mf["step_phase"][right_on], np.pi, atol=1e-9)
    np.testing.assert_allclose(mf["step_frequency"], 2 * np.pi / 30, atol=1e-9)
    assert mf["step_phase"].min() >= 0 and mf["step_phase"].max() < 2 * np.pi


def test_step_phase_from_given_contacts():
    T = 70
    contacts = np.zeros((T, 2), bool)
    for s in (10, 40):
        contacts[s:s + 12, 0] = True
    for s in (25, 55):
        contacts[s:s + 12, 1] = True
    P, sk, fps = stepping_sequence(T=T)
    mf = movement_features(P, fps, sk, contacts=contacts)
    th = mf["step_phase"]
    assert th[10] == pytest.approx(0.0) and th[25] == pytest.approx(np.pi) and th[40] == pytest.approx(0.0)
    assert th[17] == pytest.approx(np.pi * 7 / 15)
    np.testing.assert_allclose(mf["step_frequency"], np.pi / 15)


def test_root_features_straight_and_turning():
    sk = gait_skeleton()
    fps, T = 30.0, 150
    rest = sk.rest_positions()
    s = 1.2 * np.arange(T) / fps
    # straight along +x while facing +x: the path heads the way the body faces
    facing_x = yaw(rest, np.pi / 2)
    P = facing_x[None] + np.stack([s, 0 * s, 0 * s], -1)[:, None]
    P[:, :, 1] += 0.02 * np.sin(np.arange(T) / 3)[:, None]
    mf = movement_features(P, fps, sk)
    np.testing.assert_allclose(mf["root_speed"][1:], 1.2, rtol=1e-9)
    np.testing.assert_allclose(mf["orientation_diff"], 0.0, atol=1e-9)
    np.testing.assert_allclose(mf["curvature"], 0.0, atol=1e-9)
    assert abs(mf["root_height_dev"].mean()) < 1e-12
    # same path while facing +z: the path is to the body's left, +pi/2
    P2 = rest[None] + np.stack([s, 0 * s, 0 * s], -1)[:, None]
    np.testing.assert_allclose(movement_features(P2, fps, sk)["orientation_diff"], np.pi / 2, atol=1e-9)
    # a left turn on a circle of radius 2 m, body facing along the path
    R = 2.0
    h = s / R
    circle = np.stack([R * (1 - np.cos(h)), 0 * h, R * np.sin(h)], -1)
    P3 = np.stack([yaw(rest, a) for a in h]) + circle[:, None]
    mf3 = movement_features(P3, fps, sk)
    # the path fit spans +-2 s (70 degrees of this tight turn), so allow 10 %
    np.testing.assert_allclose(mf3["curvature"][10:-10], 1 / R, rtol=0.1)
    np.testing.assert_allclose(mf3["curvature"], 1 / R, rtol=0.2)
    np.testing.assert_allclose(mf3["orientation_diff"], 0.0, atol=0.02)
    np.testing.assert_allclose(mf3["root_speed"][1:], 1.2, rtol=1e-3)


def test_movement_features_batched_and_root_rotation_facing():
    P, sk, fps = stepping_sequence()
    batch = np.stack([P, yaw(P, 0.7)])
    mf = movement_features(batch, fps, sk)
    single = movement_features(P, fps, sk)
    for key, value in single.items():
        assert mf[key].shape == (2, 120)
        np.testing.assert_allclose(mf[key][0], value, atol=1e-9)
        np.testing.assert_allclose(mf[key][1], value, atol=1e-6)  # yaw changes none of them
    ident = np.tile([1.0, 0, 0, 0], (120, 1))
    np.testing.assert_allclose(movement_features(P, fps, sk, root_rotations=ident)["orientation_diff"],
                               single["orientation_diff"], atol=1e-9)


def test_movement_features_reject_bad_input():
    sk = gait_skeleton()
    with pytest.raises(ValueError, match="at least 2 frames"):
        movement_features(np.zeros((1, 21, 3)), 30.0, sk)
    with pytest.raises(ValueError, match="21"):
        detect_foot_contacts(np.zeros((10, 23, 3)), 30.0, sk)


def test_foot_skate_zero_for_planted_feet():
    P, sk, fps = stepping_sequence()
    fs = foot_skate(P, fps, sk)
    assert fs["mean_m_s"] < 1e-6 and 0.4 < fs["contact_share"] < 0.7
