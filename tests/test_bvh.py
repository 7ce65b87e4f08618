"""BVH reading, writing and retargeting."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from generation.core.motion import Motion, MotionFormatError
from generation.core.quaternion import np_qangle, np_qfrom_axis_angle, np_qnormalize
from generation.core.skeleton import Skeleton, gait_skeleton, gesture_skeleton
from generation.formats.bvh import read_bvh, write_bvh
from generation.mocap.retarget import leg_scale, retarget
from generation.mocap.rigs import auto_joint_map

torch.set_num_threads(1)

LEAF_NAMES = {"left_toe": "left_heel_end", "right_toe": "right_heel_end", "head": "neck_end",
              "left_hand_index": "left_hand_end", "right_hand_index": "right_hand_end"}


def random_motion(sk, T=25, seed=0, fps=30.0):
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=(T, sk.num_joints, 3))
    q = np_qfrom_axis_angle(axis, rng.uniform(-2.5, 2.5, size=(T, sk.num_joints)))
    q[:, 0] = np_qnormalize(rng.normal(size=(T, 4)))
    return Motion(sk, q, rng.normal(size=(T, 3)), fps, {})


@pytest.mark.parametrize("order", ["ZXY", "XYZ", "YZX"])
def test_write_read_round_trip(tmp_path, order):
    sk = gait_skeleton()
    m = random_motion(sk)
    path = tmp_path / "walk.bvh"
    write_bvh(m, path, rotation_order=order)
    back = read_bvh(path)
    assert back.skeleton.name == "walk"
    assert back.fps == pytest.approx(30.0, rel=1e-12)
    assert back.metadata["bvh_scale"] == 1.0
    idx = [back.skeleton.index(LEAF_NAMES.get(n, n)) for n in sk.joints]
    np.testing.assert_allclose(back.positions()[:, idx], m.positions(), atol=1e-6)
    np.testing.assert_allclose(back.skeleton.offsets[idx], sk.offsets, atol=1e-9)
    inner = [j for j, kids in enumerate(sk.children()) if kids]
    assert np_qangle(back.rotations[:, [idx[j] for j in inner]], m.rotations[:, inner]).max() < 1e-6


def test_round_trip_in_centimetres_and_gesture_skeleton(tmp_path):
    sk = gesture_skeleton(1.6, "female")
    m = random_motion(sk, seed=3, fps=120.0)
    path = tmp_path / "g.bvh"
    write_bvh(m, path, scale=100.0)
    back = read_bvh(path)                       # guessed from the 1.6 m body -> centimetres
    assert back.metadata["bvh_scale"] == 0.01
    assert back.fps == pytest.approx(120.0)
    names = {n: n for n in sk.joints}
    names.update({"head": "neck_end", "left_toe": "left_ankle_end", "right_toe": "right_ankle_end",
                  "left_wrist": "left_elbow_end", "right_wrist": "right_elbow_end"})
    idx = [back.skeleton.index(names[n]) for n in sk.joints]
    np.testing.assert_allclose(back.positions()[:, idx], m.positions(), atol=1e-6)


HAND_WRITTEN = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation
  JOINT Chest
  {
    OFFSET 0 10 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0 20 0
    }
  }
  JOINT Leg
  {
    OFFSET 0 -90 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0 0 0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.04
0 100 0 0 0 0 0 0 0 0 0 0
5 100 0 90 0 0 0 0 0 0 0 0
0 100 0 0 90 90 0 0 90 0 0 0
"""


def test_hand_written_xyz_file(tmp_path):
    path = tmp_path / "hand.bvh"
    path.write_text(HAND_WRITTEN)
    m = read_bvh(path, scale=0.01)
    sk = m.skeleton
    assert sk.joints == ("Hips", "Chest", "Chest_end", "Leg")   # zero-offset End Site dropped
    assert m.fps == pytest.approx(25.0)
    P = m.positions()
    chest, end = sk.index("Chest"), sk.index("Chest_end")
    np.testing.assert_allclose(P[0, chest], [0, 1.1, 0], atol=1e-9)
    np.testing.assert_allclose(P[0, end], [0, 1.3, 0], atol=1e-9)
    # frame 1: root at x = 5 cm, rotated 90 degrees about x: +y -> +z
    np.testing.assert_allclose(P[1, 0], [0.05, 1.0, 0], atol=1e-9)
    np.testing.assert_allclose(P[1, chest], [0.05, 1.0, 0.1], atol=1e-9)
    # frame 2: root R = Rx(0) Ry(90) Rz(90) (XYZ order): +y -> Rz: -x -> Ry: +z
    np.testing.assert_allclose(P[2, chest], [0, 1.0, 0.1], atol=1e-9)
    # Chest's own Rz(90) turns (0, 0.2, 0) to (-0.2, 0, 0); the root's Ry(90) Rz(90) maps that to (0, -0.2, 0)
    np.testing.assert_allclose(P[2, end], [0, 0.8, 0.1], atol=1e-9)
    # the opposite composition order would put the Chest at -x instead
    assert m.metadata["bvh_channels"]["Hips"][3:] == ["Xrotation", "Yrotation", "Zrotation"]


