"""Renderer speed-ups keep the pictures: the merged mannequin mesh, anti-aliasing "auto"."""
from __future__ import annotations

import numpy as np

from generation.render import RenderSettings
from generation.render import clip as clip_mod
from generation.render.camera import CameraPose
from generation.render.clip import anti_aliasing_for
from tests.test_render import seated, swinging_walk


def test_merged_mannequin_poses_are_not_cumulative():
    """Setting a pose twice gives the same points and normals whatever was set in between (the merged mesh is
    rewritten from the rest-pose buffers, never from its own last state)."""
    motion = swinging_walk(T=12, fps=10.0)
    settings = RenderSettings(width=160, height=120, fps=10.0, duration_s=1.2, anti_aliasing="none",
                              body="mannequin")
    clip, pos = clip_mod.prepare(motion, settings)
    scene, _ = clip_mod.build_scene(clip, pos, settings)
    try:
        scene.set_pose(pos[3])
        first = (np.array(scene.body_mesh.points), np.array(scene.body_mesh.point_data["Normals"]))
        for t in range(len(pos)):
            scene.set_pose(pos[t])
        scene.set_pose(pos[3])
        assert np.allclose(scene.body_mesh.points, first[0])
        assert np.allclose(scene.body_mesh.point_data["Normals"], first[1])
        n = np.asarray(scene.body_mesh.point_data["Normals"])
        assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-6)
        # Each part moved rigidly with its bone: the thigh's points stay at their rest distance from the hip.
        k = [p.name for p in scene.parts].index("left_thigh")
        sel = scene._point_part == k
        hip = pos[3][scene.parts[k].a]
        rest = np.linalg.norm(scene._base_points[sel], axis=1)
        assert np.allclose(np.linalg.norm(scene.body_mesh.points[sel] - hip, axis=1), rest, atol=1e-9)
    finally:
        scene.close()


def test_auto_anti_aliasing_follows_the_camera():
    a = CameraPose(np.zeros(3), np.ones(3))
    b = CameraPose(np.ones(3), np.zeros(3))
    assert anti_aliasing_for("auto", [a, a, a], seated=True) == "fxaa"
    assert anti_aliasing_for("auto", [a, a, a], seated=False) == "none"      # walks: none, fixed camera or not
    assert anti_aliasing_for("auto", [a, b, a], seated=True) == "none"
    assert anti_aliasing_for("msaa", [a, b]) == "msaa"


def test_render_records_the_anti_aliasing_used(tmp_path):
    from generation.render import render_clip

    res = render_clip(seated(T=6), tmp_path, "sit", RenderSettings(width=160, height=120, fps=10.0, duration_s=0.6))
    assert res.camera["rule"] == "fixed" and res.camera["anti_aliasing"] == "fxaa"
    res = render_clip(swinging_walk(T=6), tmp_path, "walk", RenderSettings(width=160, height=120, fps=10.0,
                                                                         duration_s=0.6))
    assert res.camera["anti_aliasing"] == "none"
