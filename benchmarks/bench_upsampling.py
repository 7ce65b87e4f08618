"""Benchmark: upsampling the networks' poses (gait 7.5 Hz, gesture 10 Hz) to 30 fps by slerp (linear in time) or by
cubic splines (``Motion.resample(fps, smooth=True)``), on real captured walks and on generated walks and gestures
(docs/benchmarks/gait.md, "Upsampling the networks' output").

1. Real walks (the shipped dataset-1 forward walks, take 1 of happy, sad, angry and normal; Bandai Namco Research
   Motion Dataset, Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0): every 4th frame kept (the network's
   rate), upsampled back both ways and compared with the capture: joint position error (cm) and mean joint jerk
   (m/s^3) against the capture's own.
2. Generated walks (the shipped real-trained weights, real seeds, 10 s on a straight path, a 150-degree sharp turn
   and a 2.5 m curve per emotion): the network's raw 7.5 Hz output upsampled both ways, then the foot clean-up
   generation applies (``plant_feet(lower_pelvis=True)``); mean joint jerk, toe skim and skate speed
   (``generation.quality.realism``) per emotion, beside the same measures of the real take.
3. Generated gestures (the shipped gesture weights, three sentences per emotion, female, right-handed,
   narration): mean joint jerk and peak hand speed, both ways, per emotion.
4. A figure: the right hand's speed over 3 s of a generated angry walk, both ways, above the same for the real
   angry take subsampled and upsampled (docs/img/upsampling_hand_speed.png).

Usage: OMP_NUM_THREADS=1 python -m benchmarks.bench_upsampling [--out JSON] [--figure PNG]
Results: docs/benchmarks/upsampling.json, rendered into the marked ``upsampling.*`` tables of
docs/benchmarks/gait.md (benchmarks/doc_tables.py); also the time of one upsampling call per method.
"""
from __future__ import annotations

import argparse
import datetime
import math
import shlex
import sys
import time
from pathlib import Path

import numpy as np
import torch

from benchmarks import doc_tables
from benchmarks.bench_record import commit_label, machine_label
from generation.core import paths
from generation.core.foot_contact import plant_feet
from generation.core.motion import Motion
from generation.gait.generate import generate_gaits, load_default_model
from generation.gait.real_seeds import STYLE_OF_EMOTION, shipped_walk
from generation.quality.metrics import mean_jerk
from generation.quality.realism import realism_measures
from protocol.vocabulary import GAIT_EMOTIONS

ROOT = Path(__file__).resolve().parents[1]

METHODS = {"slerp": False, "spline": True}
"""Upsampling method -> the ``smooth`` argument of Motion.resample."""
FPS = 30.0
FRAME_STEP = 4
PATHS = {"straight 10 m": lambda: paths.straight(10.0),
         "sharp turn 150 deg": lambda: paths.sharp_turn(math.radians(150.0), 10.0, 0.5),
         "curve r 2.5 m": lambda: paths.curved(2.5, math.radians(300.0), 10.0)}


def network_rate(motion: Motion) -> Motion:
    """Every FRAME_STEP-th frame of a 30 fps capture: the capture at the gait network's rate."""
    return Motion(motion.skeleton, motion.rotations[::FRAME_STEP], motion.root_positions[::FRAME_STEP],
                  motion.fps / FRAME_STEP, dict(motion.metadata))


def feet_and_jerk(motion: Motion) -> dict:
    """Mean joint jerk (m/s^3), toe skim and skate speed (cm/s) of a 30 fps motion."""
    r = realism_measures(motion)
    return {"jerk": mean_jerk(motion.positions(), motion.fps), "toe_skim": r["toe_skim"],
            "skate_cm_s": r["skate_cm_s"]}


def real_round_trip() -> dict:
    """Per emotion: the shipped real walk subsampled to the network's rate and upsampled back both ways."""
    out = {}
    for emotion in GAIT_EMOTIONS:
        take = shipped_walk(STYLE_OF_EMOTION[emotion])
        n = (take.num_frames - 1) // FRAME_STEP * FRAME_STEP + 1                  # end on a kept frame
        truth = take.slice(0, n)
        keys = network_rate(truth)
        P = truth.positions()
        row = {"take": take.metadata.get("source", emotion), "seconds": n / truth.fps,
               "capture": feet_and_jerk(truth)}
        for method, smooth in METHODS.items():
            up = keys.resample(truth.fps, smooth=smooth)
            row[method] = {**feet_and_jerk(up),
                           "position_error_cm": 100.0 * float(np.linalg.norm(up.positions() - P, axis=-1).mean())}
        out[emotion] = row
    return out


def generated(steps: int) -> dict:
    """Per emotion and path: the real-trained network's raw walk upsampled both ways and foot-planted."""
    net = load_default_model(weights="real")
    names = [(e, p) for e in GAIT_EMOTIONS for p in PATHS]
    raw = generate_gaits([None] * len(names), [PATHS[p]() for _, p in names],
                         np.array([np.eye(4)[GAIT_EMOTIONS.index(e)] for e, _ in names]), steps=steps,
                         fps_out=net.fps, model=net, foot_cleanup=False)
    out: dict = {}
    for (emotion, path), m in zip(names, raw):
        out.setdefault(emotion, {})[path] = {
            method: feet_and_jerk(plant_feet(m.resample(FPS, smooth=smooth), lower_pelvis=True))
            for method, smooth in METHODS.items()}
    return out


