"""Fine-tune the gait network on both real corpora (Bandai dataset 1 + the BML walks of 21 training actors) and
choose the epoch on the BML validation actors.

    OMP_NUM_THREADS=1 nice -n 10 python -m generation.gait.train_both --labels acted|soft \
        [--init generation/data/weights/gait_net_real.pt] [--epochs 20] [--max-minutes 30] --out var/gait_both/acted.pt

Starts from ``--init`` (the shipped real-trained weights: pretrained on both Bandai datasets' locomotion and
fine-tuned on dataset 1's four emotion walks) with its configuration (30-step windows, the fine-tuning losses),
trains on :func:`generation.gait.bml_data.load_both_sequences` and writes every epoch's weights
(``<out stem>_eNN.pt``), then copies the epoch of the lowest validation loss (free-running, BML validation actors)
to ``--out`` and writes ``<out stem>_choice.json`` (the per-epoch validation losses and the choice). The weights
record their provenance in the typed ``training_data`` record (real capture of stage ``finetune-both``: both
datasets with licence, citation, performer split and corpus hashes, and the labels). Test actors are never read
here.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
from pathlib import Path

import torch

from generation.mocap.real_corpus import RealCorpora

from .bml_data import LABEL_MODES, load_both_sequences
from .config import GaitNetConfig
from .train import train


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--labels", choices=LABEL_MODES, required=True)
    ap.add_argument("--init", type=Path, default=Path(__file__).resolve().parent.parent / "data" / "weights"
                    / "gait_net_real.pt")
    ap.add_argument("--epochs", type=int, default=20)
    ap.add_argument("--max-minutes", type=float, default=None)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--bandai-windows", type=int, default=None,
                    help="windows per Bandai take (default 12; more weighs the Bandai emotion takes more)")
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args(argv)
    torch.set_num_threads(a.threads)
    payload = torch.load(a.init, map_location="cpu", weights_only=False)
    config = GaitNetConfig.from_dict(payload["config"])
    config.train.epochs = a.epochs
    corpora = RealCorpora.from_environ(os.environ)   # $REAL_CORPUS and $BML_CORPUS, else var/mocap/
    data = load_both_sequences(config.data, a.labels, corpora.bandai, corpora.bml, bandai_windows=a.bandai_windows)
    n = {s: int(((data.split == s) & (data.offset == 0)).sum()) for s in ("train", "val")}
    print(f"{len(data)} rows ({n}); init {a.init}", flush=True)
    result = train(config, data, a.out, init=a.init, keep_epochs=True, max_minutes=a.max_minutes,
                   progress=not a.quiet, device="cpu")
    history = result["history"]
    val = [(h["epoch"], h["val"].get("total", float("inf"))) for h in history]
    best = min(val, key=lambda x: x[1])[0]
    chosen = a.out.with_name(f"{a.out.stem}_e{best:02d}{a.out.suffix}")
    shutil.copyfile(chosen, a.out)
    a.out.with_name(f"{a.out.stem}_choice.json").write_text(json.dumps(
        {"labels": a.labels, "init": str(a.init), "bandai_windows": a.bandai_windows, "epochs_run": len(history),
         "val_total": dict(val),
         "chosen_epoch": best, "rule": "lowest free-running validation loss on the BML validation actors",
         "minutes": history[-1]["elapsed_s"] / 60 if history else 0}, indent=1) + "\n")
    print(f"chose epoch {best} (val {dict(val)[best]:.4f}) -> {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
