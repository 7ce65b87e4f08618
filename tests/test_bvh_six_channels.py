"""BVH rigs with position channels on every joint (the Bandai Namco layout): read against an independent FK, folded
static roots, and the importer's checks (import error against the source, standing height, units)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from generation.formats.bvh import parse_bvh, read_bvh
from generation.mocap.importer import ImportOptions, import_file

# joint, parent, offset (cm; bones along local x as in the Bandai Namco rig: legs point down in the root's frame)
RIG = [
    ("joint_Root", None, (0, 0, 0)), ("Hips", "joint_Root", (0, 93.9, -3)),
    ("Spine", "Hips", (15.7, 0, 0)), ("Chest", "Spine", (9.0, -0.4, 0)), ("Neck", "Chest", (16.4, 0, 0)),
    ("Head", "Neck", (6.5, 0, 0)),
    ("Shoulder_L", "Chest", (13.0, -0.2, 5.0)), ("UpperArm_L", "Shoulder_L", (5.3, 0, 0)),
    ("LowerArm_L", "UpperArm_L", (24.3, 0, 0)), ("Hand_L", "LowerArm_L", (22.3, 0, 0)),
    ("Shoulder_R", "Chest", (13.0, -0.2, -5.0)), ("UpperArm_R", "Shoulder_R", (-5.3, 0, 0)),
    ("LowerArm_R", "UpperArm_R", (-24.3, 0, 0)), ("Hand_R", "LowerArm_R", (-22.3, 0, 0)),
    ("UpperLeg_L", "Hips", (-2.2, -6.5, 0)), ("LowerLeg_L", "UpperLeg_L", (39.1, 0, 0)),
    ("Foot_L", "LowerLeg_L", (41.0, 0, 0)), ("Toes_L", "Foot_L", (11.8, 0, 0)),
    ("UpperLeg_R", "Hips", (-2.2, 6.5, 0)), ("LowerLeg_R", "UpperLeg_R", (-39.1, 0, 0)),
    ("Foot_R", "LowerLeg_R", (-41.0, 0, 0)), ("Toes_R", "Foot_R", (-11.8, 0, 0)),
]
CHANNELS = "Xposition Yposition Zposition Zrotation Xrotation Yrotation"


def six_channel_take(n_frames: int = 60, stretch_knee_cm: float = 0.0, seed: int = 0):
    """A BVH text of RIG with six channels per joint, and its channel values (T, J, 6): a static placement root,
    hips that rise and fall by 4 cm and travel forward, the body turned to stand (legs down, spine and arms up),
    every other joint rotating a little."""
    rng = np.random.default_rng(seed)
    t = np.arange(n_frames) / 30.0
    values = np.zeros((n_frames, len(RIG), 6))
    for j, (_, _, offset) in enumerate(RIG):
        values[:, j, :3] = offset
        values[:, j, 3:] = rng.normal(0, 6, 3) * np.sin(2 * np.pi * (1.0 + 0.3 * j) * t)[:, None]
    values[:, 1, 0] = 40 * t                                  # Hips travel along x
    values[:, 1, 1] = 93.9 + 4 * np.sin(2 * np.pi * 1.8 * t)  # and bounce
    values[:, 0, 3:] = 0.0                                    # the placement root does not move
    values[:, 1, 3] += 90.0                                   # Zrotation: bones along +x now point up
    values[:, [n for n, *_ in RIG].index("UpperLeg_L"), 3] += 180.0   # the left leg's +x bones point down
    lower_leg = [n for n, *_ in RIG].index("LowerLeg_L")
    values[:, lower_leg, 0] += stretch_knee_cm * np.sin(2 * np.pi * 0.7 * t)
    values = np.round(values, 6)                              # as written to the file
    lines = ["HIERARCHY"]

    def emit(j: int, depth: int):
        name, _, offset = RIG[j]
        ind = "  " * depth
        lines.append(f"{ind}{'ROOT' if j == 0 else 'JOINT'} {name}")
        lines.extend([f"{ind}{{", f"{ind}  OFFSET {offset[0]} {offset[1]} {offset[2]}",
                      f"{ind}  CHANNELS 6 {CHANNELS}"])
        kids = [k for k, (_, parent, _) in enumerate(RIG) if parent == name]
        for k in kids:
            emit(k, depth + 1)
        if not kids:
            lines.extend([f"{ind}  End Site", f"{ind}  {{", f"{ind}    OFFSET 0 0 0", f"{ind}  }}"])
        lines.append(f"{ind}}}")

    emit(0, 0)
    lines += ["MOTION", f"Frames: {n_frames}", "Frame Time: 0.0333333"]
    lines += [" ".join(f"{v:.6f}" for v in row.ravel()) for row in values]
    return "\n".join(lines) + "\n", values


def independent_positions(values: np.ndarray) -> np.ndarray:
    """World positions (T, J, 3), cm, by scipy rotations: R = Rz Rx Ry (intrinsic ZXY), translation per frame."""
    names = [n for n, *_ in RIG]
    T, J = values.shape[:2]
    world_R = [None] * J
    world_P = np.zeros((T, J, 3))
    for j, (_, parent, _) in enumerate(RIG):
        local = Rotation.from_euler("ZXY", values[:, j, 3:], degrees=True)
        if parent is None:
            world_R[j], world_P[:, j] = local, values[:, j, :3]
        else:
            p = names.index(parent)
            world_R[j] = world_R[p] * local
            world_P[:, j] = world_P[:, p] + world_R[p].apply(values[:, j, :3])
    return world_P


def test_six_channel_rig_matches_an_independent_reading(tmp_path):
    text, values = six_channel_take()
    path = tmp_path / "six.bvh"
    path.write_text(text)
    expected = independent_positions(values)
    data = parse_bvh(path)
    assert data.names[1] == "Hips"
    np.testing.assert_allclose(data.global_positions(), expected, atol=1e-6)
    hips_y = data.global_positions(0.01)[:, 1, 1]
    assert np.ptp(hips_y) == pytest.approx(0.08, abs=0.005)   # the pelvis moves (it was frozen at one height)


def test_read_bvh_folds_the_static_root_into_the_hips(tmp_path):
    text, values = six_channel_take()
    path = tmp_path / "six.bvh"
    path.write_text(text)
    motion = read_bvh(path)
    assert motion.metadata["folded_root"] == "joint_Root" and motion.skeleton.joints[0] == "Hips"
    assert motion.metadata["bvh_scale"] == 0.01
    expected = independent_positions(values)[:, 1:] * 0.01
    np.testing.assert_allclose(motion.positions(), expected, atol=1e-6)
    assert "translation_residual_m" not in motion.metadata


def test_import_reports_error_height_and_passes(tmp_path):
    text, _ = six_channel_take()
    path = tmp_path / "six.bvh"
    path.write_text(text)
    for skeleton in ("gait", "gesture"):
        row = import_file(path, ImportOptions(skeleton=skeleton)).row
        assert row["status"] == "ok", row["message"]
        assert float(row["import_error_cm"]) < 3.0
        assert 1.6 < float(row["height_m"]) < 1.9    # hip height 0.9 m / 0.53


def test_wrong_units_are_an_error_row(tmp_path):
    text, _ = six_channel_take()
    path = tmp_path / "six.bvh"
    path.write_text(text)
    row = import_file(path, ImportOptions(skeleton="gait", scale=0.001)).row
    assert row["status"] == "error" and "standing height" in row["message"] and float(row["height_m"]) < 1.2


def test_a_body_the_solve_cannot_reproduce_is_an_error_row(tmp_path):
    text, _ = six_channel_take(stretch_knee_cm=12.0)     # the shin changes length by 12 cm within the take
    path = tmp_path / "stretch.bvh"
    path.write_text(text)
    row = import_file(path, ImportOptions(skeleton="gait")).row
    assert row["status"] == "error" and "import error" in row["message"]
    assert float(row["import_error_cm"]) > 3.0


def _knee_flexion_deg(P: np.ndarray, hip: int, knee: int, ankle: int) -> np.ndarray:
    u, v = P[:, hip] - P[:, knee], P[:, ankle] - P[:, knee]
    cos = (u * v).sum(-1) / np.linalg.norm(u, axis=-1) / np.linalg.norm(v, axis=-1)
    return 180.0 - np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def test_real_walk_keeps_its_knee_flexion_on_our_skeleton():
    """Our hips hang lower below the root than this rig's: the root is moved to the source hips, so the knees
    straighten as the actor's do instead of staying bent by the leg's missing reach."""
    from generation.mocap.bandai_namco import shipped_takes

    path = next(t.path for t in shipped_takes() if t.content == "walk" and t.style == "feminine")
    data = parse_bvh(path)
    n = data.names.index
    source = _knee_flexion_deg(data.global_positions(0.01), n("UpperLeg_L"), n("LowerLeg_L"), n("Foot_L"))
    motion = import_file(path, ImportOptions(skeleton="gait")).motion
    j = motion.skeleton.index
    ours = _knee_flexion_deg(motion.positions(), j("left_hip"), j("left_knee"), j("left_heel"))
    assert abs(np.median(ours) - np.median(source)) < 4.0
    assert ours.min() < source.min() + 5.0
