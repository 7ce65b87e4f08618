"""Stick-figure contact sheet of the captured DeepMimic walks retargeted onto the gait skeleton.

Writes docs/img/core_features_captured_walks.png: for each clip, side views (z forward, y up) at 6 frames with
the left side in blue and the right in red, plus a top view of the root path and the foot contacts.

Usage: python -m benchmarks.core_captured_walk_sheet [out.png]
"""
from __future__ import annotations

import sys
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from generation.core.features import detect_foot_contacts
from generation.mocap.captured import captured_walks

matplotlib.use("Agg")
ROOT = Path(__file__).resolve().parents[1]


def main(out: Path) -> None:
    walks = captured_walks()
    n_frames = 6
    fig, axes = plt.subplots(len(walks), n_frames + 1, figsize=(2.0 * (n_frames + 1), 2.6 * len(walks)))
    for row, motion in enumerate(walks):
        P = motion.positions()
        sk = motion.skeleton
        contacts = detect_foot_contacts(P, motion.fps, sk)
        frames = np.linspace(0, motion.num_frames - 1, n_frames).round().astype(int)
        for k, t in enumerate(frames):
            ax = axes[row, k]
            for j, p in enumerate(sk.parents):
                if p < 0:
                    continue
                name = sk.joints[j]
                color = "tab:blue" if name.startswith("left_") else "tab:red" if name.startswith("right_") else "k"
                # side view: forward axis of the clip's overall direction on x, height on y
                ax.plot([P[t, p, 2], P[t, j, 2]], [P[t, p, 1], P[t, j, 1]], color=color, lw=2)
            ax.axhline(0.0, color="0.6", lw=1)
            cz = P[t, 0, 2]
            ax.set_xlim(cz - 0.7, cz + 0.7)
            ax.set_ylim(-0.05, 1.85)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([0, 0.5, 1.0, 1.5] if k == 0 else [])
            lc = "L" if contacts[t, 0] else "-"
            rc = "R" if contacts[t, 1] else "-"
            ax.set_title(f"f{t} {lc}{rc}", fontsize=8)
        ax = axes[row, -1]
        ax.plot(P[:, 0, 0], P[:, 0, 2], "k-", lw=1)
        for side, color, joint in ((0, "tab:blue", "left_toe"), (1, "tab:red", "right_toe")):
            j = sk.index(joint)
            ax.plot(P[contacts[:, side], j, 0], P[contacts[:, side], j, 2], ".", color=color, ms=4)
        xc, half = P[:, 0, 0].mean(), max(0.5, np.ptp(P[:, 0, 2]) / 2)
        ax.set_xlim(xc + half, xc - half)   # +x (left) drawn on the left when looking along +z
        ax.set_aspect("equal")
        ax.tick_params(labelsize=6)
        ax.set_title("top: root, contacts", fontsize=8)
        axes[row, 0].set_ylabel(Path(motion.metadata["source"]).stem, fontsize=8)
    fig.suptitle("Captured DeepMimic walks on the 21-joint gait skeleton (side view, blue = left, red = right)",
                 fontsize=10)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=80)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "img" / "core_features_captured_walks.png")
