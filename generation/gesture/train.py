"""Train the gesture network on the synthetic corpus: ``python -m generation.gesture.train`` (or
``python manage.py train_gesture``).

Seed 003 section 5.2: Adam, learning rate 1e-3 decayed by 0.999 every epoch, batches of 16 drawn without
replacement, weight decay (the lambda ||W|| term of eq. 11), 80/10/10 split. Teacher forcing over whole sequences
with the decoder's self-attention limited to the past ``window`` = 20 steps, which is exactly what autoregressive
generation sees; small Gaussian noise on the teacher-forced input poses and parallel scheduled sampling (a share of
the inputs, up to all of them, are the network's own predictions, refined over a few no-grad passes) train it on
inputs like the ones it feeds itself at generation time. Every 5 epochs the validation gestures are generated
autoregressively from text and attributes; their pose error times (1 + their wrist-speed gap to the corpus)
(:func:`generation.gesture.metrics.selection_score`) decides which weights are kept; with ``--select real-range``
the kept epoch is the one whose validation gestures, generated with each emotion of the real capture, are most often
inside the real captured range, among the epochs whose rollout pose error is at most ``--max-pose-error``
(:mod:`generation.gesture.selection`). A fixed seed makes runs
repeatable; checkpoints (model, optimiser, epoch, history) are written every epoch and ``--resume`` continues from
the last one. The best model is saved as plain weights (config + CPU state dict, float32).

Devices: ``--device auto|cpu|cuda[:N]`` (:func:`generation.core.device.resolve_device`); the corpus is
moved to the device once (:class:`generation.gesture.data.DeviceCorpus`) and batches are cut there; every random
draw (batch order, input noise, self-fed picks) comes from one CPU generator, so a seed gives the same run on any
device up to float rounding. ``--amp`` runs the forward passes under CUDA autocast (ignored on the CPU).
Files are device-independent: CPU tensors, read with ``map_location="cpu"``.

Soft labels: ``--soft-labels clip_norms.csv`` trains on the gestures people rated in a norming study instead of the
synthetic corpus, each with its perceived shares turned into a share-weighted NRC-VAD emotion attribute
(:mod:`generation.gesture.soft_labels`); ``--init-from`` the shipped weights makes it a fine-tune. The weights file's
``corpus.soft_labels`` records the norms (path, sha256, study, clips and ratings); without ``--out`` it writes
``var/weights/gesture_net_soft_labels.pt``, never the shipped weights.

Presets: ``--config small`` (the shipped weights: d_model 64, 269,772 parameters, a 20-minute CPU budget) and
``--config paper`` (the published size, 26.2 M parameters, 600 epochs, no time budget; :func:`paper_config`).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import os
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from generation.core.device import (
    autocast_context,
    cpu_state_dict,
    describe,
    needs_grad_scaler,
    resolve_device,
    to_cpu,
)
from generation.core.skeleton import GESTURE_PARENTS

from . import config
from .data import SYNTHETIC_LABEL, DeviceCorpus, GestureDataset, build_dataset
from .generate import decode_examples
from .losses import LIVELINESS_FORMS, LossWeights, total_loss
from .metrics import dataset_pose_error, selection_score
from .model import MODEL_PRESETS, GestureNet, GestureNetConfig
from .real_range import load_ranges, range_arrays
from .real_range import provenance as real_range_provenance
from .selection import history_score, real_range_rollout
from .soft_labels import SoftLabelError, load_soft_label_dataset

PRESETS = tuple(MODEL_PRESETS)
SELECTIONS = ("pose", "real-range")


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
    # by the network's own (no-grad) predictions, ramped up linearly over the first ``sampling_ramp`` epochs;
    # ``sampling_passes`` no-grad passes each feed the previous pass's predictions back in.
    sampling: float = 1.0
    sampling_ramp: int = 15
    sampling_passes: int = 3
    seed: int = 0
    variants: int = 2
    counterfactual: int = 1  # extra gestures per sentence performed with another emotion (data.build_dataset)
    # extra training sentences recombined from the training sentences' phrases (data.augment_rows); 0 = none
    augment: int = 0
    max_minutes: float | None = 20.0  # stop (and keep the best model) after this wall-clock time
    loss: LossWeights = field(default_factory=LossWeights)
    model: GestureNetConfig = field(default_factory=GestureNetConfig)
    out: str = str(config.DEFAULT_WEIGHTS)
    checkpoint: str = str(config.DEFAULT_VAR_DIR / "checkpoints" / "gesture_net.pt")
    resume: bool = False
    threads: int = 1
    # Every this many epochs, generate the validation gestures autoregressively and measure their pose error;
    # the best model is chosen by it (0: choose by the teacher-forced validation loss instead).
    rollout_every: int = 5
    # add the worst per-emotion wrist-speed ratio on the validation split to the selection score
    # (metrics.selection_score); off for the shipped weights
    select_emotion_gap: bool = False
    # which rollout epoch is kept: "pose" (the score above) or "real-range" (generation.gesture.selection: the largest
    # in-real-range share among epochs with rollout pose error <= max_pose_error, else the lowest pose error)
    select: str = "pose"
    max_pose_error: float = 0.00715
    min_arousal_r: float | None = None  # real-range rule: also require this validation r(peak wrist speed, arousal)
    keep_rollouts: str | None = None  # also write the weights of every rollout epoch into this folder
    init_from: str | None = None  # start from these weights (fine-tuning) instead of a random initialisation
    device: str = "auto"
    amp: bool = False
    preset: str = "small"
    soft_labels: str | None = None  # the clip_norms.csv the rated training gestures come from (soft_labels.py)


def preset_config(name: str = "small", **overrides) -> TrainConfig:
    """The :class:`TrainConfig` of a preset ("small": the shipped weights; "paper": the published size trained for
    600 epochs without a time budget), with ``overrides`` applied."""
    if name not in MODEL_PRESETS:
        raise ValueError(f"unknown gesture config {name!r}; choose one of {', '.join(PRESETS)}")
    base: dict = {"preset": name, "model": MODEL_PRESETS[name]()}
    if name == "paper":
        base.update(epochs=600, max_minutes=None)
    base.update(overrides)
    return TrainConfig(**base)


def _forward(net, b: dict, inputs: torch.Tensor, amp: bool) -> torch.Tensor:
    """The teacher-forced pass (under autocast when ``amp``), returned as float32 unit quaternions."""
    with autocast_context(inputs.device, amp):
        pred = net(b["tokens"], b["token_mask"], b["attributes"], inputs, b["positions"], b["progress"], b["rest"])
    pred = pred.float()
    return pred / pred.norm(dim=-1, keepdim=True).clamp_min(1e-8) if amp else pred


def _self_fed_inputs(net, b: dict, share: float, passes: int, generator: torch.Generator,
                     amp: bool = False) -> torch.Tensor:
    """Inputs where a random ``share`` of the frames are the network's own previous predictions (no grad)."""
    inputs = b["inputs"]
    with torch.no_grad():
        for _ in range(passes):
            pred = _forward(net, b, inputs, amp)
            own = torch.cat((b["inputs"][:, :1], pred[:, :-1]), dim=1)
            pick = torch.rand(inputs.shape[:2], generator=generator) < share
            pick[:, 0] = False  # the start-of-sequence pose is always given
            inputs = torch.where(pick.to(inputs.device)[..., None, None], own, b["inputs"])
    return inputs


