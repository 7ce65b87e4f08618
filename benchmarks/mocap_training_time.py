"""Time the bring-your-own-capture training path of the gait network on a corpus of realistic size.

SYNTHETIC stand-in for a downloaded capture set (no captured data is available offline): ``--takes`` procedural
walks of ``--frames`` frames (30 fps, a quarter each happy, sad, angry, neutral, named ``takeNNN_<emotion>.bvh``)
are written as CMU BVH files, then the documented commands run and are timed (wall and CPU seconds):

    python -m generation.mocap import TAKES --skeleton gait --out IMPORTED --label-pattern '_(?P<emotion>[a-z]+)\\.bvh'
    python -m generation.mocap corpus IMPORTED --out CORPUS --frames 240 --stride STRIDE
    python manage.py train_gait --corpus CORPUS --epochs N --device cpu --threads 1 --quiet

The default (20 takes of 2,400 frames, windows every 24 frames) gives 1,820 windows of 240 frames, about the
1,835 gaits seed 000 trained on (section 5.1). Figures: docs/benchmarks/mocap.md.

Usage: python -m benchmarks.mocap_training_time [--takes 20] [--frames 2400] [--stride 24] [--epochs 2] [--dir DIR]
"""
from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def write_takes(folder: Path, n_takes: int, n_frames: int) -> None:
    import numpy as np

    from generation.procedural.emotion import gait_params_for_emotion
    from generation.procedural.walk import walk
    from protocol.vocabulary import GAIT_EMOTIONS
    from tests.mocap_conventions import export_as

    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(0)
    for k in range(n_takes):
        e = k % len(GAIT_EMOTIONS)
        params = gait_params_for_emotion(np.eye(len(GAIT_EMOTIONS))[e], rng)
        export_as(walk(params, n_frames=n_frames, seed=k), "cmu", folder / f"take{k:03d}_{GAIT_EMOTIONS[e]}.bvh")


def timed(label: str, cmd: list[str]) -> None:
    """Run a command; print its wall and CPU seconds (children's user + system time) and its last lines."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    res = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=dict(os.environ, OMP_NUM_THREADS="1"))
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    tail = (res.stdout + res.stderr).strip().splitlines()[-4:]
    print(f"{label}: wall {time.perf_counter() - t0:.1f} s, cpu {cpu:.1f} s, exit {res.returncode}; "
          f"load {os.getloadavg()[0]:.1f}")
    for line in tail:
        print(f"    {line}")
    if res.returncode not in (0, 1):
        raise SystemExit(f"{label} failed")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--takes", type=int, default=20)
    ap.add_argument("--frames", type=int, default=2400)
    ap.add_argument("--stride", type=int, default=24)
    ap.add_argument("--epochs", type=int, default=2)
    ap.add_argument("--dir", type=Path, help="work folder (default: a temporary one)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        d = a.dir or Path(tmp)
        t0 = time.perf_counter()
        write_takes(d / "takes", a.takes, a.frames)
        print(f"{a.takes} SYNTHETIC takes of {a.frames} frames written in {time.perf_counter() - t0:.1f} s")
        py = sys.executable
        timed("import", [py, "-m", "generation.mocap", "import", str(d / "takes"), "--skeleton", "gait", "--out",
                         str(d / "imported"), "--quiet", "--label-pattern", r"_(?P<emotion>[a-z]+)\.bvh"])
        timed("corpus", [py, "-m", "generation.mocap", "corpus", str(d / "imported"), "--out", str(d / "corpus.npz"),
                         "--frames", "240", "--stride", str(a.stride)])
        timed(f"train_gait, {a.epochs} epochs", [py, "manage.py", "train_gait", "--corpus", str(d / "corpus.npz"),
                                                 "--epochs", str(a.epochs), "--out", str(d / "w.pt"), "--device",
                                                 "cpu", "--threads", "1", "--checkpoint", str(d / "w.ckpt"), "--quiet"])


if __name__ == "__main__":
    main()
