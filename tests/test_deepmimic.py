"""DeepMimic reader and the captured walks retargeted onto the gait skeleton."""
from __future__ import annotations

import json

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from generation.core.features import detect_foot_contacts, foot_skate, movement_features, np_gait_affective_features
from generation.core.motion import MotionFormatError
from generation.core.skeleton import GAIT_JOINTS
from generation.formats.deepmimic import DATA_DIR, deepmimic_skeleton, read_deepmimic
from generation.mocap.captured import WALK_FILES, captured_walks, chain_clip_repeats, load_captured_walk

torch.set_num_threads(1)

# humanoid.urdf joint origins (DeepMimic axes: x forward, y up, z right), before the 0.25 scale
URDF = {"chest": ("root", (0, 0.944604, 0)), "neck": ("chest", (0, 0.895576, 0)),
        "right_hip": ("root", (0, 0, 0.339548)), "right_knee": ("right_hip", (0, -1.686184, 0)),
        "right_ankle": ("right_knee", (0, -1.639480, 0)), "right_shoulder": ("chest", (-0.0962, 0.974, 0.73244)),
        "right_elbow": ("right_shoulder", (0, -1.099152, 0)), "right_wrist": ("right_elbow", (0, -1.035788, 0)),
        "left_hip": ("root", (0, 0, -0.339548)), "left_knee": ("left_hip", (0, -1.686184, 0)),
        "left_ankle": ("left_knee", (0, -1.639480, 0)), "left_shoulder": ("chest", (-0.0962, 0.974, -0.73244)),
        "left_elbow": ("left_shoulder", (0, -1.099152, 0)), "left_wrist": ("left_elbow", (0, -1.035788, 0))}
LAYOUT = [("root", 4), ("chest", 4), ("neck", 4), ("right_hip", 4), ("right_knee", 1), ("right_ankle", 4),
          ("right_shoulder", 4), ("right_elbow", 1), ("left_hip", 4), ("left_knee", 1), ("left_ankle", 4),
          ("left_shoulder", 4), ("left_elbow", 1)]


def reference_positions(frame):
    """Independent DeepMimic FK of one raw frame with scipy rotations, in DeepMimic axes."""
    local = {}
    col = 4
    for name, n in LAYOUT:
        v = frame[col:col + n]
        local[name] = (Rotation.from_quat([v[1], v[2], v[3], v[0]]) if n == 4
                       else Rotation.from_rotvec([0, 0, v[0]]))
        col += n
    local["right_wrist"] = local["left_wrist"] = Rotation.identity()
    glob = {"root": local["root"]}
    pos = {"root": np.array(frame[1:4])}
    for name, (parent, off) in URDF.items():
        pos[name] = pos[parent] + glob[parent].apply(np.array(off) * 0.25)
        glob[name] = glob[parent] * local[name]
    return pos


def turn(p):
    return np.array([-p[2], p[1], p[0]])


def test_reader_matches_independent_forward_kinematics():
    path = DATA_DIR / "humanoid3d_walk.txt"
    raw = json.loads(path.read_text())["Frames"]
    m = read_deepmimic(path)
    assert m.num_frames == 39 and m.fps == pytest.approx(30.0, rel=1e-3)
    assert m.metadata["loop"] == "wrap"
    P = m.positions()
    for t in (0, 11, 27):
        ref = reference_positions(raw[t])
        for name, p in ref.items():
            np.testing.assert_allclose(P[t, m.skeleton.index(name)], turn(p), atol=1e-9, err_msg=f"{t} {name}")


def test_skeleton_from_urdf():
    sk = deepmimic_skeleton()
    assert sk.num_joints == 18
    assert sk.offsets[sk.index("left_hip")] == pytest.approx([0.084887, 0, 0], abs=1e-6)   # left = +x
    assert sk.offsets[sk.index("left_toe")][2] > 0.1                                      # toes forward (+z)
    assert 1.4 < sk.height < 1.7


def write(tmp_path, obj, name="m.txt"):
    path = tmp_path / name
    path.write_text(json.dumps(obj) if not isinstance(obj, str) else obj)
    return path


def good_frame():
    return json.loads((DATA_DIR / "humanoid3d_walk.txt").read_text())["Frames"][0]


