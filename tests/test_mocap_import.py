"""One file -> Motion (generation.mocap.importer): every naming convention, positions, units, labels, errors.

Fixtures are written here: our own procedural motions re-exported under each rig's names, with the rig's extra
joints, a T-pose rest and centimetre units (tests/mocap_conventions.py), so the original positions are the
ground truth of the import.
"""
from __future__ import annotations

import re

import numpy as np
import pytest

from generation.core.motion import Motion
from generation.core.quaternion import np_qmul
from generation.core.skeleton import Skeleton, gait_skeleton
from generation.formats.bvh import write_bvh
from generation.mocap.importer import ImportOptions, import_file
from generation.mocap.labels import Label, LabelError, compile_pattern, label_from_pattern, read_labels
from generation.mocap.positions import LAYOUTS
from generation.procedural.gesture import GestureParams, seated_gesture
from generation.procedural.walk import WalkParams, walk
from protocol.vocabulary import GAIT_EMOTIONS, GESTURE_VAD
from tests.mocap_conventions import CONVENTIONS, convention_motion, export_as

EG16 = ("root", "spine", "neck", "head", "left_shoulder", "left_elbow", "left_hand", "right_shoulder",
        "right_elbow", "right_hand", "left_hip", "left_knee", "left_heel", "right_hip", "right_knee", "right_heel")


@pytest.fixture(scope="module")
def walk_motion():
    return walk(WalkParams(torso_pitch_rad=0.15, arm_swing_rad=0.5), n_frames=40)


@pytest.fixture(scope="module")
def gesture_motion():
    return seated_gesture(GestureParams(kind="descriptive", torso_lean=0.3, amplitude=1.4), n_frames=40)


@pytest.mark.parametrize("convention", sorted(CONVENTIONS["gait"]))
def test_each_convention_recovers_gait_positions(tmp_path, walk_motion, convention):
    path = export_as(walk_motion, convention, tmp_path / f"{convention}.bvh")
    result = import_file(path, ImportOptions(skeleton="gait"))
    assert result.row["status"] == "ok", result.row["message"]
    m = result.motion
    assert m.skeleton.name == "gait" and m.num_frames == 40
    err = np.linalg.norm(m.positions() - walk_motion.positions(), axis=-1)
    assert err.max() < 0.02
    assert result.row["mapped_joints"] == 21 and result.row["unmapped_joints"] == ""
    assert m.metadata["unit_guess"] == "centimetres" and m.metadata["up_axis"] == "+y"
    assert m.metadata["synthetic"] is False and m.metadata["origin"] == "captured"
    assert m.metadata["source"] == f"{convention}.bvh"


@pytest.mark.parametrize("convention", sorted(CONVENTIONS["gesture"]))
def test_each_convention_recovers_gesture_positions(tmp_path, gesture_motion, convention):
    path = export_as(gesture_motion, convention, tmp_path / f"{convention}.bvh")
    result = import_file(path, ImportOptions(skeleton="gesture"))
    assert result.row["status"] == "ok", result.row["message"]
    err = np.linalg.norm(result.motion.positions() - gesture_motion.positions(), axis=-1)
    assert err.max() < 0.02


def test_other_proportions_keep_the_feet(tmp_path):
    small = walk(WalkParams(), n_frames=30, skeleton=gait_skeleton(1.55, "female"))
    path = export_as(small, "mixamo", tmp_path / "small.bvh", tpose=False)
    result = import_file(path, ImportOptions(skeleton="gait"))
    m = result.motion
    heels = [m.skeleton.index("left_heel"), m.skeleton.index("right_heel")]
    scale = m.metadata["retarget"]["scale"]
    assert scale == pytest.approx(1.75 / 1.55, rel=0.03)
    np.testing.assert_allclose(m.positions()[:, heels], small.positions()[:, heels] * scale, atol=1e-6)
    assert 0.0 < float(result.row["retarget_max_error_m"]) < 0.1
    assert float(result.row["height_m"]) == pytest.approx(small.skeleton.height, rel=0.15)