def _run_epoch(net, corpus: DeviceCorpus, idx: np.ndarray, cfg: TrainConfig, optimizer=None,
               generator: torch.Generator | None = None, sampling: float = 0.0, amp: bool = False,
               scaler=None) -> dict[str, float]:
    """One pass over examples ``idx``; trains when an optimiser is given. Returns mean loss terms."""
    training = optimizer is not None
    net.train(training)
    if training:
        idx = idx[torch.randperm(len(idx), generator=generator).numpy()]
    sums: dict[str, float] = {}
    count = 0
    for start in range(0, len(idx), cfg.batch_size):
        b = corpus.batch(idx[start:start + cfg.batch_size], noise=cfg.input_noise if training else 0.0,
                         generator=generator)
        bounds = getattr(corpus, "real_bounds", None)
        if bounds is not None:
            pick = torch.as_tensor(np.asarray(idx[start:start + cfg.batch_size])).to(corpus.device)
            bounds = (bounds[0][pick], bounds[1][pick])
        inputs = b["inputs"]
        if training and sampling > 0:
            net.eval()
            inputs = _self_fed_inputs(net, b, sampling, cfg.sampling_passes, generator, amp)
            net.train()
        with torch.set_grad_enabled(training):
            pred = _forward(net, b, inputs, amp)
            loss, parts = total_loss(pred, b["targets"], b["mask"], b["offsets"], GESTURE_PARENTS, cfg.loss,
                                     fps=corpus.fps, real_bounds=bounds)
        if training:
            _step(net, optimizer, loss, scaler)
        n = len(b["tokens"])
        count += n
        sums["total"] = sums.get("total", 0.0) + float(loss.detach()) * n
        for k, v in parts.items():
            sums[k] = sums.get(k, 0.0) + v * n
    return {k: v / max(count, 1) for k, v in sums.items()}


