"""Rig name normalisation and automatic maps onto the gait and gesture skeletons (generation.mocap.rigs)."""
from __future__ import annotations

import json

import pytest

from generation.core.skeleton import gait_skeleton, gesture_skeleton
from generation.mocap.rigs import RigMapError, auto_joint_map, check_joint_map, load_joint_map, normalise


@pytest.mark.parametrize("name, key", [
    ("mixamorig:LeftUpLeg", "left_upleg"),
    ("mixamorig1:RightHandIndex1", "right_handindex1"),
    ("Bip01 L Thigh", "left_thigh"),
    ("Bip01_R_Calf", "right_calf"),
    ("Character1_LeftArm", "left_arm"),
    ("UpperArm_L", "left_upperarm"),
    ("ShoulderLeft", "left_shoulder"),
    ("lShldr", "left_shldr"),
    ("LEFT-FOOT", "left_foot"),
    ("Spine1", "spine1"),
    ("HeadTop_End", "headtopend"),
    ("Bip01", "bip01"),
])
def test_normalise_ignores_namespaces_separators_and_case(name, key):
    assert normalise(name) == key


CMU = ("Hips", "LHipJoint", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RHipJoint", "RightUpLeg",
       "RightLeg", "RightFoot", "RightToeBase", "LowerBack", "Spine", "Spine1", "Neck", "Neck1", "Head",
       "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand", "LeftFingerBase", "LeftHandIndex1", "LThumb",
       "RightShoulder", "RightArm", "RightForeArm", "RightHand", "RightFingerBase", "RightHandIndex1", "RThumb")
BIOVISION = ("Hips", "LeftHip", "LeftKnee", "LeftAnkle", "RightHip", "RightKnee", "RightAnkle", "Chest",
             "LeftCollar", "LeftShoulder", "LeftElbow", "LeftWrist", "RightCollar", "RightShoulder", "RightElbow",
             "RightWrist", "Neck", "Head")


def test_cmu_names_on_the_gait_skeleton():
    jm = auto_joint_map(CMU, gait_skeleton())
    assert jm["root"] == "Hips" and jm["lower_back"] == "LowerBack" and jm["spine"] == "Spine1"
    assert jm["left_shoulder"] == "LeftArm"            # LeftShoulder is CMU's clavicle
    assert jm["left_heel"] == "LeftFoot" and jm["left_toe"] == "LeftToeBase"
    assert jm["right_hand_index"] == "RightHandIndex1"
    check_joint_map(jm, CMU, gait_skeleton())


def test_biovision_shoulder_is_the_upper_arm_and_collar_the_clavicle():
    jm = auto_joint_map(BIOVISION, gesture_skeleton())
    assert jm["left_shoulder"] == "LeftShoulder" and jm["left_collar"] == "LeftCollar"
    assert jm["chest4"] == "Chest" and "chest" not in jm      # the one chest joint carries the arms
    assert jm["left_wrist"] == "LeftWrist"
    gait = auto_joint_map(BIOVISION, gait_skeleton())
    assert gait["spine"] == "Chest" and gait["left_hand"] == "LeftWrist"


def test_unreal_mannequin_names():
    names = ("root", "pelvis", "thigh_l", "calf_l", "foot_l", "ball_l", "thigh_r", "calf_r", "foot_r", "ball_r",
             "spine_01", "spine_02", "spine_03", "neck_01", "head", "clavicle_l", "upperarm_l", "lowerarm_l",
             "hand_l", "clavicle_r", "upperarm_r", "lowerarm_r", "hand_r")
    jm = auto_joint_map(names, gait_skeleton())
    assert jm["root"] == "pelvis" and jm["spine"] == "spine_03" and jm["lower_back"] == "spine_01"
    assert jm["left_shoulder"] == "upperarm_l" and jm["left_toe"] == "ball_l" and jm["neck"] == "neck_01"


def test_kinect_wrist_and_hand():
    names = ("SpineBase", "SpineMid", "SpineShoulder", "Neck", "Head", "ShoulderLeft", "ElbowLeft", "WristLeft",
             "HandLeft", "ShoulderRight", "ElbowRight", "WristRight", "HandRight", "HipLeft", "KneeLeft",
             "AnkleLeft", "FootLeft", "HipRight", "KneeRight", "AnkleRight", "FootRight")
    jm = auto_joint_map(names, gait_skeleton())
    assert len(jm) == 21
    assert jm["left_hand"] == "WristLeft" and jm["left_hand_index"] == "HandLeft"
    assert jm["left_heel"] == "AnkleLeft" and jm["left_toe"] == "FootLeft"


def test_unmappable_rig_lists_found_and_missing_joints_and_the_map_format():
    names = ("pelvis_jnt", "thigh_l", "calf_l", "Spine")
    jm = auto_joint_map(names, gait_skeleton())
    with pytest.raises(RigMapError) as err:
        check_joint_map(jm, names, gait_skeleton(), "odd.bvh")
    msg = str(err.value)
    assert "odd.bvh" in msg and "pelvis_jnt, thigh_l, calf_l, Spine" in msg
    assert "missing root, left_heel, right_hip" in msg and "--joint-map" in msg and "{our_joint: their_joint}" in msg


def test_joint_map_overrides(tmp_path):
    names = ("pelvis_jnt", "LeftUpLeg", "Spine")
    jm = auto_joint_map(names, gait_skeleton(), {"root": "pelvis_jnt", "spine": "spine"})
    assert jm["root"] == "pelvis_jnt" and jm["spine"] == "Spine" and jm["left_hip"] == "LeftUpLeg"
    with pytest.raises(RigMapError, match="not a joint of the gait skeleton"):
        auto_joint_map(names, gait_skeleton(), {"pelvis": "pelvis_jnt"})
    with pytest.raises(RigMapError, match="which the file does not have"):
        auto_joint_map(names, gait_skeleton(), {"root": "nothing"})
    good = tmp_path / "map.json"
    good.write_text(json.dumps({"root": "pelvis_jnt"}))
    assert load_joint_map(good) == {"root": "pelvis_jnt"}
    bad = tmp_path / "bad.json"
    bad.write_text('{"root": \n "pelvis_jnt",, }')
    with pytest.raises(RigMapError, match=r"bad.json: line 2"):
        load_joint_map(bad)
