"""Does seed 004's averaged neutral base keep the energy of the real normal walks it was averaged from?

Averaging aligned cycles can flatten amplitudes, which would make the unstyled base look calmer (more tired) than
any real walker. This measures the base as the plans walk it (the ``rbf`` generator at weight 0: 3 cycles of the
shipped real base, ``generation/data/rbf/neutral_real.npz``, feet planted, 30 fps) with the five affect measures of
:mod:`generation.gait.affect_measures` (speed, arm swing, elbow angle, head pitch, pelvis bounce; lengths in walker
heights) and places each value among the real straight normal walks of the Bandai Namco corpus (Kobayashi et al.
2023, arXiv:2306.08861, CC BY-NC 4.0; both datasets, train and test takes): the real minimum and maximum and the
share of real walks below the base (its percentile).

    OMP_NUM_THREADS=1 python -m benchmarks.bench_rbf_base_energy [--corpus var/mocap/bandai-namco.npz] \
        [--json docs/benchmarks/rbf_base_energy.json]

Needs the real corpus (docs/corpus.md); about 10 s on the 2-core machine.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from generation.gait.affect_measures import MEASURES, walk_measures
from generation.mocap.real_corpus import DEFAULT_PATH
from generation.plans.generators.neutral_walk import base_cycle
from generation.rbf.real_neutral import corpus_normal_walks
from generation.rbf.stylise import stylise

N_CYCLES = 3


def real_rows(corpus: Path) -> list[dict]:
    """The five measures of every straight normal walk of the corpus (train and test splits)."""
    rows = []
    for split in ("train", "test"):
        for clip in corpus_normal_walks(corpus, split=split):
            rows.append({"name": clip.name, "dataset": clip.dataset, "split": split, **walk_measures(clip.motion)})
    return rows


def base_row() -> dict:
    """The five measures of the real base as the plans walk it (weight 0, all features, no tempo change)."""
    walk = stylise(base_cycle("real"), "happy", 0.0, 10, n_cycles=N_CYCLES)
    return walk_measures(walk)


def placement(base: dict, real: list[dict]) -> dict:
    """Per measure: the base's value, the real minimum/maximum, the share of real walks below it, inside or not."""
    out = {}
    for k in MEASURES:
        values = np.array([r[k] for r in real])
        out[k] = {"base": base[k], "real_min": float(values.min()), "real_max": float(values.max()),
                  "percentile": float((values < base[k]).mean() * 100),
                  "inside": bool(values.min() <= base[k] <= values.max())}
    return out


def render(result: dict) -> str:
    units = {"speed": "heights/s", "arm_swing": "heights", "elbow_deg": "deg", "head_pitch_deg": "deg",
             "bounce": "heights"}
    lines = ["| measure | base (walked as the plans do) | real normal walks: min - max | real walks below the base |",
             "|---|---|---|---|"]
    for k, p in result["placement"].items():
        mark = "" if p["inside"] else " **(outside)**"
        lines.append(f"| {k} ({units[k]}) | {p['base']:.4f}{mark} | {p['real_min']:.4f} - {p['real_max']:.4f} | "
                     f"{p['percentile']:.0f} % |")
    lines.append(f"\n{result['n_real']} real normal walks ({result['n_by_dataset']}).")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", type=Path, default=DEFAULT_PATH)
    ap.add_argument("--json", type=Path, default=Path("docs/benchmarks/rbf_base_energy.json"))
    args = ap.parse_args(argv)
    if not args.corpus.is_file():
        ap.error(f"{args.corpus}: no real corpus (build it as docs/corpus.md says)")
    t0 = time.time()
    real = real_rows(args.corpus)
    datasets = sorted({r["dataset"] for r in real})
    result = {"date": time.strftime("%Y-%m-%d"), "machine": "2-core shared CPU, no GPU", "n_real": len(real),
              "n_by_dataset": ", ".join(f"{d}: {sum(r['dataset'] == d for r in real)}" for d in datasets),
              "n_cycles": N_CYCLES, "placement": placement(base_row(), real), "real": real,
              "licence": "CC BY-NC 4.0 (Bandai Namco Research Motion Dataset)"}
    result["seconds"] = round(time.time() - t0, 1)
    args.json.write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
    print(render(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
