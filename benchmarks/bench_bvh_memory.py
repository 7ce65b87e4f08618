"""Memory of reading a large BVH: a SYNTHETIC take (the shipped Bandai Namco walk's frames repeated to about
--mb MB, made in a temporary folder) parsed by ``generation.formats.bvh.parse_bvh`` in a fresh process of
``--code`` (default: this checkout; an extracted older commit for the "before" row). Reports the file's size and
the process's peak resident memory growth during the parse (ru_maxrss after minus before). Example:

    .venv/bin/python -m benchmarks.bench_bvh_memory --mb 24.6 --code /tmp/before --label before
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TAKE = (ROOT / "generation/data/mocap/bandai-namco/Bandai-Namco-Research-Motiondataset-1/data"
        / "dataset-1_walk_happy_001.bvh")
PARSE = """
import resource, sys, time
from generation.formats.bvh import parse_bvh
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t0 = time.perf_counter()
kwargs = {"max_bytes": None} if "max_bytes" in parse_bvh.__code__.co_varnames else {}
data = parse_bvh(sys.argv[1], **kwargs)
print(data.rotations.shape[0], time.perf_counter() - t0, before, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def synthetic_bvh(path: Path, megabytes: float) -> int:
    """The take's header and its frame lines repeated to about ``megabytes`` MB; returns the frame count."""
    text = TAKE.read_text()
    head, _, rest = text.partition("MOTION")
    lines = rest.strip().splitlines()
    frame_time = lines[1]
    frames = [ln for ln in lines[2:] if ln.strip()]
    per_frame = sum(len(f) + 1 for f in frames) / len(frames)
    n = int(megabytes * 1e6 / per_frame)
    with path.open("w") as f:
        f.write(f"{head}MOTION\nFrames: {n}\n{frame_time}\n")
        for i in range(n):
            f.write(frames[i % len(frames)] + "\n")
    return n


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mb", type=float, default=24.6)
    ap.add_argument("--code", type=Path, default=ROOT)
    ap.add_argument("--label", default="")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bench-bvh-") as tmp:
        path = Path(tmp) / "synthetic_long_walk.bvh"
        frames = synthetic_bvh(path, args.mb)
        out = subprocess.run([sys.executable, "-c", PARSE, str(path)], cwd=args.code, check=True,
                             capture_output=True, text=True).stdout.split()
        size = path.stat().st_size
    n, seconds, before_kib, after_kib = int(out[0]), float(out[1]), int(out[2]), int(out[3])
    growth = (after_kib - before_kib) * 1024
    print(json.dumps({"label": args.label, "file_mb": round(size / 1e6, 1), "frames": n, "frames_written": frames,
                      "parse_s": round(seconds, 2), "peak_growth_mb": round(growth / 1e6, 1),
                      "growth_over_size": round(growth / size, 1)}))


if __name__ == "__main__":
    main()
