"""Can a participant see seed 004's manipulations? Style observers trained on real walks read the styled walks.

Measures (machine: 2-core shared CPU; about 1 min):
1. The style observers (:mod:`generation.quality.style_observer`): held-out recall per scale and class (val and test
   takes of the Bandai Namco walks, whole takes held out).
2. The neutral base (:func:`generation.rbf.real_neutral.load_cycle`): speed, arm swing (wrist fore-aft peak-to-peak
   relative to the pelvis) and bounce (pelvis vertical peak-to-peak), all / height, against the steady cycles of
   every real normal walk; the observers' reading of the base walk beside the held-out real normal takes.
3. Per theme and weight (-0.7, 0.4, 0.7, 1.0), with the ``visual`` and the ``calibrated`` intensities of the expert
   features and with the data-driven features (``features: data``): the theme scale's reading of the styled walk (4
   cycles, 30 fps, feet planted), beside the held-out real takes of that style.
4. Feature differences per Table III group (:mod:`generation.rbf.calibrate`): real style minus normal (train and
   held-out takes) beside the generated edit minus the base at w = 1, visual and calibrated.

    OMP_NUM_THREADS=1 python -m benchmarks.bench_rbf_manipulation [--corpus var/mocap/bandai-namco.npz] \
        [--json docs/benchmarks/rbf_manipulation.json] [--doc docs/benchmarks/rbf.md] \
        [--sheet docs/img/rbf_manipulation_sheet.png]

With ``--doc`` the tables replace the text between ``<!-- manipulation -->`` and ``<!-- /manipulation -->``.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from benchmarks.doc_tables import publish_marked
from generation.mocap.style_scales import NEUTRAL_CLASS, THEME_SCALE
from generation.quality.style_observer import train_style_observers
from generation.rbf import calibrate as C
from generation.rbf.real_neutral import load_cycle, steady_cycles
from generation.rbf.stylise import neutral_walk, stylise
from generation.rbf.themes import CALIBRATED_PATH, THEME_NAMES

WEIGHTS = (-0.7, 0.4, 0.7, 1.0)
SETS = ("visual", "calibrated", "data")  # expert features at two intensity sets; the data-driven features


def energy_measures(positions: np.ndarray, joints: tuple, stride: float, duration: float) -> dict:
    """speed (heights/s), arm swing and bounce (heights) of one cycle (m, J, 3) in heights."""
    r, lw, rw = joints.index("root"), joints.index("left_hand"), joints.index("right_hand")
    arm = float(np.mean([np.ptp(positions[:, w, 2] - positions[:, r, 2]) for w in (lw, rw)]))
    return {"speed": stride / duration, "arm_swing": arm, "bounce": float(np.ptp(positions[:, r, 1]))}


def base_section(obs, clips, base) -> dict:
    joints = tuple(base.skeleton.joints)
    rows = [energy_measures(c.positions[:-1], joints, c.stride, c.duration_s)
            for clip in clips if clip.style == "normal" for c in steady_cycles(clip.motion, 100, clip.name)]
    h = base.skeleton.height
    mine = energy_measures(base.positions() / h, joints, base.metadata["stride_m"][2] / h, base.duration)
    real = {k: {"min": float(np.min([r[k] for r in rows])), "median": float(np.median([r[k] for r in rows])),
                "max": float(np.max([r[k] for r in rows]))} for k in mine}
    walk = neutral_walk(base, n_cycles=4, fps=30.0)
    readings = {}
    for scale, o in obs.scales.items():
        neutral = NEUTRAL_CLASS[scale]
        held = [r for r in o.heldout(clips)["rows"] if r["class"] == neutral]
        readings[scale] = {"base": o.read(walk)["p"][neutral],
                           "heldout_real_mean": float(np.mean([r["p"][neutral] for r in held])),
                           "heldout_real_takes": len(held)}
    return {"measures": mine, "real_normal_cycles": len(rows), "real_range": real, "readings": readings}


def cross_dataset_section(clips) -> dict:
    """Energy and gender scales trained on dataset 2's training takes, reading every dataset-1 take of their classes
    (other actors, other sessions): {scale: {class: {"takes", "recall"}}}."""
    from generation.mocap.style_scales import scale_clips
    from generation.quality.style_observer import StyleObserver

    out = {}
    for scale in ("energy", "gender"):
        o = StyleObserver.fit([c for c in clips if c.dataset == "bandai-namco-2"], scale)
        rows = [(k, o.read(c.motion)["top"]) for c, k in scale_clips(clips, scale) if c.dataset == "bandai-namco-1"
                and c.motion.num_frames >= 60]
        out[scale] = {k: {"takes": sum(1 for kk, _ in rows if kk == k),
                          "recall": float(np.mean([t == k for kk, t in rows if kk == k]))}
                      for k in o.classes if any(kk == k for kk, _ in rows)}
    return out


def reading_section(obs, clips, base) -> dict:
    held = obs.heldout(clips)
    out = {}
    for theme in THEME_NAMES:
        scale, target = THEME_SCALE[theme]
        rows = [r for r in held[scale]["rows"] if r["class"] == target]
        entry = {"scale": scale, "target": target, "real_heldout_takes": len(rows),
                 "real_read_as": held[scale]["recall"][target], "real_mean_p": held[scale]["mean_p"][target]}
        for name in SETS:
            entry[name] = {}
            for w in WEIGHTS:
                kw = {"features": "data"} if name == "data" else {"intensities": name}
                r = obs.read_theme(stylise(base, theme, w, 10, n_cycles=4, fps=30.0, **kw), theme)
                entry[name][str(w)] = {"p_target": r["p_target"], "top": r["top"]}
        out[theme] = entry
    return out


def feature_section(base) -> dict:
    shipped = json.loads(CALIBRATED_PATH.read_text(encoding="utf-8"))
    out = {}
    for theme in THEME_NAMES:
        vis = C.generated_measures(base, theme, "visual")
        cal = C.generated_measures(base, theme, "calibrated")
        out[theme] = [{"group": f"{g['part']} {g['axis']} {g['kind']}", "real_train": g["real_train"],
                       "real_heldout": g["real_heldout"], "visual_w1": float(v), "calibrated_w1": float(c)}
                      for g, v, c in zip(shipped["themes"][theme]["groups"], vis, cal)]
    return out


def contact_sheet(obs, clips, base, path: Path, n_poses: int = 5) -> None:
    """Stick figures per theme: the base, a held-out real take of the style (its first steady cycle), the calibrated
    edit at w = 0.7 and 1.0 and the visual edit at w = 1.0; side view at ``n_poses`` phases, walker frame."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from benchmarks.bench_rbf_features import _bones, _draw
    from generation.rbf.stylise import stylised_cycle

    bones = _bones(base.skeleton)
    h = base.skeleton.height
    cols = ("base", "real held-out take", "calibrated w = 0.7", "calibrated w = 1.0", "visual w = 1.0")
    fig, axes = plt.subplots(len(THEME_NAMES), len(cols), figsize=(4.2 * len(cols), 2.6 * len(THEME_NAMES)), dpi=90)
    for row, theme in enumerate(THEME_NAMES):
        real = next(c for c in clips if c.split != "train" and c.style in C.theme_styles(theme)
                    and steady_cycles(c.motion, 100, c.name))
        real_pos = steady_cycles(real.motion, 100, real.name)[0].positions[:-1] * h
        poses = {"base": stylised_cycle(base, theme, 0.0, 10)["positions"], "real held-out take": real_pos,
                 "calibrated w = 0.7": stylised_cycle(base, theme, 0.7, 10, intensities="calibrated")["positions"],
                 "calibrated w = 1.0": stylised_cycle(base, theme, 1.0, 10, intensities="calibrated")["positions"],
                 "visual w = 1.0": stylised_cycle(base, theme, 1.0, 10, intensities="visual")["positions"]}
        for col, label in enumerate(cols):
            ax = axes[row, col]
            pos = poses[label]
            frames = np.linspace(0, len(pos), n_poses, endpoint=False).astype(int)
            for k, f in enumerate(frames):
                centred = pos[f] - np.array([0.0, 0.0, pos[f][0, 2]])
                _draw(ax, centred, bones, 2, 1, shift=0.55 * k)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_xlim(-0.55, 0.55 * n_poses)
            ax.set_ylim(-0.05, 1.95)
            ax.axhline(0.0, color="#999999", lw=0.6)
            name = real.name if label.startswith("real") else label
            ax.set_title(f"{theme}: {name}", fontsize=8, loc="left")
    fig.suptitle("Seed 004 themes (10 features): base, held-out real take, calibrated and visual edits; side view at "
                 "5 phases, pelvis-centred (stick figures; blue = left, red = right)", fontsize=10)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)
    from PIL import Image

    Image.open(path).convert("RGB").quantize(32).save(path, optimize=True)  # few colours: a fraction of the bytes