GESTURE_SENTENCES = ("We waited at the station for hours, and then the last train finally arrived.",
                     "I cannot believe you did that to me again.",
                     "Please put the books back on the shelf when you are done.")
GESTURE_EMOTIONS = ("joyous", "sad", "angry", "proud", "neutral", "afraid")


def gestures() -> dict:
    """Per gesture emotion: the mean over GESTURE_SENTENCES of the jerk (m/s^3) and the peak hand speed (m/s) of
    the network's 10 Hz gesture upsampled to 30 fps each way (hands: the wrist joints)."""
    from generation.gesture.config import TRAIN_FPS
    from generation.gesture.generate import generate_gesture
    from generation.gesture.generate import load_default_model as load_gesture_model

    net = load_gesture_model()
    net_fps = float(getattr(net, "train_fps", TRAIN_FPS))
    out = {}
    for emotion in GESTURE_EMOTIONS:
        vals: dict = {m: {"jerk": [], "peak_hand_speed": []} for m in METHODS}
        for sentence in GESTURE_SENTENCES:
            keys = generate_gesture(sentence, task="narration", emotion=emotion, gender="female",
                                    handedness="right", fps=net_fps, model=net)
            hands = [keys.skeleton.joints.index(j) for j in ("left_wrist", "right_wrist")]
            for method, smooth in METHODS.items():
                P = keys.resample(FPS, smooth=smooth).positions()
                vals[method]["jerk"].append(mean_jerk(P, FPS))
                vals[method]["peak_hand_speed"].append(
                    float(np.linalg.norm(np.diff(P[:, hands], axis=0), axis=-1).max() * FPS))
        out[emotion] = {m: {k: float(np.mean(v)) for k, v in d.items()} for m, d in vals.items()}
    return out


def call_ms(repeats: int = 20) -> dict:
    """Milliseconds of one upsampling call per method: a 10 s walk at 7.5 Hz (21 joints) to 30 fps."""
    keys = network_rate(shipped_walk(STYLE_OF_EMOTION["neutral"]))
    out = {}
    for method, smooth in METHODS.items():
        t0 = time.perf_counter()
        for _ in range(repeats):
            keys.resample(FPS, smooth=smooth)
        out[method] = 1e3 * (time.perf_counter() - t0) / repeats
    out["frames_in"] = keys.num_frames
    return out


def hand_speed(motion: Motion, seconds: float = 3.0) -> np.ndarray:
    """(T,) speed of the right hand, m/s, over the first ``seconds``."""
    hand = motion.skeleton.joints.index("right_hand")
    P = motion.positions()[: int(seconds * motion.fps) + 2, hand]
    return np.linalg.norm(np.diff(P, axis=0), axis=-1) * motion.fps


def figure(path: Path, steps: int) -> None:
    """The right hand's speed over 3 s: a generated angry walk and the real angry take, both ways."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    net = load_default_model(weights="real")
    raw = generate_gaits([None], [paths.straight(10.0)], np.eye(4)[[GAIT_EMOTIONS.index("angry")]], steps=steps,
                         fps_out=net.fps, model=net, foot_cleanup=False)[0]
    take = shipped_walk(STYLE_OF_EMOTION["angry"])
    keys = network_rate(take)
    fig, axes = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    for ax, (title, source) in zip(axes, (("generated angry walk (real-trained weights)", raw),
                                          ("real angry take, every 4th frame kept", keys))):
        if source is keys:
            v = hand_speed(take)
            ax.plot(np.arange(len(v)) / take.fps, v, color="0.6", lw=3, label="capture (30 fps)")
        for method, smooth in METHODS.items():
            v = hand_speed(source.resample(FPS, smooth=smooth))
            ax.plot(np.arange(len(v)) / FPS, v, lw=1.2, label=f"{method} to 30 fps")
        ax.set_title(title, fontsize=10)
        ax.set_ylabel("right hand speed, m/s")
        ax.legend(fontsize=8, loc="upper right")
    axes[-1].set_xlabel("s")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=76, help="network steps of each generated walk (7.5 per second)")
    ap.add_argument("--out", default=str(doc_tables.area_files("upsampling")[0]))
    ap.add_argument("--figure", type=Path, default=ROOT / "docs" / "img" / "upsampling_hand_speed.png")
    a = ap.parse_args(argv)
    torch.set_num_threads(1)
    t0 = time.time()
    res = {"date": datetime.date.today().isoformat(), "commit": commit_label(),
           "command": shlex.join(["python", "-m", "benchmarks.bench_upsampling", *argv]),
           "machine": machine_label("1 torch thread"),
           "real_round_trip": real_round_trip(), "generated": generated(a.steps), "gestures": gestures(),
           "call_ms": call_ms()}
    figure(a.figure, a.steps)
    res["seconds"] = time.time() - t0
    for name, lines in doc_tables.render_tables("upsampling", res).items():
        print(f"\n{name}\n" + "\n".join(lines))
    doc_tables.write_results("upsampling", Path(a.out), res, res["seconds"])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