def malformed_cases():
    good = HAND_WRITTEN
    return [
        ("missing OFFSET", good.replace("  OFFSET 0 10 0", "  OFSET 0 10 0"), "line 8: expected 'OFFSET', got 'OFSET'"),
        ("bad number", good.replace("OFFSET 0 -90 0", "OFFSET 0 -9x0 0"),
         "line 17: expected a number for OFFSET of Leg"),
        ("unknown channel", good.replace("CHANNELS 3 Xrotation Yrotation Zrotation\n    End Site\n    {\n"
                                         "      OFFSET 0 20 0", "CHANNELS 3 Xrotation Yrotation Wrotation\n"
                                         "    End Site\n    {\n      OFFSET 0 20 0"), "line 9: unknown channel"),
        ("short frame", good.replace("5 100 0 90 0 0 0 0 0 0 0 0", "5 100 0 90 0 0 0 0 0 0 0"),
         "line 29: frame 1 has 11 values, expected 12"),
        ("frame count", good.replace("Frames: 3", "Frames: 4"), "'Frames: 4' but the file holds 3"),
        ("no hierarchy", good.replace("HIERARCHY", "HIERARCH"), "line 1: expected 'HIERARCHY'"),
        ("truncated", good.split("MOTION")[0][:-30], "unexpected end of file"),
        ("bad frame time", good.replace("Frame Time: 0.04", "Frame Time: 0"), "Frame Time must be from 0.001 to 1 s"),
        ("tiny frame time", good.replace("Frame Time: 0.04", "Frame Time: 1e-300"),
         "line 27: Frame Time must be from 0.001 to 1 s (1000 to 1 frames per second), got 1e-300"),
        ("long frame time", good.replace("Frame Time: 0.04", "Frame Time: 2"), "Frame Time must be from"),
        ("text in frame", good.replace("0 100 0 0 90 90", "0 100 0 0 ninety 90"),
         "line 30: frame 2: expected a number"),
        ("duplicate joint", good.replace("JOINT Leg", "JOINT Chest"), "duplicate joint name 'Chest'"),
    ]


@pytest.mark.parametrize("name,text,message", malformed_cases(), ids=[c[0] for c in malformed_cases()])
def test_malformed_files_rejected_with_line(tmp_path, name, text, message):
    path = tmp_path / "bad.bvh"
    path.write_text(text)
    with pytest.raises(MotionFormatError) as exc:
        read_bvh(path)
    assert str(path) in str(exc.value)
    assert message in str(exc.value)


def test_frame_time_limits_are_inclusive(tmp_path):
    for frame_time, fps in (("0.001", 1000.0), ("1", 1.0)):
        path = tmp_path / f"ok_{frame_time}.bvh"
        path.write_text(HAND_WRITTEN.replace("Frame Time: 0.04", f"Frame Time: {frame_time}"))
        assert read_bvh(path).fps == pytest.approx(fps)


def test_a_bvh_over_the_size_limit_is_refused_before_it_is_read(tmp_path, monkeypatch):
    from generation.formats import bvh as bvh_module

    path = tmp_path / "huge.bvh"
    with path.open("wb") as f:                     # 100 MB: a valid header, then a sparse hole of frame "lines"
        f.write(HAND_WRITTEN.encode())
        f.truncate(100 * 1000 * 1000)

    def no_read(*args, **kwargs):
        raise AssertionError("the file was read")

    monkeypatch.setattr(type(path), "read_text", no_read)
    with pytest.raises(MotionFormatError, match=r"huge.bvh: 95.4 MiB, larger than the BVH limit of 32 MiB"):
        read_bvh(path)
    monkeypatch.undo()
    small = tmp_path / "small.bvh"
    small.write_text(HAND_WRITTEN)
    with pytest.raises(MotionFormatError, match="larger than the BVH limit"):
        bvh_module.parse_bvh(small, max_bytes=100)
    assert bvh_module.parse_bvh(small, max_bytes=None).fps == pytest.approx(25.0)


def test_missing_file(tmp_path):
    with pytest.raises(MotionFormatError, match="cannot read"):
        read_bvh(tmp_path / "nope.bvh")


def test_retarget_onto_same_skeleton_is_exact():
    sk = gait_skeleton()
    m = random_motion(sk, seed=4)
    out = retarget(m, sk, {n: n for n in sk.joints})
    assert out.metadata["retarget"]["scale"] == pytest.approx(1.0)
    np.testing.assert_allclose(out.positions(), m.positions(), atol=1e-9)