def test_emotion_gait_positions_z_up_millimetres(tmp_path, walk_motion):
    sk = walk_motion.skeleton
    Q = walk_motion.positions()[:, [sk.index(n) for n in EG16]]
    z_up = Q @ np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]]).T
    np.save(tmp_path / "eg.npy", (z_up * 1000).reshape(len(Q), -1))
    result = import_file(tmp_path / "eg.npy", ImportOptions(skeleton="gait", layout="emotion-gait-16",
                                                            input_fps=25))
    assert result.row["status"] == "ok", result.row["message"]
    m = result.motion
    assert m.metadata["up_axis"] == "+z" and m.metadata["unit_guess"] == "millimetres" and m.fps == 25
    err = np.linalg.norm(m.positions()[:, [sk.index(n) for n in EG16]] - Q, axis=-1)
    assert err.max() < 0.02
    assert result.row["mapped_joints"] == 16


def test_csv_with_header_onto_gesture(tmp_path, walk_motion):
    P = walk_motion.positions()[:10] * 100
    names = ["Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "RightUpLeg", "RightLeg", "RightFoot", "Spine2", "Neck",
             "Head", "LeftArm", "LeftForeArm", "LeftHand", "RightArm", "RightForeArm", "RightHand"]
    ours = ["root", "left_hip", "left_knee", "left_heel", "right_hip", "right_knee", "right_heel", "spine", "neck",
            "head", "left_shoulder", "left_elbow", "left_hand", "right_shoulder", "right_elbow", "right_hand"]
    cols = [walk_motion.skeleton.index(n) for n in ours]
    header = "frame," + ",".join(f"{n}_{a}" for n in names for a in "xyz")
    rows = [f"{t}," + ",".join(f"{v:.6f}" for v in P[t, cols].reshape(-1)) for t in range(10)]
    (tmp_path / "take.csv").write_text("\n".join([header, *rows]) + "\n")
    result = import_file(tmp_path / "take.csv", ImportOptions(skeleton="gesture", fps=15))
    assert result.row["status"] == "ok", result.row["message"]
    assert result.motion.skeleton.name == "gesture" and result.motion.fps == 15
    assert result.motion.metadata["source_fps"] == 30
    m = result.motion.resample(30)   # back on the source frames: the ankles land on the (scaled) source heels
    ankle, scale = m.skeleton.index("left_ankle"), m.metadata["retarget"]["scale"]
    np.testing.assert_allclose(m.positions()[::2, ankle], P[::2, cols[3]] / 100 * scale, atol=1e-6)


def test_malformed_files_name_file_and_line(tmp_path, walk_motion):
    good = export_as(walk_motion, "cmu", tmp_path / "good.bvh").read_text().splitlines()
    assert good[4].startswith("\tCHANNELS 6")
    good[4] = "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Qrotation"
    (tmp_path / "bad.bvh").write_text("\n".join(good))
    row = import_file(tmp_path / "bad.bvh", ImportOptions()).row
    assert row["status"] == "error" and re.search(r"bad\.bvh: line 5: unknown channel 'Qrotation'", row["message"])
    (tmp_path / "bad.csv").write_text("Hips_x,Hips_y,Hips_z\n1,2,3\n1,oops,3\n")
    row = import_file(tmp_path / "bad.csv", ImportOptions()).row
    assert "bad.csv: line 3: column 2: expected a number, got 'oops'" in row["message"]
    np.save(tmp_path / "nolayout.npy", np.zeros((3, 48)))
    row = import_file(tmp_path / "nolayout.npy", ImportOptions()).row
    assert "nolayout.npy" in row["message"] and "--layout" in row["message"]


def test_unmappable_rig_is_a_report_row(tmp_path):
    (tmp_path / "odd.csv").write_text("pelvis_jnt_x,pelvis_jnt_y,pelvis_jnt_z,knee_jnt_x,knee_jnt_y,knee_jnt_z\n"
                                      "0,1,0,0,0.5,0\n")
    row = import_file(tmp_path / "odd.csv", ImportOptions()).row
    assert row["status"] == "error"
    assert "Joints found in the file: pelvis_jnt, knee_jnt" in row["message"] and "--joint-map" in row["message"]


