"""Train the gesture network on the synthetic corpus: ``python -m generation.gesture.train`` (or
``python manage.py train_gesture``).

Seed 003 section 5.2: Adam, learning rate 1e-3 decayed by 0.999 every epoch, batches of 16 drawn without
replacement, weight decay (the lambda ||W|| term of eq. 11), 80/10/10 split. Teacher forcing over whole sequences
with the decoder's self-attention limited to the past ``window`` = 20 steps, which is exactly what autoregressive
generation sees; small Gaussian noise on the teacher-forced input poses makes the network robust to its own
errors at generation time, and so does parallel scheduled sampling (part of the inputs are the network's own
predictions). Every 5 epochs the validation gestures are generated autoregressively from text and attributes and
their pose error decides which weights are kept. A fixed seed makes runs repeatable; checkpoints (model,
optimiser, epoch, history) are written every epoch and ``--resume`` continues from the last one. The best model
is saved as plain weights (config + state dict, float32).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch

from generation.core.skeleton import GESTURE_PARENTS

from . import config
from .data import SYNTHETIC_LABEL, GestureDataset, build_dataset
from .generate import decode_examples
from .losses import LossWeights, total_loss
from .metrics import dataset_pose_error
from .model import GestureNet, GestureNetConfig


@dataclass
class TrainConfig:
    """Training options; the defaults train the shipped weights (20 minutes of wall clock on one thread)."""

    epochs: int = 400
    batch_size: int = 16
    lr: float = 1e-3
    lr_decay: float = 0.999  # per epoch
    weight_decay: float = 1e-5
    input_noise: float = 0.02
    # Parallel scheduled sampling (Duckworth et al. 2019): this share of the teacher-forced inputs is replaced
    # by the network's own (no-grad) predictions, ramped up linearly over the first ``sampling_ramp`` epochs.
    sampling: float = 0.5
    sampling_ramp: int = 15
    sampling_passes: int = 1
    seed: int = 0
    variants: int = 2
    max_minutes: float | None = 20.0  # stop (and keep the best model) after this wall-clock time
    loss: LossWeights = field(default_factory=LossWeights)
    model: GestureNetConfig = field(default_factory=GestureNetConfig)
    out: str = str(config.DEFAULT_WEIGHTS)
    checkpoint: str = str(config.VAR_DIR / "checkpoints" / "gesture_net.pt")
    resume: bool = False
    threads: int = 1
    # Every this many epochs, generate the validation gestures autoregressively and measure their pose error;
    # the best model is chosen by it (0: choose by the teacher-forced validation loss instead).
    rollout_every: int = 5


def _self_fed_inputs(net, b: dict, share: float, passes: int, generator: torch.Generator) -> torch.Tensor:
    """Inputs where a random ``share`` of the frames are the network's own previous predictions (no grad)."""
    inputs = b["inputs"]
    with torch.no_grad():
        for _ in range(passes):
            pred = net(b["tokens"], b["token_mask"], b["attributes"], inputs, b["positions"], b["progress"],
                       b["rest"])
            own = torch.cat((b["inputs"][:, :1], pred[:, :-1]), dim=1)
            pick = torch.rand(inputs.shape[:2], generator=generator) < share
            pick[:, 0] = False  # the start-of-sequence pose is always given
            inputs = torch.where(pick[..., None, None], own, b["inputs"])
    return inputs


def _run_epoch(net, data: GestureDataset, idx: np.ndarray, cfg: TrainConfig, optimizer=None,
               generator: torch.Generator | None = None, sampling: float = 0.0) -> dict[str, float]:
    """One pass over examples ``idx``; trains when an optimiser is given. Returns mean loss terms."""
    training = optimizer is not None
    net.train(training)
    if training:
        perm = torch.randperm(len(idx), generator=generator).numpy()
        idx = idx[perm]
    sums: dict[str, float] = {}
    count = 0
    for start in range(0, len(idx), cfg.batch_size):
        b = data.batch(idx[start:start + cfg.batch_size], noise=cfg.input_noise if training else 0.0,
                       generator=generator)
        inputs = b["inputs"]
        if training and sampling > 0:
            net.eval()
            inputs = _self_fed_inputs(net, b, sampling, cfg.sampling_passes, generator)
            net.train()
        with torch.set_grad_enabled(training):
            pred = net(b["tokens"], b["token_mask"], b["attributes"], inputs, b["positions"], b["progress"],
                       b["rest"])
            loss, parts = total_loss(pred, b["targets"], b["mask"], b["offsets"], GESTURE_PARENTS, cfg.loss)
        if training:
            optimizer.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(net.parameters(), 1.0)
            optimizer.step()
        n = len(b["tokens"])
        count += n
        sums["total"] = sums.get("total", 0.0) + float(loss.detach()) * n
        for k, v in parts.items():
            sums[k] = sums.get(k, 0.0) + v * n
    return {k: v / max(count, 1) for k, v in sums.items()}