def _f(x, d=2):
    return "-" if x is None else f"{x:.{d}f}"


def render(res: dict) -> str:
    lines = [f"Run {res['date']}, {res['machine']}, {res['seconds']:.0f} s; corpus `{res['corpus']}`.", "",
             "Held-out recall of the style observers (val and test takes, whole takes held out):", "",
             "| scale | class | held-out takes | recall | mean p(own class) |", "|---|---|---|---|---|"]
    for scale, h in res["observers"].items():
        for k in h["recall"]:
            lines.append(f"| {scale} | {k} | {h['takes'][k]} | {_f(h['recall'][k])} | {_f(h['mean_p'][k])} |")
    lines += ["", "Held out by dataset: the energy and gender scales trained on dataset 2 only, reading dataset 1's "
              "takes (another actor; takes of at least 2 s):", "", "| scale | class | dataset-1 takes | recall |",
              "|---|---|---|---|"]
    for scale, classes in res["cross_dataset"].items():
        for k, v in classes.items():
            lines.append(f"| {scale} | {k} | {v['takes']} | {v['recall']:.2f} |")
    b = res["base"]
    lines += ["", f"Neutral base against {b['real_normal_cycles']} steady cycles of the real normal walks (/ height):",
              "", "| measure | base | real min | real median | real max | inside |", "|---|---|---|---|---|---|"]
    for k, v in b["measures"].items():
        r = b["real_range"][k]
        lines.append(f"| {k} | {v:.3f} | {r['min']:.3f} | {r['median']:.3f} | {r['max']:.3f} | "
                     f"{'yes' if r['min'] <= v <= r['max'] else '**no**'} |")
    lines += ["", "| scale | p(normal) of the base walk | mean p(normal) of held-out real normal takes (n) |",
              "|---|---|---|"]
    for scale, r in b["readings"].items():
        lines.append(f"| {scale} | {r['base']:.2f} | {r['heldout_real_mean']:.2f} ({r['heldout_real_takes']}) |")
    lines += ["", "Reading of the styled walks on the theme's scale: p(theme) and the top class, per weight; the "
              "held-out real takes of the style beside (share read as the style, mean p):", "",
              "| theme | intensities | " + " | ".join(f"w = {w}" for w in WEIGHTS) + " | held-out real takes |",
              "|---|---|" + "---|" * len(WEIGHTS) + "---|"]
    for theme, e in res["readings"].items():
        for name in SETS:
            cells = [f"{e[name][str(w)]['p_target']:.2f} ({e[name][str(w)]['top']})" for w in WEIGHTS]
            real = (f"{_f(e['real_read_as'])} read as {e['target']}, p {_f(e['real_mean_p'])} "
                    f"(n = {e['real_heldout_takes']})")
            lines.append(f"| {theme} | {name} | " + " | ".join(cells) + f" | {real} |")
    lines += ["", "Feature differences per Table III group (heights; tilt: mean offset, swing: peak-to-peak change), "
              "real style minus normal beside generated w = 1 minus base:", "",
              "| theme | group | real (train) | real (held out) | visual w = 1 | calibrated w = 1 |",
              "|---|---|---|---|---|---|"]
    for theme, rows in res["features"].items():
        for r in rows:
            lines.append(f"| {theme} | {r['group']} | {r['real_train']:+.4f} | {r['real_heldout']:+.4f} | "
                         f"{r['visual_w1']:+.4f} | {r['calibrated_w1']:+.4f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", default="var/mocap/bandai-namco.npz")
    ap.add_argument("--json", default="docs/benchmarks/rbf_manipulation.json")
    ap.add_argument("--doc", default=None)
    ap.add_argument("--sheet", default=None, help="contact sheet PNG (e.g. docs/img/rbf_manipulation_sheet.png)")
    args = ap.parse_args(argv)
    t0 = time.time()
    obs, clips = train_style_observers(args.corpus)
    base = load_cycle()
    held = obs.heldout(clips)
    res = {"date": "2026-12-06", "machine": "2-core shared CPU, no GPU", "corpus": args.corpus,
           "observers": {s: {k: h[k] for k in ("recall", "takes", "mean_p")} for s, h in held.items()},
           "cross_dataset": cross_dataset_section(clips),
           "base": base_section(obs, clips, base), "readings": reading_section(obs, clips, base),
           "features": feature_section(base)}
    res["seconds"] = time.time() - t0
    if args.sheet:
        contact_sheet(obs, clips, base, Path(args.sheet))
    publish_marked(res, args.json, render(res), args.doc, "manipulation")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
