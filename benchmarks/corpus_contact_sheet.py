"""Contact sheets of the synthetic procedural motions (matplotlib stick figures).

Writes ``docs/img/corpus_gait_emotions.png`` (side and front views, a few frames per gait emotion),
``docs/img/corpus_gait_paths.png`` (top view of walks on straight, curved and sharp-turn paths with
their footprints) and ``docs/img/corpus_gesture_emotions.png`` (seated gestures per emotion).

Usage: python -m benchmarks.corpus_contact_sheet [--out docs/img]
"""
from __future__ import annotations

import argparse
import os
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import torch

from generation.core import paths
from generation.procedural.emotion import GAIT_EMOTIONS, gait_params_for_emotion, gesture_params_for_vad
from generation.procedural.gesture import seated_gesture
from generation.procedural.walk import walk, walk_with_contacts
from protocol.vocabulary import GESTURE_VAD

torch.set_num_threads(1)


def _bone_color(skeleton, j):
    name = skeleton.joints[j]
    if name.startswith("left_"):
        return "tab:blue"
    if name.startswith("right_"):
        return "tab:red"
    return "k"


def draw(ax, skeleton, pos, horiz_axis, offset=0.0, alpha=1.0):
    """Stick figure of one pose (J, 3) projected onto (horiz_axis, y)."""
    for j, p in enumerate(skeleton.parents):
        if p < 0:
            continue
        ax.plot([pos[p, horiz_axis] + offset, pos[j, horiz_axis] + offset], [pos[p, 1], pos[j, 1]],
                color=_bone_color(skeleton, j), lw=1.6, alpha=alpha, solid_capstyle="round")
    head = skeleton.joints.index("head")
    ax.plot(pos[head, horiz_axis] + offset, pos[head, 1], "o", color="k", ms=4, alpha=alpha)


def gait_sheet(out: Path):
    frames = [0, 6, 12, 18, 24]
    fig, axes = plt.subplots(len(GAIT_EMOTIONS), 2, figsize=(13, 2.6 * len(GAIT_EMOTIONS)),
                             gridspec_kw={"width_ratios": [3.2, 1]})
    for row, emotion in enumerate(GAIT_EMOTIONS):
        vec = np.eye(4)[row]
        params = gait_params_for_emotion(vec, np.random.default_rng(0), jitter=0.0)
        motion = walk(params, n_frames=40)
        pos = motion.positions()
        ax = axes[row, 0]
        for i, f in enumerate(frames):
            # side view: forward (z) horizontal, shifted so figures sit side by side
            draw(ax, motion.skeleton, pos[f], 2, offset=i * 1.1 - pos[f, 0, 2])
        ax.axhline(0.0, color="0.6", lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlim(-0.7, len(frames) * 1.1 - 0.4)
        ax.set_ylim(-0.05, 1.85)
        ax.set_xticks([])
        ax.set_ylabel(f"{emotion}\n{params.speed_mps:.2f} m/s", fontsize=11)
        if row == 0:
            ax.set_title("side view (facing right), frames " + ", ".join(map(str, frames)) + " at 30 fps")
        ax = axes[row, 1]
        f = frames[2]
        draw(ax, motion.skeleton, pos[f], 0, offset=-pos[f, 0, 0])
        ax.axhline(0.0, color="0.6", lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlim(-0.6, 0.6)
        ax.set_ylim(-0.05, 1.85)
        ax.set_xticks([])
        if row == 0:
            ax.set_title("front view")
    fig.suptitle("Synthetic procedural gaits per emotion (pure emotion vectors, no jitter)")
    fig.tight_layout()
    fig.savefig(out / "corpus_gait_emotions.png", dpi=80)
    plt.close(fig)


def paths_sheet(out: Path):
    cases = [("straight", paths.straight(12)), ("curved r=3 m, 120 deg", paths.curved(3.0, np.radians(120), 12)),
             ("sharp turn 90 deg", paths.sharp_turn(np.radians(-90), 12))]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.6))
    for ax, (title, path) in zip(axes, cases):
        res = walk_with_contacts(gait_params_for_emotion(np.eye(4)[3], np.random.default_rng(0), jitter=0.0),
                                 path, n_frames=240)
        pos = res.motion.positions()
        ax.plot(path.points[:, 0], path.points[:, 1], color="0.7", lw=3, label="path")
        ax.plot(pos[:, 0, 0], pos[:, 0, 2], color="k", lw=1, label="root")
        for f, c in ((0, "tab:blue"), (1, "tab:red")):
            heel = pos[:, 3 if f == 0 else 7]
            toe = pos[:, 4 if f == 0 else 8]
            ax.plot(heel[res.heel_contact[:, f], 0], heel[res.heel_contact[:, f], 2], ".", color=c, ms=3)
            ax.plot(toe[res.toe_contact[:, f], 0], toe[res.toe_contact[:, f], 2], "x", color=c, ms=3)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(title)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("z (m)")
    axes[0].legend(loc="lower right", fontsize=8)
    fig.suptitle("Top view: neutral synthetic walk, 8 s; dots = planted heels, x = planted toes (blue left, red right)")
    fig.tight_layout()
    fig.savefig(out / "corpus_gait_paths.png", dpi=80)
    plt.close(fig)


