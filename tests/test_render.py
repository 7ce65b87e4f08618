"""Renderer: frames are drawn, fresh every frame, files are complete, the camera frames the motion."""
from __future__ import annotations

import numpy as np
import pytest

from generation.core.motion import Motion
from generation.core.skeleton import gait_skeleton, gesture_skeleton
from generation.render import RenderSettings, RenderSettingsError, contact_sheet, render_clip, render_frames
from generation.render.camera import fit_distance, fixed_camera, view_offset
from generation.render.clip import plan_cameras, prepare
from generation.render.encode import probe_video
from generation.render.scene import LEFT_COLOUR, RIGHT_COLOUR, bone_matrices

TINY = RenderSettings(width=160, height=120, fps=10, duration_s=1.0, body="stick", camera="fixed")


def _axis_angle(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    angle = np.asarray(angle, float)[..., None]
    return np.concatenate([np.cos(angle / 2), np.sin(angle / 2) * axis], -1)


def swinging_walk(T: int = 10, fps: float = 10.0, speed: float = 1.2) -> Motion:
    """A synthetic test motion: legs and arms swing while the root moves along +z."""
    sk = gait_skeleton()
    t = np.arange(T) / fps
    rot = np.zeros((T, sk.num_joints, 4))
    rot[..., 0] = 1.0
    phase = 2 * np.pi * 0.9 * t
    for side, sign in (("left", 1), ("right", -1)):
        rot[:, sk.index(f"{side}_hip")] = _axis_angle([1, 0, 0], -0.5 * sign * np.sin(phase))
        rot[:, sk.index(f"{side}_shoulder")] = _axis_angle([1, 0, 0], 0.4 * sign * np.sin(phase))
    root = np.stack([np.zeros(T), np.full(T, sk.root_height()), speed * t], 1)
    return Motion(sk, rot, root, fps, {"synthetic": True})


def seated(T: int = 10, fps: float = 10.0) -> Motion:
    sk = gesture_skeleton()
    rot = np.zeros((T, sk.num_joints, 4))
    rot[..., 0] = 1.0
    for side in ("left", "right"):
        rot[:, sk.index(f"{side}_hip")] = _axis_angle([1, 0, 0], np.full(T, -np.pi / 2))
        rot[:, sk.index(f"{side}_knee")] = _axis_angle([1, 0, 0], np.full(T, np.pi / 2))
    rot[:, sk.index("right_shoulder")] = _axis_angle([1, 0, 0], -0.3 - 1.2 * np.linspace(0, 1, T))
    root = np.tile([0.0, 0.52, 0.0], (T, 1))
    return Motion(sk, rot, root, fps, {"synthetic": True})


def _brown_pixels(img: np.ndarray) -> int:
    """Pixels of the chair's blue-grey under any shading (bluer than the neutral floor, darker than the sky)."""
    r, g, b = (img[..., k].astype(int) for k in range(3))
    return int(((b - r >= 8) & (b - r <= 40) & (g - r >= 2) & (b < 200) & (r > 20)).sum())


def _colour_pixels(img: np.ndarray, colour, tol: int = 60) -> int:
    target = np.array(colour) * 255
    return int((np.abs(img.astype(int) - target).max(-1) < tol).sum())


def test_frames_are_drawn_and_change_every_frame():
    frames = list(render_frames(swinging_walk(), TINY))
    assert len(frames) == 10
    assert frames[0].shape == (120, 160, 3) and frames[0].dtype == np.uint8
    for f in frames:
        # Not blank: both body sides are visible in their colours, and the image is not one flat colour.
        assert _colour_pixels(f, LEFT_COLOUR) > 5
        assert _colour_pixels(f, RIGHT_COLOUR) > 5
        assert f.std() > 10
    # Fresh frames: every frame differs from the one before (PyVista returns stale images if not re-rendered).
    for a, b in zip(frames, frames[1:]):
        assert np.abs(a.astype(int) - b.astype(int)).sum() > 500


def test_seated_motion_gets_a_chair():
    frame = next(iter(render_frames(seated(), TINY)))
    chair = _brown_pixels(frame)
    assert chair > 300
    walk_frame = next(iter(render_frames(swinging_walk(), TINY)))
    assert _brown_pixels(walk_frame) < chair / 10


def test_render_clip_writes_complete_files(tmp_path):
    settings = RenderSettings(width=160, height=120, fps=10, duration_s=1.0, webm=True)
    seen = []
    result = render_clip(swinging_walk(T=14), tmp_path, "abc123", settings, progress=lambda d, n: seen.append((d, n)))
    assert result.n_frames == 10  # cut at duration_s * fps
    assert result.duration_s == pytest.approx(1.0)
    assert seen[-1] == (10, 10)
    assert result.mp4.name == "abc123.mp4" and result.webm.name == "abc123.webm" and result.poster.name == "abc123.png"
    n_frames, seconds = probe_video(result.mp4)
    assert n_frames == 10 and seconds == pytest.approx(1.0, abs=0.15)
    assert probe_video(result.webm)[0] == 10
    head = result.mp4.read_bytes()[:64]
    assert b"ftyp" in head and b"moov" in result.mp4.read_bytes()[:4096]  # faststart: index at the front
    from PIL import Image

    assert Image.open(result.poster).size == (160, 120)
    # Nothing left under temporary names.
    assert sorted(p.name for p in tmp_path.iterdir()) == ["abc123.mp4", "abc123.png", "abc123.webm"]


def test_short_motion_gives_short_clip_and_resampling(tmp_path):
    motion = swinging_walk(T=12, fps=30.0)  # 0.4 s at 30 fps -> 4 frames at 10 fps
    result = render_clip(motion, tmp_path, "short", TINY)
    assert result.n_frames == 4


def _colour_centre_x(img: np.ndarray, colour, tol: int = 60) -> float:
    ys, xs = np.nonzero(np.abs(img.astype(int) - np.array(colour)).max(-1) < tol)
    return float(xs.mean())


def test_tracking_camera_follows_the_walker_and_fixed_does_not():
    """A walk 6 m along +z: the tracking camera's focal point moves with the root and keeps the figure in the
    middle of the frame; the fixed camera stays put, so the figure crosses the frame."""
    motion = swinging_walk(T=50, fps=10.0)                   # 5 s at 1.2 m/s
    settings = {mode: RenderSettings(width=160, height=120, fps=10, camera=mode, body="stick")
                for mode in ("tracking", "fixed")}
    clip, positions = prepare(motion, settings["tracking"])
    poses, info, _ = plan_cameras(clip, positions, settings["tracking"])
    assert info["rule"] == "follow" and len(poses) == 50
    focal_z = np.array([p.focal_point[2] for p in poses])
    root_z = positions[:, 0, 2]
    moved = focal_z[-1] - focal_z[0]
    assert moved == pytest.approx(root_z[-1] - root_z[0], rel=0.25) and np.all(np.diff(focal_z) >= -1e-9)
    fixed, fixed_info, _ = plan_cameras(clip, positions, settings["fixed"])
    assert fixed_info["rule"] == "fixed" and all(np.array_equal(p.focal_point, fixed[0].focal_point) for p in fixed)
    centres = {mode: [_colour_centre_x(f, LEFT_COLOUR) for f in render_frames(motion, settings[mode])][::49]
               for mode in settings}
    assert abs(centres["tracking"][1] - centres["tracking"][0]) < 0.15 * 160
    assert abs(centres["fixed"][1] - centres["fixed"][0]) > abs(centres["tracking"][1] - centres["tracking"][0])


def test_fixed_camera_keeps_every_joint_in_view():
    motion = swinging_walk(T=60)
    pos = motion.positions()
    cam = fixed_camera(pos, motion.rotations[0, 0], aspect=4 / 3)
    d = cam.focal_point - cam.position
    d /= np.linalg.norm(d)
    r = np.cross(d, [0, 1, 0])
    r /= np.linalg.norm(r)
    u = np.cross(r, d)
    rel = pos.reshape(-1, 3) - cam.position
    depth = rel @ d
    tv = np.tan(np.radians(cam.view_angle) / 2)
    assert (depth > 0).all()
    assert (np.abs(rel @ u) <= depth * tv + 1e-9).all()
    assert (np.abs(rel @ r) <= depth * tv * 4 / 3 + 1e-9).all()


def test_fit_distance_is_tight():
    pts = np.array([[1.0, 0, 0], [-1.0, 0, 0]])
    off = view_offset(np.array([0.0, 0, 1]), 90.0, 0.0)  # camera in front, looking along -z
    dist = fit_distance(pts, np.zeros(3), off, 90.0, aspect=1.0, margin=1.0)
    assert dist == pytest.approx(1.0)


def test_bone_matrices_map_unit_cylinder_onto_bone():
    start = np.array([[0.0, 0, 0], [1.0, 1, 1]])
    end = np.array([[0.0, 2, 0], [1.0, 1, 3]])
    m = bone_matrices(start, end, 0.1)
    tip = m @ np.array([0, 1.0, 0, 1])
    np.testing.assert_allclose(tip[:, :3], end, atol=1e-12)
    side = m @ np.array([1.0, 0, 0, 1])
    np.testing.assert_allclose(np.linalg.norm(side[:, :3] - start, axis=1), 0.1, atol=1e-12)


def test_settings_are_checked():
    with pytest.raises(RenderSettingsError, match="field 'width'"):
        RenderSettings(width=161)
    with pytest.raises(RenderSettingsError, match="field 'camera'"):
        RenderSettings(camera="orbit")
    with pytest.raises(RenderSettingsError, match="field 'zoom': unknown render setting"):
        RenderSettings.from_dict({"zoom": 2})
    assert RenderSettings.from_dict({"fps": 25}).fps == 25.0
    assert "webm" not in RenderSettings().content_dict()


def test_contact_sheet(tmp_path):
    from PIL import Image

    paths = []
    for k in range(3):
        p = tmp_path / f"p{k}.png"
        Image.new("RGB", (160, 120), (40 * k, 100, 150)).save(p)
        paths.append(p)
    out = contact_sheet(paths, ["a", "b", "c"], tmp_path / "sheet.png", thumb_width=80)
    sheet = Image.open(out)
    assert sheet.width > 80 * 2 and sheet.height > 60
    with pytest.raises(ValueError, match="2 labels"):
        contact_sheet(paths, ["a", "b"], tmp_path / "x.png")


def test_patch_rendering_matches_whole_frames():
    """With a fixed camera only the figure's patch is re-rendered; the pictures must stay the same."""
    settings = RenderSettings(width=320, height=240, fps=10, duration_s=3.0, body="stick", camera="fixed")
    motion = swinging_walk(T=30, speed=4.0)  # a long path: the figure is small, so patches are used
    from generation.render import clip as clip_mod

    clip, pos = clip_mod.prepare(motion, settings)
    scene, cams = clip_mod.build_scene(clip, pos, settings)
    try:
        assert scene.plan_patches(pos, cams[0])
    finally:
        scene.close()
    whole = list(render_frames(motion, settings, patches=False))
    patched = list(render_frames(motion, settings, patches=True))
    for a, b in zip(whole, patched):
        diff = np.abs(a.astype(int) - b.astype(int))
        assert diff.mean() < 0.1 and (diff.max(-1) > 40).sum() < 40


def test_patch_rendering_of_a_seated_gesture_matches_whole_frames():
    """In place (root fixed): the background keeps the still body, the patch covers what moves."""
    settings = RenderSettings(width=320, height=240, fps=10, duration_s=1.0, body="stick", camera="fixed")
    whole = list(render_frames(seated(), settings, patches=False))
    patched = list(render_frames(seated(), settings, patches=True))
    assert np.abs(whole[-1].astype(int) - whole[0].astype(int)).sum() > 1000  # the arm did move
    for a, b in zip(whole, patched):
        diff = np.abs(a.astype(int) - b.astype(int))
        assert diff.mean() < 0.1 and (diff.max(-1) > 40).sum() < 40
