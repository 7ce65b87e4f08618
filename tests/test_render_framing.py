"""The mannequin and the other looks, body choice validation, framing measured from decoded video."""
from __future__ import annotations

import numpy as np
import pytest
from test_render import seated, swinging_walk

from generation.core.motion import Motion
from generation.core.skeleton import gait_skeleton, gesture_skeleton
from generation.plans.schema import PlanError, validate_plan
from generation.render import RenderSettings, RenderSettingsError, render_clip, render_frames
from generation.render.body import PartPoser, mannequin_parts
from generation.render.camera import critically_damped


def _figure_mask(img: np.ndarray) -> np.ndarray:
    """Pixels of the clay-coloured mannequin: clearly warmer than the neutral floor and grid, the translucent
    black shadow, the bluish white sky and the blue-grey chair (red minus blue survives shading)."""
    r, b = img[..., 0].astype(int), img[..., 2].astype(int)
    return (r - b) > 30


def _height_fraction(img: np.ndarray, mask_fn=_figure_mask) -> tuple[float, bool]:
    """Figure height / frame height from the rows holding figure pixels, and whether it touches the border."""
    mask = mask_fn(img)
    rows = np.flatnonzero(mask.sum(1) >= 2)
    cols = np.flatnonzero(mask.sum(0) >= 2)
    if len(rows) == 0:
        return 0.0, False
    h, w = mask.shape
    touches = rows[0] <= 0 or rows[-1] >= h - 1 or cols[0] <= 0 or cols[-1] >= w - 1
    return (rows[-1] - rows[0] + 1) / h, bool(touches)


def _decode_ffmpeg(path) -> list[np.ndarray]:
    import imageio_ffmpeg

    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    w, h = meta["size"]
    return [np.frombuffer(buf, np.uint8).reshape(h, w, 3) for buf in reader]


def test_defaults_are_human_720p_auto_camera():
    s = RenderSettings()
    assert (s.width, s.height, s.body, s.camera) == (1280, 720, "human", "auto")
    assert (s.body_preset, s.face, s.skin_tone) == (None, "neutral", "medium")
    assert s.content_dict()["body"] == "human"  # the look is part of every clip's hash
    assert {"body_preset", "face", "skin_tone"} <= set(s.content_dict())


def test_body_choice_is_validated():
    with pytest.raises(RenderSettingsError, match="field 'body'"):
        RenderSettings(body="avatar")
    for body in ("human", "mannequin", "stick", "points"):
        assert RenderSettings.from_dict({"body": body}).body == body
    walk = {"id": "w", "generator": "procedural_walk", "emotion": [1, 0, 0, 0]}
    with pytest.raises(PlanError, match="field 'render': field 'body'"):
        validate_plan({"name": "t", "clips": [dict(walk, render={"body": "robot"})]})
    plan = validate_plan({"name": "t", "render": {"body": "points"},
                          "clips": [walk, dict(walk, id="w2", render={"body": "stick"})]})
    assert [e.render.body for e in plan.entries] == ["points", "stick"]


@pytest.mark.parametrize("skel", [gait_skeleton(1.55, "female"), gait_skeleton(1.95, "male"),
                                  gesture_skeleton(1.60, "female"), gesture_skeleton(1.85, "male")])