@pytest.mark.parametrize("obj,message", [
    ("{not json", "not valid JSON"),
    ([1, 2], "expected a JSON object"),
    ({"Loop": "wrap"}, "missing key 'Frames'"),
    ({"Loop": "wrap", "Frames": [], "Extra": 1}, "unknown keys ['Extra']"),
    ({"Loop": "sometimes", "Frames": [[0.0] * 44]}, "'Loop' must be"),
    ({"Frames": []}, "non-empty list"),
    ({"Frames": [good_frame(), good_frame()[:43]]}, "frame 1 has 43 values, expected 44"),
    ({"Frames": [good_frame()[:5] + ["x"] + good_frame()[6:]]}, "frame 0, root_rotation[1]: not a finite number"),
    ({"Frames": [good_frame()[:20] + [None] + good_frame()[21:]]}, "frame 0, right_knee_angle"),
    ({"Frames": [good_frame()[:8] + [3.0] + good_frame()[9:]]}, "frame 0, chest_rotation: quaternion norm"),
    ({"Frames": [[-0.1] + good_frame()[1:]]}, "frame 0, frame_duration: negative"),
])
def test_malformed_files(tmp_path, obj, message):
    path = write(tmp_path, obj)
    with pytest.raises(MotionFormatError) as exc:
        read_deepmimic(path)
    assert str(path) in str(exc.value) and message in str(exc.value)


def test_captured_walks_metadata_and_shape():
    walks = captured_walks()
    assert len(walks) == len(WALK_FILES) == 6
    for m in walks:
        assert m.skeleton.joints == GAIT_JOINTS
        md = m.metadata
        assert md["origin"] == "captured" and md["synthetic"] is False and md["license"] == "MIT"
        assert md["emotion_labels"] is None and "CMU" in md["credit"] and md["source"].endswith(".txt")
        assert m.fps == pytest.approx(30.0, rel=1e-3) and m.num_frames >= 38


def test_captured_walks_look_like_walks():
    for m in captured_walks():
        P = m.positions()
        sk = m.skeleton
        name = m.metadata["source"]
        # upright: head above neck above root above knees above heels, in every frame
        for upper, lower in (("head", "neck"), ("neck", "root"), ("root", "left_knee"), ("left_knee", "left_heel"),
                             ("root", "right_knee")):
            assert (P[:, sk.index(upper), 1] > P[:, sk.index(lower), 1]).all(), (name, upper, lower)
        # feet on the ground: nothing below it, and in every frame some foot joint within 4 cm of it
        feet = [sk.index(n) for n in ("left_heel", "left_toe", "right_heel", "right_toe")]
        assert P[..., 1].min() == pytest.approx(0.0, abs=1e-9)
        assert P[:, feet, 1].min(1).max() < 0.04, name
        # walking speed of a person, and legs alternating: each foot lands once while the other swings
        speed = np.linalg.norm(P[-1, 0, [0, 2]] - P[0, 0, [0, 2]]) / m.duration
        assert 0.7 < speed < 1.5, (name, speed)
        c = detect_foot_contacts(P, m.fps, sk)
        assert 0.3 < c[:, 0].mean() < 0.8 and 0.3 < c[:, 1].mean() < 0.8, name
        assert (c[:, 0] ^ c[:, 1]).mean() > 0.5, name                    # mostly single support
        assert foot_skate(P, m.fps, sk)["mean_m_s"] < 0.15, name
        assert np.isfinite(np_gait_affective_features(P)).all()


def test_turns_turn_the_right_way():
    walks = {m.metadata["source"].rsplit("/", 1)[-1]: m for m in captured_walks()}
    for name, sign in (("turn_left0.txt", 1), ("turn_left1.txt", 1), ("turn_right0.txt", -1),
                       ("turn_right1.txt", -1)):
        m = walks[name]
        mf = movement_features(m.positions(), m.fps, m.skeleton, root_rotations=m.rotations[:, 0])
        assert sign * np.median(mf["curvature"]) > 0.2, name
        assert sign * m.root_positions[-1, 0] > 0.2, name   # left = +x


def test_step_phase_of_loopable_cycle_and_repeat():
    m = load_captured_walk("humanoid3d_walk.txt")
    mf = movement_features(m.positions(), m.fps, m.skeleton, cyclic=True)
    omega = mf["step_frequency"]
    assert np.all(omega > 0.1) and np.all(omega < 0.25)              # about one stride per 1.3 s
    long = chain_clip_repeats(m, 4)
    assert long.num_frames == 4 * m.num_frames
    P = long.positions()
    dist = np.linalg.norm(P[-1, 0, [0, 2]] - P[0, 0, [0, 2]])
    assert 4.2 < dist < 5.6
    step = np.linalg.norm(np.diff(P[:, 0, [0, 2]], axis=0), axis=1)
    assert step.max() < 2.5 * np.median(step)                        # no jumps at the seams
    c = detect_foot_contacts(P, long.fps, long.skeleton)
    onsets = np.nonzero(c[1:, 0] & ~c[:-1, 0])[0]
    assert len(onsets) >= 3