def test_labels_csv_vector_category_and_pattern(tmp_path):
    (tmp_path / "labels.csv").write_text(
        "source," + ",".join(GAIT_EMOTIONS) + ",emotion\n"
        "a.bvh,2,0,0,2,\n"
        "b,,,,,proud\n")
    labels = read_labels(tmp_path / "labels.csv")
    assert labels["a.bvh"].metadata("gait")["emotion"] == dict(zip(GAIT_EMOTIONS, (0.5, 0.0, 0.0, 0.5)))
    proud = labels["b"].metadata("gesture")
    assert proud["emotion_label"] == "proud" and proud["vad"] == list(GESTURE_VAD["proud"])
    with pytest.raises(LabelError, match="not one of"):
        labels["b"].metadata("gait")
    sad = label_from_pattern(compile_pattern(r"_(?P<emotion>[a-z]+)_\d+"), tmp_path / "actor1_sad_03.bvh")
    assert sad == Label("sad")
    assert sad.metadata("gait")["emotion"]["sad"] == 1.0
    (tmp_path / "bad.csv").write_text("source,emotion\nx.bvh,gleeful\n")
    with pytest.raises(LabelError, match=r"bad.csv: line 2: emotion 'gleeful'"):
        read_labels(tmp_path / "bad.csv")
    with pytest.raises(LabelError, match="named group"):
        compile_pattern(r"(\w+)")


def test_z_up_bvh_in_metres(tmp_path, walk_motion):
    """A BVH whose offsets, root path and rotations are all z-up (3ds Max style), in metres."""
    m = convention_motion(walk_motion, "biped")
    q = np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0])     # +90 deg about x: y -> z
    R = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])
    q_inv = q * np.array([1.0, -1, -1, -1])
    rot = np_qmul(np_qmul(np.broadcast_to(q, m.rotations.shape), m.rotations),
                  np.broadcast_to(q_inv, m.rotations.shape))
    sk = Skeleton(m.skeleton.name, m.skeleton.joints, m.skeleton.parents, m.skeleton.offsets @ R.T)
    write_bvh(Motion(sk, rot, m.root_positions @ R.T, m.fps, {}), tmp_path / "zup.bvh")
    result = import_file(tmp_path / "zup.bvh", ImportOptions(skeleton="gait"))
    assert result.row["status"] == "ok", result.row["message"]
    assert result.motion.metadata["up_axis"] == "+z" and result.motion.metadata["unit_guess"] == "metres"
    assert np.linalg.norm(result.motion.positions() - walk_motion.positions(), axis=-1).max() < 0.02


def test_kinect_layout_csv_without_header(tmp_path, walk_motion):
    ours = {"SpineBase": "root", "SpineMid": "lower_back", "Neck": "neck", "Head": "head", "SpineShoulder": "spine"}
    for side, s in (("Left", "left"), ("Right", "right")):
        ours.update({f"Shoulder{side}": f"{s}_shoulder", f"Elbow{side}": f"{s}_elbow", f"Wrist{side}": f"{s}_hand",
                     f"Hand{side}": f"{s}_hand_index", f"HandTip{side}": f"{s}_hand_index",
                     f"Thumb{side}": f"{s}_hand_index", f"Hip{side}": f"{s}_hip", f"Knee{side}": f"{s}_knee",
                     f"Ankle{side}": f"{s}_heel", f"Foot{side}": f"{s}_toe"})
    sk = walk_motion.skeleton
    P = walk_motion.positions()[:, [sk.index(ours[n]) for n in LAYOUTS["kinect-v2"]]]
    np.savetxt(tmp_path / "kinect.csv", P.reshape(len(P), -1), delimiter=",", fmt="%.7f")
    result = import_file(tmp_path / "kinect.csv", ImportOptions(skeleton="gait", layout="kinect-v2"))
    assert result.row["status"] == "ok", result.row["message"]
    assert result.row["mapped_joints"] == 21
    assert np.linalg.norm(result.motion.positions() - walk_motion.positions(), axis=-1).max() < 0.02