def test_mannequin_is_built_from_the_skeleton(skel):
    parts = mannequin_parts(skel)
    names = {p.name for p in parts}
    for needed in ("head", "neck", "left_thigh", "right_shin", "left_foot", "right_upper_arm", "left_forearm",
                   "right_hand"):
        assert needed in names
    # Part lengths follow the bones; rigid transforms are proper rotations placing parts on their joints.
    pos = skel.rest_positions()
    mats = PartPoser(skel, parts).matrices(pos)
    for p, m in zip(parts, mats):
        np.testing.assert_allclose(m[:3, :3] @ m[:3, :3].T, np.eye(3), atol=1e-9)
        assert np.linalg.det(m[:3, :3]) == pytest.approx(1.0)
        np.testing.assert_allclose(m[:3, 3], pos[p.a])
        if p.ellipsoid is None and p.y0 == 0.0 and p.name != "neck":
            tip = m @ np.array([0, p.y1, 0, 1.0])
            np.testing.assert_allclose(tip[:3], pos[p.b], atol=1e-9)
    # The head's top is at the body height in the rest pose.
    head = next(p for p in parts if p.name == "head")
    top = pos[head.a] + (pos[head.b] - pos[head.a]) / np.linalg.norm(pos[head.b] - pos[head.a]) * \
        (head.y1 + head.ellipsoid[1])
    assert top[1] + skel.root_height() == pytest.approx(skel.height, abs=0.03)
    # Builds differ: female hips wider than the male's relative to the chest.
    trunk = [p for p in parts if p.name.startswith("trunk")]
    assert trunk[0].r0 > 0.1 * skel.height / 1.75


def test_critically_damped_smoothing_has_no_lag_or_overshoot():
    t = np.arange(90) / 30.0
    x = np.stack([1.5 * t, 0.05 * np.sin(2 * np.pi * 2 * t)], 1)  # walking forward with a sway
    y = critically_damped(x, 30.0, 2.5)
    assert np.abs(y[10:-10, 0] - x[10:-10, 0]).max() < 0.05  # no lag on steady motion
    assert np.abs(y[10:-10, 1]).max() < 0.02  # sway removed
    step = critically_damped(np.r_[np.zeros(30), np.ones(60)][:, None], 30.0, 2.5)
    assert step.max() <= 1.0 + 1e-3 and step.min() >= -1e-3


def long_walk(T: int = 20, fps: float = 10.0) -> Motion:
    return swinging_walk(T=T, fps=fps, speed=4.0)  # 8 m in 2 s: a fixed camera would leave a small figure


@pytest.mark.parametrize("motion_fn, kind, need", [(long_walk, "walk", 0.50), (seated, "seated", 0.60)])
def test_framing_measured_in_decoded_video(tmp_path, motion_fn, kind, need):
    """Render (mannequin, 16:9, auto camera), decode the MP4, measure the figure's height per frame."""
    settings = RenderSettings(width=256, height=144, fps=10, duration_s=2.0, body="mannequin")
    result = render_clip(motion_fn(), tmp_path, kind, settings)
    assert result.camera["rule"] == ("follow" if kind == "walk" else "fixed")
    assert result.camera["min_figure_fraction"] >= need
    frames = _decode_ffmpeg(result.mp4)
    assert len(frames) == result.n_frames and frames[0].shape == (144, 256, 3)
    fractions = []
    for f in frames:
        frac, touches = _height_fraction(f)
        assert not touches, "the whole body stays in frame"
        fractions.append(frac)
    assert min(fractions) >= need, fractions
    # The measured heights agree with the camera's projected outline (which pads the body a little).
    assert min(fractions) <= result.camera["max_figure_fraction"] + 0.03


def _human_mask(img: np.ndarray) -> np.ndarray:
    """Pixels of the human body's skin, hair, trousers and shoes: warm (skin) or dark and not bluish (the floor,
    grid lines and shadow are light neutral greys, the sky bluish white)."""
    r, g, b = (img[..., k].astype(int) for k in range(3))
    return ((r - b) > 30) | ((np.maximum(np.maximum(r, g), b) < 100) & (b - r < 12))


def test_human_framing_measured_in_decoded_video(tmp_path):
    """The human body, head to shoes, fills at least half the frame height in every frame of a long walk, from the
    first frame on, and never touches the border."""
    settings = RenderSettings(width=256, height=144, fps=10, duration_s=2.0)
    result = render_clip(long_walk(), tmp_path, "human", settings)
    assert result.camera["body"] == "human" and result.camera["body_preset"] == "male"
    assert result.camera["min_figure_fraction"] >= 0.5
    fractions = []
    for f in _decode_ffmpeg(result.mp4):
        frac, touches = _height_fraction(f, _human_mask)
        assert not touches, "the whole body stays in frame"
        fractions.append(frac)
    assert min(fractions) >= 0.5, fractions
    assert max(fractions) <= result.camera["max_figure_fraction"] + 0.03