def _step(net, optimizer, loss: torch.Tensor, scaler) -> None:
    """Backward pass, gradient clipping at norm 1 and an optimiser step (through the fp16 scaler when given)."""
    optimizer.zero_grad(set_to_none=True)
    if scaler is None:
        loss.backward()
        torch.nn.utils.clip_grad_norm_(net.parameters(), 1.0)
        optimizer.step()
        return
    scaler.scale(loss).backward()
    scaler.unscale_(optimizer)
    torch.nn.utils.clip_grad_norm_(net.parameters(), 1.0)
    scaler.step(optimizer)
    scaler.update()


def save_weights(net: GestureNet, path: str | Path, extra: dict) -> None:
    """Write {config, state_dict (float32, CPU), train_fps, trained_on, ...} to ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    state = {k: v.float() for k, v in cpu_state_dict(net).items()}
    torch.save({"config": net.cfg.to_dict(), "state_dict": state,
                "train_fps": config.TRAIN_FPS, "trained_on": SYNTHETIC_LABEL, **extra}, path)


@dataclass
class _Run:
    """The mutable state of one training run (what a checkpoint holds besides the network and optimiser)."""

    history: list = field(default_factory=list)
    best_val: float = float("inf")
    best_state: dict | None = None
    best_epoch: int = -1
    start_epoch: int = 0
    seconds_before: float = 0.0


def _restore(path: Path, cfg: TrainConfig, net, optimizer, scheduler, generator, selected_by: str) -> _Run:
    """Load a checkpoint (CPU tensors; the optimiser state follows the network onto its device)."""
    ckpt = torch.load(path, map_location="cpu", weights_only=False)
    if ckpt["model_config"] != cfg.model.to_dict():
        raise ValueError(f"{path}: checkpoint model config {ckpt['model_config']} differs from the "
                         f"requested {cfg.model.to_dict()}")
    if ckpt.get("data", _data_options(cfg)) != _data_options(cfg):  # a checkpoint without "data" is not checked
        raise ValueError(f"{path}: checkpoint was trained on data {ckpt['data']}, not the requested "
                         f"{_data_options(cfg)}")
    net.load_state_dict(ckpt["state_dict"])
    optimizer.load_state_dict(ckpt["optimizer"])
    scheduler.load_state_dict(ckpt["scheduler"])
    generator.set_state(ckpt["generator"])
    run = _Run(ckpt["history"], ckpt["best_val"], ckpt["best_state"], ckpt.get("best_epoch", -1),
               ckpt["epoch"] + 1, float(ckpt.get("seconds", 0.0)))
    if ckpt.get("selected_by") != selected_by:  # scores on another scale: start the selection afresh
        run.best_val, run.best_state, run.best_epoch = float("inf"), None, -1
    return run


def _save_checkpoint(path: Path, epoch: int, net, optimizer, scheduler, generator, run: _Run, cfg: TrainConfig,
                     selected_by: str, seconds: float) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    torch.save({"epoch": epoch, "state_dict": cpu_state_dict(net), "optimizer": to_cpu(optimizer.state_dict()),
                "scheduler": scheduler.state_dict(), "generator": generator.get_state(), "history": run.history,
                "best_val": run.best_val, "best_state": run.best_state, "best_epoch": run.best_epoch,
                "selected_by": selected_by, "seconds": seconds, "model_config": cfg.model.to_dict(),
                "data": _data_options(cfg)}, path)


def _data_options(cfg: TrainConfig) -> dict:
    """The options that decide the training corpus (build_dataset), so --resume refuses another corpus."""
    options = {"variants": cfg.variants, "counterfactual": cfg.counterfactual, "seed": cfg.seed,
               "augment": cfg.augment}
    return {**options, "soft_labels": cfg.soft_labels} if cfg.soft_labels else options


def _build(cfg: TrainConfig, device: torch.device):
    """Network (seeded initialisation on the CPU, or ``cfg.init_from``), optimiser, scheduler and generator."""
    torch.manual_seed(cfg.seed)
    np.random.seed(cfg.seed)
    net = GestureNet(cfg.model)
    if cfg.init_from:
        blob = torch.load(cfg.init_from, map_location="cpu", weights_only=False)
        if blob.get("config") != cfg.model.to_dict():
            raise ValueError(f"{cfg.init_from}: its model config {blob.get('config')} differs from the requested "
                             f"{cfg.model.to_dict()}")
        net.load_state_dict(blob["state_dict"])
    net.to(device)
    optimizer = torch.optim.Adam(net.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    scheduler = torch.optim.lr_scheduler.ExponentialLR(optimizer, gamma=cfg.lr_decay)
    return net, optimizer, scheduler, torch.Generator().manual_seed(cfg.seed)


def train(cfg: TrainConfig, data: GestureDataset | None = None, progress: bool = True,
          provenance: dict | None = None, cache_dir: str | Path | None = None) -> dict:
    """Train and save; returns {"history": [...], "best_val", "epochs_run", "seconds", "device", "out"}.
    ``provenance``: entries for the weights file saying what ``data`` is (``trained_on``, ``corpus``);
    ``cache_dir``: where the synthetic corpus is cached when ``data`` is None (default
    :data:`generation.gesture.config.DEFAULT_VAR_DIR`)."""

    selected_by = _selected_by(cfg)  # an unusable selection rule fails before any data is built
    torch.set_num_threads(cfg.threads)
    device = resolve_device(cfg.device)
    amp = bool(cfg.amp) and device.type == "cuda"
    if cfg.amp and not amp:
        warnings.warn(f"--amp is for CUDA autocast; ignored on {device} (training runs in float32)", stacklevel=2)
    scaler = torch.amp.GradScaler("cuda") if needs_grad_scaler(device, amp) else None
    if data is not None and cfg.augment:
        warnings.warn(f"augment={cfg.augment} is ignored: training on the given dataset as it is", stacklevel=2)
    data = data if data is not None else build_dataset(variants=cfg.variants, seed=cfg.seed, cache_dir=cache_dir,
                                                       counterfactual=cfg.counterfactual, augment=cfg.augment)
    train_idx, val_idx = data.indices("train"), data.indices("val")
    if len(train_idx) == 0:
        raise ValueError("the training split is empty")
    corpus = data.on_device(device)
    if cfg.loss.real_range:
        corpus.real_bounds = tuple(torch.from_numpy(a).to(device) for a in range_arrays(data.emotion))
    net, optimizer, scheduler, generator = _build(cfg, device)
    ranges = load_ranges()["ranges"] if cfg.select == "real-range" else None
    ckpt_path = Path(cfg.checkpoint)
    run = (_restore(ckpt_path, cfg, net, optimizer, scheduler, generator, selected_by)
           if cfg.resume and ckpt_path.is_file() else _Run())
    if ranges is not None and cfg.init_from and not run.history and len(val_idx):
        # the weights fine-tuning starts from are a candidate too ("epoch" -1)
        entry = {"epoch": -1, "init_from": str(cfg.init_from)}
        run.best_val = _score(net, data, val_idx, cfg, -1, True, {}, entry, ranges)
        run.best_state, run.best_epoch = cpu_state_dict(net), -1
        run.history.append(entry)
    t0 = time.time()
    bar = tqdm(range(run.start_epoch, cfg.epochs), desc=f"gesture net on {describe(device)}", disable=not progress,
               unit="epoch")
    epoch = run.start_epoch - 1
    for epoch in bar:
        t_epoch = time.time()
        share = cfg.sampling * min(1.0, epoch / max(cfg.sampling_ramp, 1))
        tr = _run_epoch(net, corpus, train_idx, cfg, optimizer, generator, share, amp, scaler)
        scheduler.step()
        with torch.no_grad():
            va = _run_epoch(net, corpus, val_idx, cfg, amp=amp) if len(val_idx) else tr
        entry = {"epoch": epoch, "train": tr, "val": va, "lr": scheduler.get_last_lr()[0],
                 "epoch_seconds": time.time() - t_epoch}
        last_epoch = epoch == cfg.epochs - 1 or (cfg.max_minutes is not None
                                                 and (time.time() - t0) > 60 * cfg.max_minutes)
        score = _score(net, data, val_idx, cfg, epoch, last_epoch, va, entry, ranges)
        run.history.append(entry)
        if score is not None and score < run.best_val:
            run.best_val, run.best_state, run.best_epoch = score, cpu_state_dict(net), epoch
        if score is not None and cfg.keep_rollouts:
            save_weights(net, Path(cfg.keep_rollouts) / f"epoch{epoch:03d}.pt",
                         {"epoch": epoch, "val_rollout": entry.get("val_rollout"),
                          "val_real_range": entry.get("val_real_range")})
        bar.set_postfix(train=f"{tr['total']:.4f}", val=f"{va['total']:.4f}", best=f"{run.best_val:.4f}")
        _save_checkpoint(ckpt_path, epoch, net, optimizer, scheduler, generator, run, cfg, selected_by,
                         run.seconds_before + time.time() - t0)
        if last_epoch:
            break
    return _finish(net, cfg, run, epoch, selected_by, run.seconds_before + time.time() - t0, device, provenance)


def _selected_by(cfg: TrainConfig) -> str:
    """The name of the selection rule (a checkpoint made under another rule restarts the selection)."""
    if cfg.select not in SELECTIONS:
        raise ValueError(f"select must be one of {SELECTIONS}, got {cfg.select!r}")
    if cfg.select == "real-range":
        if cfg.rollout_every <= 0:
            raise ValueError("select real-range needs rollouts: --rollout-every (rollout_every) > 0")
        r_bound = "" if cfg.min_arousal_r is None else f"_arousal_r_{cfg.min_arousal_r:g}"
        return f"val_rollout_real_range_share_within_pose_error_{cfg.max_pose_error:g}{r_bound}"
    return ("val_loss" if cfg.rollout_every <= 0 else "val_rollout_pose_error_x_emotion_liveliness"
            if cfg.select_emotion_gap else "val_rollout_pose_error_x_liveliness")


def _score(net, data, val_idx, cfg: TrainConfig, epoch: int, last_epoch: bool, va: dict, entry: dict,
           ranges: dict | None = None):
    """The model-selection score of this epoch (None when not measured this epoch); adds "val_rollout" (and
    "val_real_range" when ``ranges`` are given: the real-range rule)."""
    if cfg.rollout_every > 0 and len(val_idx) and ((epoch + 1) % cfg.rollout_every == 0 or last_epoch):
        net.eval()
        entry["val_rollout"] = dataset_pose_error(decode_examples(net, data, val_idx), data, val_idx)
        if ranges is not None:
            entry["val_real_range"] = real_range_rollout(net, data, val_idx, ranges)
            return history_score(entry, cfg.max_pose_error, cfg.min_arousal_r)
        return selection_score(entry["val_rollout"], emotion_gap=cfg.select_emotion_gap)
    if cfg.rollout_every <= 0:
        return va["total"]
    return None


def _finish(net, cfg: TrainConfig, run: _Run, epoch: int, selected_by: str, seconds: float,
            device: torch.device, provenance: dict | None = None) -> dict:
    """Load the best state, save the weights file and return the run summary."""
    if run.best_state is not None:
        net.load_state_dict(run.best_state)
    summary = {"epochs_run": epoch + 1, "best_val": run.best_val, "best_epoch": run.best_epoch,
               "selected_by": selected_by, "seconds": seconds, "device": str(device), "preset": cfg.preset,
               "out": cfg.out}
    extra = {"loss_weights": dataclasses.asdict(cfg.loss), "train_config": _jsonable(cfg), "history": run.history,
             **{k: v for k, v in summary.items() if k != "out"}}
    if cfg.loss.real_range or cfg.select == "real-range":
        # the motion is still learnt from synthetic gestures only; the real-capture statistics shaped the loss or the
        # choice of epoch, so their source, licence and citation go with the weights
        used = [u for u, on in (("loss", cfg.loss.real_range), ("epoch selection", cfg.select == "real-range")) if on]
        extra["real_statistics"] = {"used_for": used, **real_range_provenance()}
    save_weights(net, cfg.out, {**extra, **(provenance or {})})
    summary["history"] = run.history
    return summary


def _jsonable(cfg: TrainConfig) -> dict:
    return json.loads(json.dumps(dataclasses.asdict(cfg), default=str))


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description="Train the Text2Gestures network (seed 003) on the synthetic corpus.")
    d = TrainConfig()
    p.add_argument("--config", default="small", help=f"preset: {' or '.join(PRESETS)} (paper = the published "
                   "26.3 M-parameter size, 600 epochs, no time budget)")
    p.add_argument("--device", default=d.device, help="auto (CUDA when available), cpu, cuda or cuda:N")
    p.add_argument("--amp", action="store_true", help="mixed-precision forward passes (CUDA autocast; ignored on "
                   "the CPU)")
    p.add_argument("--epochs", type=int, default=None, help="default: the preset's (400 small, 600 paper)")
    p.add_argument("--batch-size", type=int, default=d.batch_size)
    p.add_argument("--lr", type=float, default=d.lr)
    p.add_argument("--weight-decay", type=float, default=d.weight_decay)
    p.add_argument("--seed", type=int, default=d.seed)
    p.add_argument("--variants", type=int, default=d.variants, help="procedural gestures per sentence")
    p.add_argument("--counterfactual", type=int, default=d.counterfactual,
                   help="extra procedural gestures per sentence performed with another emotion")
    p.add_argument("--augment", type=int, default=d.augment,
                   help="add this many synthetic training sentences recombined from the training sentences' phrases "
                   "(one procedural gesture each, emotions spread evenly; validation and test unchanged; 0 = none)")
    p.add_argument("--max-minutes", type=float, default=None,
                   help="wall-clock budget in minutes (0 = none; default: 20 small, none paper); keeps the best model")
    p.add_argument("--sampling", type=float, default=d.sampling, help="share of self-fed decoder inputs")
    p.add_argument("--sampling-ramp", type=int, default=d.sampling_ramp,
                   help="epochs over which the self-fed share rises linearly to --sampling")
    p.add_argument("--sampling-passes", type=int, default=d.sampling_passes,
                   help="no-grad passes that build the self-fed inputs (more = closer to free-running generation)")
    p.add_argument("--input-noise", type=float, default=d.input_noise)
    p.add_argument("--residual", choices=("previous", "rest", "none"), default=None)
    for term in ("angle", "pose", "affective", "velocity", "liveliness"):
        p.add_argument(f"--no-{term}-loss", action="store_true")
    p.add_argument("--rollout-every", type=int, default=d.rollout_every,
                   help="generate the validation gestures every this many epochs to choose the kept weights "
                   "(0: choose by the teacher-forced validation loss)")
    p.add_argument("--liveliness-weight", type=float, default=None,
                   help=f"weight of the liveliness loss (default {LossWeights().liveliness})")
    p.add_argument("--liveliness-form", choices=LIVELINESS_FORMS, default=LossWeights().liveliness_form,
                   help="speed: each wrist's mean and RMS speed, squared m/s differences (the shipped weights); "
                   "log_peak: also the faster wrist's mean and 90th percentile, squared log ratios")
    p.add_argument("--real-range-weight", type=float, default=0.0,
                   help="weight of the loss that keeps each gesture's wrist and elbow speed, reach, holds and head "
                   "motion within the real captured range of its emotion (generation.gesture.real_range; 0 = off)")
    p.add_argument("--select-emotion-gap", action="store_true",
                   help="choose the kept weights by pose error x (1 + speed gap + worst per-emotion speed gap)")
    p.add_argument("--select", choices=SELECTIONS, default=d.select,
                   help="pose: keep the rollout epoch with the lowest pose error x liveliness (the shipped weights); "
                   "real-range: the one whose validation gestures, generated with each emotion of the real capture, "
                   "are most often inside the real range, among epochs with rollout pose error <= --max-pose-error "
                   "(else the lowest pose error; with --init-from the starting weights are a candidate)")
    p.add_argument("--max-pose-error", type=float, default=d.max_pose_error,
                   help="bound on the validation rollout pose error for --select real-range")
    p.add_argument("--min-arousal-r", type=float, default=None,
                   help="--select real-range: also require r(peak wrist speed, arousal) of the validation gestures "
                   ">= this (default: no bound)")
    p.add_argument("--keep-rollouts", default=None,
                   help="also write the weights of every rollout epoch into this folder (epochNNN.pt)")
    p.add_argument("--d-model", type=int, default=None, help="default: the preset's (64 small, 992 paper)")
    p.add_argument("--init-from", default=None, help="start from these weights (fine-tuning; same model config)")
    p.add_argument("--soft-labels", default=None, metavar="CLIP_NORMS.csv",
                   help="train on the gestures rated in a clip_norms.csv (docs/study.md) instead of the synthetic "
                   "corpus, each with its perceived shares as a share-weighted NRC-VAD emotion (with --init-from: a "
                   "fine-tune); default --out var/weights/gesture_net_soft_labels.pt")
    p.add_argument("--motions", default=None, metavar="DIR",
                   help="where the rated clips' motions are (<clip_id>.bvh; default $MEDIA_ROOT/motions)")
    p.add_argument("--clips", default=None, metavar="CLIPS.csv",
                   help="the clip catalogue (default clips.csv beside the motions folder): tells an unknown clip from "
                   "a missing motion, and extra columns sentence, task, gender, handedness give a clip's speech")
    p.add_argument("--records", default=None, metavar="DIR",
                   help="the clip records, which name each generated gesture's sentence (default clip_records "
                   "beside the motions folder)")
    p.add_argument("--norms-study", default=None,
                   help="the study the norms come from, recorded in the weights (default: the CSV's folder name)")
    p.add_argument("--min-ratings", type=int, default=1,
                   help="soft labels only from gestures with this many ratings")
    p.add_argument("--out", default=d.out, help="where the best weights go")
    p.add_argument("--var-dir", type=Path, default=config.var_dir(os.environ),
                   help="caches (token vectors, procedural gesture pairs) and the default checkpoint folder "
                        f"(default $GESTURE_VAR_DIR, else {config.DEFAULT_VAR_DIR})")
    p.add_argument("--checkpoint", default=None, help="default VAR_DIR/checkpoints/gesture_net.pt")
    p.add_argument("--resume", action="store_true", help="continue from --checkpoint")
    p.add_argument("--threads", type=int, default=d.threads)
    p.add_argument("--quiet", action="store_true")
    return p


def config_from_args(args: argparse.Namespace) -> TrainConfig:
    """A :class:`TrainConfig` from parsed options: the ``--config`` preset, then the options given explicitly."""
    if args.augment < 0:
        raise ValueError(f"--augment must be >= 0 (extra training sentences), got {args.augment}")
    base = LossWeights()
    loss = LossWeights(**{k: 0.0 if getattr(args, f"no_{k}_loss") else getattr(base, k)
                          for k in ("angle", "pose", "affective", "velocity", "liveliness")})
    if args.liveliness_weight is not None and not args.no_liveliness_loss:
        if args.liveliness_weight < 0:
            raise ValueError(f"--liveliness-weight must be >= 0, got {args.liveliness_weight}")
        loss = dataclasses.replace(loss, liveliness=args.liveliness_weight)
    loss = dataclasses.replace(loss, liveliness_form=args.liveliness_form)
    if args.real_range_weight < 0:
        raise ValueError(f"--real-range-weight must be >= 0, got {args.real_range_weight}")
    loss = dataclasses.replace(loss, real_range=args.real_range_weight)
    cfg = preset_config(args.config or "small")
    model = dataclasses.replace(cfg.model, **{k: v for k, v in (("d_model", args.d_model),
                                                                 ("residual", args.residual)) if v is not None})
    overrides = dict(batch_size=args.batch_size, lr=args.lr, weight_decay=args.weight_decay, seed=args.seed,
                     variants=args.variants, counterfactual=args.counterfactual, augment=args.augment, loss=loss,
                     sampling=args.sampling,
                     sampling_ramp=args.sampling_ramp,
                     sampling_passes=args.sampling_passes, input_noise=args.input_noise, model=model, out=args.out,
                     checkpoint=args.checkpoint or str(Path(args.var_dir) / "checkpoints" / "gesture_net.pt"),
                     resume=args.resume, threads=args.threads,
                     init_from=args.init_from, device=args.device, amp=bool(args.amp),
                     rollout_every=args.rollout_every, select_emotion_gap=bool(args.select_emotion_gap),
                     select=args.select, max_pose_error=args.max_pose_error, min_arousal_r=args.min_arousal_r,
                     keep_rollouts=args.keep_rollouts, soft_labels=getattr(args, "soft_labels", None))
    if args.epochs is not None:
        overrides["epochs"] = args.epochs
    if args.max_minutes is not None:
        overrides["max_minutes"] = args.max_minutes or None
    resolve_device(args.device)  # an unknown or unavailable device fails here, before any data is built
    cfg = dataclasses.replace(cfg, **overrides)
    _selected_by(cfg)  # so does a selection rule the options cannot serve (real-range without rollouts)
    return cfg


SOFT_LABEL_WEIGHTS = Path("var/weights/gesture_net_soft_labels.pt")
"""Where a soft-label run writes unless --out says otherwise (never over the shipped weights)."""


def soft_label_data(cfg: TrainConfig, args: argparse.Namespace, log=print) -> tuple[GestureDataset, dict]:
    """The rated gestures of ``--soft-labels`` and the weights file's record of them (``trained_on``,
    ``corpus.soft_labels``); points ``cfg.out`` and ``cfg.checkpoint`` away from the shipped weights and the
    synthetic run's checkpoint when they are the defaults. ValueError (with file, line and column) on bad input."""
    if args.motions is None:
        raise ValueError("--soft-labels: say where the clips' motions are (--motions DIR or MEDIA_ROOT)")
    try:
        data, norms = load_soft_label_dataset(args.soft_labels, args.motions, study=args.norms_study,
                                              min_ratings=args.min_ratings, catalogue=args.clips,
                                              records_dir=args.records, cache_dir=args.var_dir,
                                              max_frames=cfg.model.max_frames, log=log)
    except SoftLabelError as exc:
        raise ValueError(f"--soft-labels: {exc}") from None
    defaults = TrainConfig()
    if Path(cfg.out).resolve() == Path(defaults.out).resolve():
        cfg.out = str(SOFT_LABEL_WEIGHTS)
        log(f"--soft-labels: writing {cfg.out} (the shipped weights are never replaced; --out to choose)")
    if args.checkpoint is None:
        cfg.checkpoint = str(Path(cfg.checkpoint).with_name("gesture_net_soft_labels.pt"))
    log(f"soft labels: {norms['n_clips']} rated gestures, {norms['n_ratings']} ratings, study {norms['study']}"
        + (f"; {len(norms['skipped'])} left out without a sentence" if norms["skipped"] else ""))
    description = (f"soft labels: {norms['n_clips']} rated gestures ({norms['n_ratings']} ratings, study "
                   f"{norms['study']}), emotion = {norms['target']}")
    return data, {"trained_on": description, "corpus": {"soft_labels": norms}}


def main(argv: list[str] | None = None) -> dict:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.motions is None and os.environ.get("MEDIA_ROOT"):   # the study app's media folder
        args.motions = Path(os.environ["MEDIA_ROOT"]) / "motions"
    data, provenance = None, None
    try:
        cfg = config_from_args(args)
        if args.soft_labels:
            data, provenance = soft_label_data(cfg, args)
    except ValueError as exc:  # unknown preset, unavailable device, bad norms: a usage error, not a traceback
        parser.error(str(exc))
    summary = train(cfg, data=data, progress=not args.quiet, provenance=provenance, cache_dir=args.var_dir)
    last = summary["history"][-1] if summary["history"] else {}
    print(f"trained {summary['epochs_run']} epochs in {summary['seconds']:.0f} s on {summary['device']}; best "
          f"selection score {summary['best_val']:.5f}; last {json.dumps(last.get('val', {}))}; "
          f"weights -> {summary['out']}")
    return summary


if __name__ == "__main__":
    main()
