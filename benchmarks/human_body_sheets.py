"""Pictures of the human bodies for docs/img (researchers only): every preset walking and gesturing, close-ups at
player size, the seated presets from the side, and demo clips beside the old mannequin.

    python -m benchmarks.human_body_sheets [--out docs/img] [--only presets closeup seated demo]

Motions are the demo plan's own (``happy_loop``: the gait network's happy walk on a loop; ``gesture_proud``: the
gesture network's proud narration gesture, female; ``transition_sad_to_happy``), made as ``generate_clips`` makes
them; only the body (``render.body_preset``, ``body``) changes between pictures.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from generation.render.offscreen import prepare_render_process

prepare_render_process()

FONT = ImageFont.load_default()


def demo_motion(entry_id: str, fps: float = 15.0):
    from generation.plans.clipgen import make_motion, resolve
    from generation.plans.schema import load_plan

    plan = load_plan("demo")
    entry = next(e for e in plan.entries if e.id == entry_id)
    run_entry, _ = resolve(entry)
    return make_motion(run_entry, fps=fps)


def settings(**kw):
    from generation.render import RenderSettings

    return RenderSettings(**{"width": 640, "height": 360, "fps": 15.0, "duration_s": 10.0, **kw})


def moments(motion, st, fractions=(0.1, 0.37, 0.63, 0.9)) -> list[np.ndarray]:
    from generation.render.clip import prepare, render_frames_at

    n = prepare(motion, st)[0].num_frames
    return [img for _, img in render_frames_at(motion, st, [round(f * (n - 1)) for f in fractions])]


def grid(rows: list[tuple[str, list[np.ndarray]]], out: Path, thumb: int = 300) -> Path:
    """A labelled grid: one row per (label, images)."""
    label_w, pad = 130, 4
    ims = [[Image.fromarray(a).resize((thumb, round(a.shape[0] * thumb / a.shape[1])), Image.LANCZOS) for a in r]
           for _, r in rows]
    th = ims[0][0].height
    cols = max(len(r) for r in ims)
    sheet = Image.new("RGB", (label_w + cols * (thumb + pad), len(rows) * (th + pad)), "white")
    draw = ImageDraw.Draw(sheet)
    for i, ((label, _), r) in enumerate(zip(rows, ims)):
        y = i * (th + pad)
        for k, line in enumerate(label.split("\n")):
            draw.text((4, y + th // 2 - 12 + 13 * k), line, fill=(20, 20, 20), font=FONT)
        for j, im in enumerate(r):
            sheet.paste(im, (label_w + j * (thumb + pad), y))
    out.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(out)
    print(out)
    return out


def presets_sheet(out_dir: Path) -> None:
    from generation.render.bodies import PRESETS

    walk, gesture = demo_motion("happy_loop"), demo_motion("gesture_proud")
    rows = []
    for name in PRESETS:
        rows.append((f"{name}\nwalk (happy)", moments(walk, settings(body_preset=name))))
        rows.append((f"{name}\ngesture (proud)", moments(gesture, settings(body_preset=name))))
    grid(rows, out_dir / "human_presets_sheet.png", thumb=240)


def closeup(out_dir: Path) -> None:
    """Head and hands at 1:1 pixels of a 1280x720 clip (player size), neutral and hidden face."""
    from generation.render import clip as clip_mod
    from generation.render.camera import project

    gesture = demo_motion("gesture_proud")
    crops = []
    for face, tone in (("neutral", "medium"), ("hidden", "medium"), ("neutral", "dark")):
        st = settings(width=1280, height=720, face=face, skin_tone=tone)
        clip, pos = clip_mod.prepare(gesture, st)
        cams, _, (_, _, _, fig) = clip_mod.plan_cameras(clip, pos, st)
        t = int(0.45 * (clip.num_frames - 1))
        img = dict(clip_mod.render_frames_at(gesture, st, [t]))[t]
        heads = fig.heads()[t]
        body = fig.body
        for label in ("head", "wrist.L", "wrist.R"):
            px, _, _ = project(heads[body.bone(label)][None], cams[t], 1280, 720)
            cx, cy = (int(round(v)) for v in px[0])
            h = 90
            x0, y0 = np.clip(cx - h, 0, 1280 - 2 * h), np.clip(cy - h + (30 if label == "head" else 20), 0, 720 - 2 * h)
            crops.append(img[y0:y0 + 2 * h, x0:x0 + 2 * h])
    rows = [("neutral face", crops[0:3]), ("face: hidden", crops[3:6]), ("skin tone dark", crops[6:9])]
    grid(rows, out_dir / "human_closeup.png", thumb=180)


def seated_side(out_dir: Path) -> None:
    """Each preset seated, first frame of the proud gesture, seen from its left side."""
    from generation.render import clip as clip_mod
    from generation.render.bodies import PRESETS
    from generation.render.camera import CameraPose, facing_direction, view_offset

    gesture = demo_motion("gesture_proud")
    images = []
    for name in PRESETS:
        st = settings(body_preset=name, anti_aliasing="fxaa")
        clip, pos = clip_mod.prepare(gesture, st)
        scene, _ = clip_mod.build_scene(clip, pos, st)
        try:
            t = int(0.2 * (clip.num_frames - 1))
            root = pos[t, 0]
            off = view_offset(facing_direction(clip.rotations[0, 0]), 0.0, 4.0)
            focal = np.array([root[0], 0.62, root[2]]) + 0.1 * facing_direction(clip.rotations[0, 0])
            scene.set_camera(CameraPose(focal + off * 4.2, focal, view_angle=30.0))
            scene.set_frame(t, pos[t])
            images.append(scene.frame())
        finally:
            scene.close()
    names = list(PRESETS)
    grid([("seated, side:\n" + "\n".join(names[:3]), images[:3]), ("seated, side:\n" + "\n".join(names[3:]),
                                                                      images[3:])],
         out_dir / "human_seated_side.png", thumb=300)


def demo_beside_mannequin(out_dir: Path) -> None:
    rows = []
    fr = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)
    for entry, label in (("happy_loop", "happy walk"), ("transition_sad_to_happy", "sad->happy"),
                         ("gesture_proud", "proud gesture")):
        m = demo_motion(entry)
        rows.append((f"{label}\nhuman", moments(m, settings(), fr)))
        rows.append((f"{label}\nmannequin", moments(m, settings(body="mannequin"), fr)))
    grid(rows, out_dir / "human_vs_mannequin_demo.png", thumb=200)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, default=Path("docs/img"))
    p.add_argument("--only", nargs="+", default=["presets", "closeup", "seated", "demo"])
    args = p.parse_args()
    jobs = {"presets": presets_sheet, "closeup": closeup, "seated": seated_side, "demo": demo_beside_mannequin}
    for name in args.only:
        jobs[name](args.out)


if __name__ == "__main__":
    main()