def test_follow_camera_moves_smoothly(tmp_path):
    from generation.render import clip as clip_mod

    settings = RenderSettings(width=256, height=144, fps=10, duration_s=2.0)
    clip, pos = clip_mod.prepare(long_walk(), settings)
    info: dict = {}
    scene, cams = clip_mod.build_scene(clip, pos, settings, info)
    scene.close()
    assert info["rule"] == "follow"
    focal = np.array([c.focal_point for c in cams])
    step = np.diff(focal, axis=0)
    accel = np.diff(step, axis=0)
    assert np.abs(focal[:, 1] - focal[0, 1]).max() < 1e-9  # no vertical bobbing
    assert np.linalg.norm(accel, axis=1).max() < 0.05  # no jitter (metres per frame^2)
    offsets = np.array([c.position - c.focal_point for c in cams])
    np.testing.assert_allclose(offsets, offsets[:1].repeat(len(cams), 0), atol=1e-9)  # fixed distance


def test_each_body_renders():
    settings = dict(width=160, height=96, fps=10, duration_s=0.3)
    walk = swinging_walk(T=3)
    mann = list(render_frames(walk, RenderSettings(body="mannequin", **settings)))
    stick = list(render_frames(walk, RenderSettings(body="stick", **settings)))
    points = list(render_frames(walk, RenderSettings(body="points", **settings)))
    assert len(mann) == len(stick) == len(points) == 3
    assert _figure_mask(mann[0]).sum() > 200  # a body with volume
    assert _figure_mask(stick[0]).sum() < _figure_mask(mann[0]).sum() / 3
    p = points[0].astype(int)
    white = (p.min(-1) > 120).sum()
    black = (p.max(-1) < 10).sum()
    assert black > 0.9 * p.shape[0] * p.shape[1]  # black background, no floor or grid
    assert 10 < white < 0.05 * p.shape[0] * p.shape[1]  # a few white dots
    for a, b in zip(mann, mann[1:]):
        assert np.abs(a.astype(int) - b.astype(int)).sum() > 500  # fresh frames


def test_mannequin_patch_rendering_matches_whole_frames():
    """Fixed camera: the mannequin is re-rendered in a patch over a cached background; same pictures."""
    settings = RenderSettings(width=320, height=180, fps=10, duration_s=1.0, camera="fixed")
    whole = list(render_frames(seated(), settings, patches=False))
    patched = list(render_frames(seated(), settings, patches=True))
    for a, b in zip(whole, patched):
        diff = np.abs(a.astype(int) - b.astype(int))
        assert diff.mean() < 0.2 and (diff.max(-1) > 40).sum() < 60


def test_build_from_metadata_changes_the_body():
    from generation.render.clip import body_skeleton

    m = seated()
    m2 = Motion(m.skeleton, m.rotations, m.root_positions, m.fps, {"gender": "female"})
    assert body_skeleton(m2).build == "female" and body_skeleton(m).build == "male"
    np.testing.assert_allclose(body_skeleton(m2).offsets, m.skeleton.offsets)


def test_plan_record_carries_the_camera_rule(tmp_path):
    from generation.pipeline.runner import run_plan

    plan = validate_plan({"name": "t", "render": {"width": 128, "height": 72, "fps": 5, "duration_s": 1.0},
                          "clips": [{"id": "w", "generator": "procedural_walk", "emotion": [0, 0, 0, 1],
                                     "render": {"body": "points"}}]})
    result = run_plan(plan, tmp_path / "clips", tmp_path / "records")
    assert not result.failed
    cam = result.records[0]["metadata"]["camera"]
    assert cam["rule"] in ("fixed", "follow") and cam["body"] == "points"
    assert cam["min_figure_fraction"] >= 0.5