def test_retarget_scales_to_target_and_fills_unmapped(tmp_path):
    src = gait_skeleton(1.75)
    tgt = gait_skeleton(1.5, "female")
    m = random_motion(src, seed=5)
    mapping = {n: n for n in src.joints if n != "lower_back"}
    out = retarget(m, tgt, mapping)
    def legs(sk):                                                       # thigh + shin
        return sk.bone_lengths()[sk.index("left_knee")] + sk.bone_lengths()[sk.index("left_heel")]

    scale = legs(tgt) / legs(src)                                       # our leg length / the source's
    assert leg_scale(m.positions(), src.joints, tgt, mapping) == pytest.approx(scale)
    assert out.metadata["retarget"]["scale"] == pytest.approx(scale)
    # the root moves so that the hips' midpoint lands on the scaled source's (rigs hang the hips at different
    # depths below the root; keeping the root would leave the legs short of the feet)
    hips = [src.index("left_hip"), src.index("right_hip")]
    np.testing.assert_allclose(out.positions()[:, hips].mean(1), m.positions()[:, hips].mean(1) * scale, atol=1e-9)
    # limbs of the same proportions land on the scaled source positions
    knee = src.index("left_knee")
    assert out.skeleton is tgt
    d_src = m.positions()[:, knee] - m.positions()[:, 0]
    d_out = out.positions()[:, knee] - out.positions()[:, 0]
    cos = (d_src * d_out).sum(-1) / np.linalg.norm(d_src, axis=-1) / np.linalg.norm(d_out, axis=-1)
    assert cos.min() > 0.99
    # foot IK puts the heels exactly on the scaled source heels (the random poses keep them reachable here
    # wherever the hip-heel distance fits the target leg)
    for side in ("left", "right"):
        heel, hip = src.index(f"{side}_heel"), src.index(f"{side}_hip")
        want = m.positions()[:, heel] * scale
        reach = np.linalg.norm(want - out.positions()[:, hip], axis=-1)
        ok = reach < tgt.bone_lengths()[heel] + tgt.bone_lengths()[src.index(f"{side}_knee")] - 1e-3
        assert ok.sum() > 5
        np.testing.assert_allclose(out.positions()[ok, heel], want[ok], atol=1e-9)
    plain = retarget(m, tgt, mapping, foot_ik=False)
    assert np.abs(plain.positions()[:, src.index("left_heel")] - m.positions()[:, src.index("left_heel")] * scale
                  ).max() > 1e-3
    with pytest.raises(ValueError, match="root"):
        retarget(m, tgt, {"left_knee": "left_knee"})
    with pytest.raises(KeyError, match="no joint"):
        retarget(m, tgt, {"root": "root", "left_knee": "LeftLeg"})


def test_the_default_joint_map_for_mixamo_names_is_the_rig_map():
    names = ("Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg", "RightFoot",
             "RightToeBase", "Spine", "Spine1", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm",
             "LeftForeArm", "LeftHand", "RightShoulder", "RightArm", "RightForeArm", "RightHand")
    parents = (-1, 0, 1, 2, 3, 0, 5, 6, 7, 0, 9, 10, 11, 12, 11, 14, 15, 16, 11, 18, 19, 20)
    src = Skeleton("mixamo", names, parents, np.ones((len(names), 3)))
    gait = auto_joint_map(src.joints, gait_skeleton())
    assert gait["root"] == "Hips" and gait["left_knee"] == "LeftLeg" and gait["left_shoulder"] == "LeftArm"
    assert gait["spine"] == "Spine2" and gait["lower_back"] == "Spine"
    gesture = auto_joint_map(src.joints, gesture_skeleton())
    assert gesture["left_collar"] == "LeftShoulder" and gesture["left_wrist"] == "LeftHand"
    assert gesture["chest4"] == "Spine2" and "chest3" not in gesture        # the top spine joint carries the arms


def test_mixamo_named_bvh_retargets_onto_gait_with_default_map(tmp_path):
    sk = gait_skeleton()
    m = random_motion(sk, seed=6)
    path = tmp_path / "mixamo.bvh"
    write_bvh(m, path, scale=100.0)
    rename = {"root": "Hips", "lower_back": "Spine", "spine": "Spine2", "neck": "Neck"}
    for side, Side in (("left", "Left"), ("right", "Right")):
        rename.update({f"{side}_hip": f"{Side}UpLeg", f"{side}_knee": f"{Side}Leg", f"{side}_heel": f"{Side}Foot",
                       f"{side}_shoulder": f"{Side}Arm", f"{side}_elbow": f"{Side}ForeArm",
                       f"{side}_hand": f"{Side}Hand"})
    text = path.read_text()
    for ours, theirs in rename.items():
        text = text.replace(f"ROOT {ours}\n", f"ROOT {theirs}\n").replace(f"JOINT {ours}\n", f"JOINT {theirs}\n")
    path.write_text(text)
    src = read_bvh(path)
    assert "LeftUpLeg" in src.skeleton.joints and src.metadata["bvh_scale"] == 0.01
    out = retarget(src, gait_skeleton())
    mapping = out.metadata["retarget"]["joint_map"]
    assert len(mapping) == 21 and mapping["left_toe"] == "LeftFoot_end" and mapping["head"] == "Neck_end"
    np.testing.assert_allclose(out.positions(), m.positions(), atol=1e-6)
