"""Quaternion algebra, forward kinematics, skeletons and the Motion type."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from generation.core import quaternion as Q
from generation.core.kinematics import forward_kinematics, np_forward_kinematics
from generation.core.motion import Motion, MotionFormatError
from generation.core.skeleton import gait_skeleton, gesture_skeleton


def random_unit_quaternions(shape, seed=0):
    rng = np.random.default_rng(seed)
    q = rng.normal(size=tuple(shape) + (4,))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def test_qrot_matches_rotation_matrix():
    q = random_unit_quaternions((50,))
    v = np.random.default_rng(1).normal(size=(50, 3))
    expected = np.einsum("nij,nj->ni", Q.np_qto_matrix(q), v)
    np.testing.assert_allclose(Q.np_qrot(q, v), expected, atol=1e-12)


def test_qmul_composes_rotations():
    q, r = random_unit_quaternions((20,), 2), random_unit_quaternions((20,), 3)
    v = np.random.default_rng(4).normal(size=(20, 3))
    np.testing.assert_allclose(Q.np_qrot(Q.np_qmul(q, r), v), Q.np_qrot(q, Q.np_qrot(r, v)), atol=1e-12)


@pytest.mark.parametrize("order", ["xyz", "yzx", "zxy", "xzy", "yxz", "zyx"])
def test_euler_round_trip(order):
    rng = np.random.default_rng(5)
    angles = rng.uniform(-1.2, 1.2, size=(100, 3))
    q = Q.np_qfrom_euler(angles, order=order)
    np.testing.assert_allclose(Q.np_qeuler(q, order=order), angles, atol=1e-6)


def test_qbetween_maps_u_onto_v_including_opposites():
    u = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 2.0]])
    v = np.array([[0, 3.0, 0], [0, -1.0, 0], [1.0, 1.0, 0]])
    q = Q.np_qbetween(u, v)
    rotated = Q.np_qrot(q, u / np.linalg.norm(u, axis=-1, keepdims=True))
    np.testing.assert_allclose(rotated, v / np.linalg.norm(v, axis=-1, keepdims=True), atol=1e-9)


def test_slerp_endpoints_and_midpoint_angle():
    q0, q1 = Q.identity(), Q.np_qfrom_axis_angle(np.array([0, 1.0, 0]), np.array(1.0))
    np.testing.assert_allclose(Q.np_qslerp(q0, q1, 0.0), q0, atol=1e-12)
    np.testing.assert_allclose(Q.np_qslerp(q0, q1, 1.0), q1, atol=1e-12)
    mid = Q.np_qslerp(q0, q1, 0.5)
    assert Q.np_qangle(q0, mid) == pytest.approx(0.5, abs=1e-9)


@pytest.mark.parametrize("factory", [gait_skeleton, gesture_skeleton])
def test_identity_pose_is_rest_pose_and_feet_touch_ground(factory):
    skeleton = factory()
    root = np.array([0.0, skeleton.root_height(), 0.0])
    pos = np_forward_kinematics(Q.identity((skeleton.num_joints,)), root, skeleton)
    np.testing.assert_allclose(pos - root, skeleton.rest_positions(), atol=1e-12)
    assert pos[:, 1].min() == pytest.approx(0.0, abs=1e-9)
    assert pos[:, 1].max() > 1.5  # head of a 1.75 m body


def test_fk_preserves_bone_lengths_and_is_differentiable():
    skeleton = gait_skeleton()
    rot = torch.tensor(random_unit_quaternions((3, 7, skeleton.num_joints)), requires_grad=True)
    root = torch.zeros(3, 7, 3, dtype=torch.float64)
    pos = forward_kinematics(rot, root, torch.tensor(skeleton.offsets), skeleton.parents)
    assert pos.shape == (3, 7, skeleton.num_joints, 3)
    parents = np.array(skeleton.parents[1:])
    lengths = (pos[..., 1:, :] - pos[..., parents, :]).norm(dim=-1)
    np.testing.assert_allclose(lengths.detach().numpy(), np.broadcast_to(skeleton.bone_lengths()[1:], lengths.shape),
                               atol=1e-12)
    pos.sum().backward()
    assert rot.grad is not None and torch.isfinite(rot.grad).all()


def test_body_builds_and_heights_scale():
    tall, short = gait_skeleton(1.9), gait_skeleton(1.6)
    assert np.ptp(tall.rest_positions()[:, 1]) / np.ptp(short.rest_positions()[:, 1]) == pytest.approx(1.9 / 1.6)
    male, female = gesture_skeleton(build="male"), gesture_skeleton(build="female")
    ls, rs = male.index("left_shoulder"), male.index("right_shoulder")
    width = lambda s: np.linalg.norm(s.rest_positions()[ls] - s.rest_positions()[rs])  # noqa: E731
    assert width(female) < width(male)
    with pytest.raises(ValueError, match="build"):
        gait_skeleton(build="robot")


def test_mirror_map_pairs_left_and_right():
    skeleton = gait_skeleton()
    mirror = skeleton.mirror_map()
    assert skeleton.joints[mirror[skeleton.index("left_hand")]] == "right_hand"
    assert mirror[skeleton.index("head")] == skeleton.index("head")
    np.testing.assert_array_equal(mirror[mirror], np.arange(skeleton.num_joints))


def test_motion_npz_round_trip_and_resample(tmp_path):
    skeleton = gesture_skeleton(build="female")
    motion = Motion(skeleton, random_unit_quaternions((12, skeleton.num_joints), 7),
                    np.linspace([0, 1, 0], [1, 1, 2], 12), 30.0, {"origin": "generated", "synthetic": True})
    path = tmp_path / "m.npz"
    motion.save_npz(path)
    loaded = Motion.load_npz(path)
    np.testing.assert_array_equal(loaded.rotations, motion.rotations)
    assert loaded.metadata == motion.metadata and loaded.skeleton.build == "female"
    fast = motion.resample(60.0)
    assert fast.num_frames == 23
    np.testing.assert_allclose(fast.positions()[::2], motion.normalized().positions(), atol=1e-9)


def _swinging_arm(fps: float, seconds: float = 4.0) -> Motion:
    """A gait skeleton whose shoulders swing about x at 1 Hz (+-30 degrees, the arms of a walk) while the root
    walks 1.4 m/s."""
    skeleton = gait_skeleton()
    t = np.arange(int(seconds * fps) + 1) / fps
    half = 0.5 * np.radians(30.0) * np.sin(2 * np.pi * 1.0 * t)
    q = np.zeros((len(t), skeleton.num_joints, 4))
    q[..., 0] = 1.0
    arms = [k for k, name in enumerate(skeleton.joints) if "shoulder" in name]
    q[:, arms, 0], q[:, arms, 1] = np.cos(half)[:, None], np.sin(half)[:, None]
    root = np.stack([np.zeros_like(t), 0.9 + 0.02 * np.sin(2 * np.pi * 2 * t), 1.4 * t], -1)
    return Motion(skeleton, q, root, fps)


def test_smooth_resample_keeps_the_key_poses_and_removes_the_knot_jerk():
    from generation.quality.metrics import mean_jerk

    keys, truth = _swinging_arm(7.5), _swinging_arm(30.0)
    linear, smooth = keys.resample(30.0), keys.resample(30.0, smooth=True)
    assert smooth.num_frames == linear.num_frames == truth.num_frames
    np.testing.assert_allclose(smooth.positions()[::4], keys.positions(), atol=1e-9)   # through every key pose
    jerk = {name: mean_jerk(m.positions(), 30.0) for name, m in
            (("truth", truth), ("linear", linear), ("smooth", smooth))}
    assert jerk["linear"] > 3 * jerk["truth"]                  # velocity jumps at each 7.5 Hz key
    assert jerk["smooth"] < 1.5 * jerk["truth"]
    err = np.abs(smooth.positions() - truth.positions()).max()
    assert err < 0.5 * np.abs(linear.positions() - truth.positions()).max()


def test_smooth_resample_agrees_with_scipys_rotation_spline():
    from scipy.spatial.transform import Rotation, RotationSpline

    keys = _swinging_arm(7.5)
    ours = keys.resample(30.0, smooth=True)
    t_keys, t_out = np.arange(keys.num_frames) / 7.5, np.arange(ours.num_frames) / 30.0
    arm = keys.skeleton.joints.index("left_shoulder")
    ref = RotationSpline(t_keys, Rotation.from_quat(keys.rotations[:, arm][:, [1, 2, 3, 0]]))(t_out)
    ref_wxyz = ref.as_quat()[:, [3, 0, 1, 2]]
    angle = 2 * np.degrees(np.arccos(np.clip(np.abs((ref_wxyz * ours.rotations[:, arm]).sum(-1)), 0, 1)))
    assert angle.max() < 1.0 and angle.mean() < 0.2         # degrees, on a 60-degree swing


def test_smooth_resample_of_a_short_motion_falls_back_to_slerp():
    m = _swinging_arm(7.5, seconds=0.3)                      # 3 frames: too few for a cubic
    np.testing.assert_allclose(m.resample(30.0, smooth=True).rotations, m.resample(30.0).rotations)


def test_motion_rejects_bad_shapes_and_files(tmp_path):
    skeleton = gait_skeleton()
    with pytest.raises(MotionFormatError, match="rotations must be"):
        Motion(skeleton, np.zeros((5, 3, 4)), np.zeros((5, 3)), 30)
    bad = tmp_path / "bad.npz"
    np.savez(bad, rotations=np.zeros((1, 21, 4)))
    with pytest.raises(MotionFormatError, match="missing field 'root_positions'"):
        Motion.load_npz(bad)
    (tmp_path / "junk.npz").write_text("not a zip")
    with pytest.raises(MotionFormatError, match="not a readable"):
        Motion.load_npz(tmp_path / "junk.npz")