def save_weights(net: GestureNet, path: str | Path, extra: dict) -> None:
    """Write {config, state_dict (float32), train_fps, ...} to ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    torch.save({"config": net.cfg.to_dict(), "state_dict": {k: v.detach().float().clone()
                                                            for k, v in net.state_dict().items()},
                "train_fps": config.TRAIN_FPS, "trained_on": SYNTHETIC_LABEL, **extra}, path)


def train(cfg: TrainConfig, data: GestureDataset | None = None, progress: bool = True) -> dict:
    """Train and save; returns {"history": [...], "best_val": float, "epochs_run": int, "seconds": float, "out"}."""
    from tqdm import tqdm

    torch.set_num_threads(cfg.threads)
    torch.manual_seed(cfg.seed)
    np.random.seed(cfg.seed)
    data = data if data is not None else build_dataset(variants=cfg.variants, seed=cfg.seed)
    train_idx, val_idx = data.indices("train"), data.indices("val")
    if len(train_idx) == 0:
        raise ValueError("the training split is empty")
    net = GestureNet(cfg.model)
    optimizer = torch.optim.Adam(net.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    scheduler = torch.optim.lr_scheduler.ExponentialLR(optimizer, gamma=cfg.lr_decay)
    generator = torch.Generator().manual_seed(cfg.seed)
    history: list[dict] = []
    best_val, best_state, start_epoch, best_epoch = float("inf"), None, 0, -1
    selected_by = "val_rollout_pose_error" if cfg.rollout_every > 0 else "val_loss"
    seconds_before = 0.0  # wall-clock seconds of earlier (resumed) segments
    ckpt_path = Path(cfg.checkpoint)
    if cfg.resume and ckpt_path.is_file():
        ckpt = torch.load(ckpt_path, weights_only=False)
        if ckpt["model_config"] != cfg.model.to_dict():
            raise ValueError(f"{ckpt_path}: checkpoint model config {ckpt['model_config']} differs from the "
                             f"requested {cfg.model.to_dict()}")
        net.load_state_dict(ckpt["state_dict"])
        optimizer.load_state_dict(ckpt["optimizer"])
        scheduler.load_state_dict(ckpt["scheduler"])
        generator.set_state(ckpt["generator"])
        history, best_val, best_state = ckpt["history"], ckpt["best_val"], ckpt["best_state"]
        best_epoch = ckpt.get("best_epoch", -1)
        if ckpt.get("selected_by") != selected_by:  # scores on another scale: start the selection afresh
            best_val, best_state, best_epoch = float("inf"), None, -1
        start_epoch = ckpt["epoch"] + 1
        seconds_before = float(ckpt.get("seconds", 0.0))
    t0 = time.time()
    bar = tqdm(range(start_epoch, cfg.epochs), desc="gesture net", disable=not progress, unit="epoch")
    epoch = start_epoch - 1
    for epoch in bar:
        share = cfg.sampling * min(1.0, epoch / max(cfg.sampling_ramp, 1))
        tr = _run_epoch(net, data, train_idx, cfg, optimizer, generator, sampling=share)
        scheduler.step()
        with torch.no_grad():
            va = _run_epoch(net, data, val_idx, cfg) if len(val_idx) else tr
        entry = {"epoch": epoch, "train": tr, "val": va, "lr": scheduler.get_last_lr()[0]}
        last_epoch = epoch == cfg.epochs - 1 or (cfg.max_minutes is not None
                                                 and (time.time() - t0) > 60 * cfg.max_minutes)
        score = None
        if cfg.rollout_every > 0 and len(val_idx) and ((epoch + 1) % cfg.rollout_every == 0 or last_epoch):
            net.eval()
            entry["val_rollout"] = dataset_pose_error(decode_examples(net, data, val_idx), data, val_idx)
            score = entry["val_rollout"]["pose_error"]
        elif cfg.rollout_every <= 0:
            score = va["total"]
        history.append(entry)
        if score is not None and score < best_val:
            best_val = score
            best_state = {k: v.detach().clone() for k, v in net.state_dict().items()}
            best_epoch = epoch
        bar.set_postfix(train=f"{tr['total']:.4f}", val=f"{va['total']:.4f}", best=f"{best_val:.4f}")
        ckpt_path.parent.mkdir(parents=True, exist_ok=True)
        torch.save({"epoch": epoch, "state_dict": net.state_dict(), "optimizer": optimizer.state_dict(),
                    "scheduler": scheduler.state_dict(), "generator": generator.get_state(), "history": history,
                    "best_val": best_val, "best_state": best_state, "best_epoch": best_epoch,
                    "selected_by": selected_by, "seconds": seconds_before + time.time() - t0,
                    "model_config": cfg.model.to_dict()},
                   ckpt_path)
        if last_epoch:
            break
    seconds = seconds_before + time.time() - t0
    if best_state is not None:
        net.load_state_dict(best_state)
    summary = {"epochs_run": epoch + 1, "best_val": best_val, "best_epoch": best_epoch,
               "selected_by": selected_by,
               "seconds": seconds, "out": cfg.out}
    save_weights(net, cfg.out, {"loss_weights": dataclasses.asdict(cfg.loss), "train_config": _jsonable(cfg),
                                "history": history, **{k: v for k, v in summary.items() if k != "out"}})
    summary["history"] = history
    return summary


def _jsonable(cfg: TrainConfig) -> dict:
    return json.loads(json.dumps(dataclasses.asdict(cfg), default=str))


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description="Train the Text2Gestures network (seed 003) on the synthetic corpus.")
    d = TrainConfig()
    p.add_argument("--epochs", type=int, default=d.epochs)
    p.add_argument("--batch-size", type=int, default=d.batch_size)
    p.add_argument("--lr", type=float, default=d.lr)
    p.add_argument("--weight-decay", type=float, default=d.weight_decay)
    p.add_argument("--seed", type=int, default=d.seed)
    p.add_argument("--variants", type=int, default=d.variants, help="procedural gestures per sentence")
    p.add_argument("--max-minutes", type=float, default=d.max_minutes,
                   help="wall-clock budget in minutes (0 = none); keeps the best model")
    p.add_argument("--sampling", type=float, default=d.sampling, help="share of self-fed decoder inputs")
    p.add_argument("--input-noise", type=float, default=d.input_noise)
    p.add_argument("--residual", choices=("previous", "rest", "none"), default=d.model.residual)
    p.add_argument("--no-angle-loss", action="store_true")
    p.add_argument("--no-pose-loss", action="store_true")
    p.add_argument("--no-affective-loss", action="store_true")
    p.add_argument("--d-model", type=int, default=d.model.d_model)
    p.add_argument("--out", default=d.out, help="where the best weights go")
    p.add_argument("--checkpoint", default=d.checkpoint)
    p.add_argument("--resume", action="store_true", help="continue from --checkpoint")
    p.add_argument("--threads", type=int, default=d.threads)
    p.add_argument("--quiet", action="store_true")
    return p


def config_from_args(args: argparse.Namespace) -> TrainConfig:
    base = LossWeights()
    loss = LossWeights(angle=0.0 if args.no_angle_loss else base.angle, pose=0.0 if args.no_pose_loss else base.pose,
                       affective=0.0 if args.no_affective_loss else base.affective)
    return TrainConfig(epochs=args.epochs, batch_size=args.batch_size, lr=args.lr, weight_decay=args.weight_decay,
                       seed=args.seed, variants=args.variants, max_minutes=args.max_minutes or None, loss=loss,
                       sampling=args.sampling, input_noise=args.input_noise,
                       model=GestureNetConfig(d_model=args.d_model, residual=args.residual), out=args.out,
                       checkpoint=args.checkpoint,
                       resume=args.resume, threads=args.threads)


def main(argv: list[str] | None = None) -> dict:
    args = build_parser().parse_args(argv)
    summary = train(config_from_args(args), progress=not args.quiet)
    last = summary["history"][-1] if summary["history"] else {}
    print(f"trained {summary['epochs_run']} epochs in {summary['seconds']:.0f} s; best val loss "
          f"{summary['best_val']:.5f}; last {json.dumps(last.get('val', {}))}; weights -> {summary['out']}")
    return summary


if __name__ == "__main__":
    main()
