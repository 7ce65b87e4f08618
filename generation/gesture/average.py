"""Weight averaging of a fine-tuning run: ``python -m generation.gesture.average``.

The epochs of a fine-tune written by ``train --keep-rollouts DIR`` (one weights file per epoch) are averaged over a
window (stochastic weight averaging, Izmailov et al. 2018) and the average is interpolated with the weights the
fine-tune started from (WiSE-FT, Wortsman et al. 2022): ``init_share`` x start + (1 - init_share) x mean of the
window. Both runs share one initialisation, so their parameters can be averaged; the average is smoother than any one
epoch (lower rollout pose error) and the interpolation keeps part of the starting weights' behaviour. The result is
measured on the validation split (rollout pose error, r(peak wrist speed, arousal), share inside the real range of
:mod:`generation.gesture.selection`) and written with those figures and the run's record.

    python -m generation.gesture.average --run var/gesture/realrange/sel_w5.pt \
        --epochs-dir var/gesture/realrange/sel_w5_epochs --first 20 --init-share 0.2 --out OUT.pt
"""
from __future__ import annotations

import argparse
import os
from pathlib import Path

import torch

from generation.core.digest import file_sha256

from . import config
from .data import build_dataset
from .generate import decode_examples, load_model
from .metrics import dataset_pose_error
from .selection import real_range_rollout


def average_states(states: list[dict], shares: list[float]) -> dict:
    """The weighted mean of state dicts with the same keys and shapes; ``shares`` >= 0, normalised to sum 1."""
    if not states or len(states) != len(shares):
        raise ValueError(f"need one share per state, got {len(states)} states and {len(shares)} shares")
    if min(shares) < 0 or sum(shares) <= 0:
        raise ValueError(f"shares must be >= 0 with a positive sum, got {shares}")
    total = float(sum(shares))
    return {k: sum(float(w) / total * s[k].float() for s, w in zip(states, shares)) for k in states[0]}


def _state(path: Path) -> dict:
    return torch.load(path, map_location="cpu", weights_only=False)["state_dict"]


def main(argv: list[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--run", required=True, help="the run's weights file (its record and starting weights are read)")
    p.add_argument("--epochs-dir", required=True, help="the run's --keep-rollouts folder (epochNNN.pt)")
    p.add_argument("--first", type=int, default=0, help="first epoch of the window")
    p.add_argument("--last", type=int, default=None, help="last epoch of the window (default: the last written)")
    p.add_argument("--init-share", type=float, default=0.0, help="share of the starting weights (--init-from)")
    p.add_argument("--init", default=None, help="the starting weights (default: the run's init_from)")
    p.add_argument("--out", required=True)
    args = p.parse_args(argv)
    for what, path in (("--run", Path(args.run)), ("--epochs-dir", Path(args.epochs_dir))):
        if not path.exists():
            raise SystemExit(f"{what}: no such file or folder {str(path)!r}")
    run = torch.load(args.run, map_location="cpu", weights_only=False)
    files = sorted(Path(args.epochs_dir).glob("epoch*.pt"))
    epochs = [int(f.stem[5:]) for f in files]
    last = max(epochs) if args.last is None else args.last
    window = [(e, f) for e, f in zip(epochs, files) if args.first <= e <= last]
    if not window:
        raise SystemExit(f"no epoch files in {args.epochs_dir} between {args.first} and {last}")
    init = args.init or run["train_config"].get("init_from")
    if not 0.0 <= args.init_share < 1.0 or (args.init_share and not init):
        raise SystemExit("--init-share must be in [0, 1) and needs the starting weights (--init or the run's)")
    if args.init_share and not Path(init).is_file():
        raise SystemExit(f"--init: the starting weights {str(init)!r} are not a file")
    states = [_state(f) for _, f in window]
    shares = [(1.0 - args.init_share) / len(window)] * len(window)
    if args.init_share:
        states.append(_state(Path(init)))
        shares.append(args.init_share)
    run["state_dict"] = average_states(states, shares)
    net = load_model(args.run)
    net.load_state_dict(run["state_dict"])
    # the validation split does not depend on --augment; cached in $GESTURE_VAR_DIR, else var/gesture
    data = build_dataset(augment=0, cache_dir=config.var_dir(os.environ))
    val = data.indices("val")
    figures = {"val_rollout": dataset_pose_error(decode_examples(net, data, val), data, val),
               "val_real_range": real_range_rollout(net, data, val)}
    run["averaged"] = {"epochs": [e for e, _ in window], "init": str(init) if args.init_share else None,
                       "init_sha256": file_sha256(init) if args.init_share else None,
                       "init_share": args.init_share, "run": str(args.run), **figures}
    run["best_epoch"], run["selected_by"] = None, "weight average (see 'averaged')"
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    torch.save(run, args.out)
    print(f"{args.out}: epochs {window[0][0]}-{window[-1][0]} ({len(window)}) + {args.init_share:g} x start; val pose "
          f"error {figures['val_rollout']['pose_error']:.5f}, r {figures['val_rollout']['r_peak_arousal']:.3f}, "
          f"in real range {figures['val_real_range']['share']:.3f}")
    return run


if __name__ == "__main__":
    main()