def gesture_sheet(out: Path):
    emotions = ["sad", "neutral", "proud", "angry", "afraid", "amused"]
    side_frames = [0, 30, 50, 80, 119]
    front_frames = [30, 50, 80]
    fig, axes = plt.subplots(len(emotions), 2, figsize=(13, 2.4 * len(emotions)),
                             gridspec_kw={"width_ratios": [len(side_frames), 0.85 * len(front_frames)]})
    for row, word in enumerate(emotions):
        v, a, d = GESTURE_VAD[word]
        rng = np.random.default_rng(1)
        params = [gesture_params_for_vad(v, a, d, rng, kind=k) for k in ("descriptive", "pointing", "beat")]
        motion = seated_gesture(params, n_frames=120, seed=1)
        pos = motion.positions()
        seat = motion.metadata["seat_height_m"]
        ax = axes[row, 0]
        for i, f in enumerate(side_frames):
            draw(ax, motion.skeleton, pos[f], 2, offset=i * 1.0)
            ax.plot([i * 1.0 - 0.15, i * 1.0 + 0.35], [seat, seat], color="saddlebrown", lw=3, alpha=0.5)
        ax.axhline(0.0, color="0.6", lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlim(-0.5, len(side_frames) * 1.0 - 0.2)
        ax.set_ylim(-0.05, 1.45)
        ax.set_xticks([])
        ax.set_ylabel(f"{word}\nV{v:.2f} A{a:.2f} D{d:.2f}", fontsize=10)
        if row == 0:
            ax.set_title("side view (facing right), frames " + ", ".join(map(str, side_frames)) + " (30 fps)")
        ax = axes[row, 1]
        for i, f in enumerate(front_frames):
            draw(ax, motion.skeleton, pos[f], 0, offset=i * 0.85)
        ax.axhline(0.0, color="0.6", lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlim(-0.5, len(front_frames) * 0.85 - 0.35)
        ax.set_ylim(-0.05, 1.45)
        ax.set_xticks([])
        if row == 0:
            ax.set_title("front view, frames " + ", ".join(map(str, front_frames)))
    fig.suptitle("Synthetic procedural seated gestures per emotion (descriptive, pointing, beat; right-handed)")
    fig.tight_layout()
    fig.savefig(out / "corpus_gesture_emotions.png", dpi=80)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="docs/img")
    parser.add_argument("--only", choices=["gait", "paths", "gesture"], default=None)
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.only in (None, "gait"):
        gait_sheet(out)
    if args.only in (None, "paths"):
        paths_sheet(out)
    if args.only in (None, "gesture"):
        gesture_sheet(out)
    print(f"wrote contact sheets to {out}")


if __name__ == "__main__":
    main()
