"""Training of the gait network (seed 000 section 5.3) with curriculum teacher forcing.

Run ``python -m generation.gait.train --help`` (or ``python manage.py train_gait``). The default run
reproduces ``generation/data/weights/gait_net_default.pt`` (see docs/benchmarks/gait.md for the command).

Each sequence has T = 60 steps. The first ``prefix_len`` (18) steps are always ground truth; at every
later step each sequence's input is the ground truth with probability ``tf_decay ** epoch`` (the
teacher-forcing ratio) and the network's own previous prediction otherwise (the curriculum of section 5.3,
after Pavllo et al.). The network predicts step t + 1 from step t; the losses of eq. 8-13 are taken over
all predicted steps.

A fraction ``splice_frac`` of each batch gets the ground-truth prefix of a walk with another emotion and a label
that switches to the sequence's own at the splice (:func:`splice_histories`), so that the emotion input, not the
motion history, decides the style.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from pathlib import Path

import numpy as np
import torch

from .config import GaitNetConfig
from .data import (
    SBAR_ALPHA,
    GaitSequences,
    Normalizer,
    affective_features,
    heading_frame_positions,
    kappa_torch,
    load_corpus_sequences,
)
from .losses import total_loss
from .model import GaitNet

DEFAULT_WEIGHTS = Path(__file__).resolve().parent.parent / "data" / "weights" / "gait_net_default.pt"
CHECKPOINT_DIR = Path("var/gait_runs")
CHECKPOINT_FORMAT = "gait_net/2"


def fit_normalizer(data: GaitSequences) -> Normalizer:
    """Standardisation statistics from a (training) set of sequences."""
    step = torch.stack((data.omega, data.sbar, data.kappa), dim=-1)
    return Normalizer.fit(data.aff.numpy().astype(np.float64), data.root.numpy().astype(np.float64),
                          step.numpy().astype(np.float64))


def ground_truth_targets(batch: dict, norm: Normalizer) -> dict:
    """Targets for predictions of steps 1..T-1 (shapes (B, T-1, ...))."""
    h = batch["root"][:, 1:, 0]
    pos = heading_frame_positions(batch["q"][:, 1:], batch["mean_height"][:, None] + h, batch["offsets"][:, None])
    return {"q": batch["q"][:, 1:], "pos": pos, "aff": norm.aff(batch["aff"][:, 1:]),
            "root": norm.root(batch["root"][:, 1:]), "omega": norm.omega(batch["omega"][:, 1:])}


def splice_histories(batch: dict, prefix: int, frac: float, rng: np.random.Generator) -> dict:
    """Give a fraction of the sequences the history of another walk with a different emotion.

    For each chosen sequence B, the inputs and targets of steps 0..prefix-1 are replaced by those of the walk A
    in the batch (different dominant emotion) whose stepping phase at step prefix - 1 is closest to B's; the
    emotion input is A's label for steps 0..prefix-2 and B's own label from step prefix - 1 on (the step that
    predicts B's first step). The network must then turn A's style into B's because the label says so.
    The skeleton (offsets, mean height) and the path heading stay B's. Returns a new batch whose ``emotion``
    is per step (B, T, C).
    """
    B, T = batch["q"].shape[:2]
    em = batch["emotion"][:, None].expand(B, T, -1).clone()
    out = dict(batch, emotion=em)
    if frac <= 0.0 or B < 2:
        return out
    dominant = batch["emotion"].argmax(-1).numpy()
    theta = batch["theta"][:, prefix - 1].numpy()
    chosen = np.flatnonzero(rng.random(B) < frac)
    src = np.arange(B)
    for b in chosen:
        cand = np.flatnonzero(dominant != dominant[b])
        if len(cand):
            dphase = np.abs(np.remainder(theta[cand] - theta[b] + math.pi, 2 * math.pi) - math.pi)
            src[b] = cand[np.argmin(dphase)]
    swap = torch.as_tensor(src != np.arange(B))
    if not swap.any():
        return out
    src_t = torch.as_tensor(src)
    for k in ("q", "root", "theta", "omega", "sbar", "kappa", "aff"):
        v = batch[k].clone()
        w = swap.view((B,) + (1,) * (v.dim() - 1))
        v[:, :prefix] = torch.where(w, batch[k][src_t, :prefix], v[:, :prefix])
        out[k] = v
    em[:, :prefix - 1] = torch.where(swap[:, None, None], batch["emotion"][src_t, None], em[:, :prefix - 1])
    return out


def rollout(model: GaitNet, norm: Normalizer, batch: dict, tf_ratio: float, prefix: int,
            generator: torch.Generator | None = None) -> dict:
    """Run the network over a batch of sequences; returns predictions for steps 1..T-1.

    Args:
        batch: from :meth:`GaitSequences.batch` (B sequences of T steps); ``emotion`` is (B, C) or per step
            (B, T, C).
        tf_ratio: probability of feeding the ground truth (rather than the prediction) after the prefix.
        prefix: number of leading steps always fed from the ground truth (>= 1).

    Returns:
        dict of (B, T-1, ...) tensors: q_raw, q, pos (heading frame, root at the predicted height), aff
        (standardised, of the predicted pose), root (standardised), omega (standardised), and the raw
        predicted root height ``h`` (B, T-1) in metres.
    """
    B, T = batch["q"].shape[:2]
    # Full teacher forcing is the same as a ground-truth prefix covering the whole sequence (one GRU call).
    prefix = T - 1 if tf_ratio >= 1.0 else max(1, min(prefix, T - 1))
    em = batch["emotion"] if batch["emotion"].dim() == 3 else batch["emotion"][:, None].expand(B, T, -1)
    aff_z = norm.aff(batch["aff"])
    root_z = norm.root(batch["root"])
    step_z = norm.step(batch["theta"], batch["omega"], batch["sbar"], batch["kappa"])
    offsets = batch["offsets"]
    mean_h = batch["mean_height"]

    def decode(out):
        root_raw = norm.root_inv(out["root"])
        h = root_raw[..., 0]
        pos = heading_frame_positions(out["q"], mean_h.view((B,) + (1,) * (h.dim() - 1)) + h,
                                      offsets if h.dim() == 1 else offsets[:, None])
        return root_raw, h, pos

    out = model(batch["q"][:, :prefix], aff_z[:, :prefix], step_z[:, :prefix], root_z[:, :prefix], em[:, :prefix])
    root_raw, h, pos = decode(out)
    preds = {"q_raw": [out["q_raw"]], "q": [out["q"]], "pos": [pos], "root": [out["root"]],
             "omega": [out["omega"]], "h": [h], "aff": [norm.aff(affective_features(pos))]}
    hidden = out["hidden"]
    # Current inputs (step prefix - 1 was ground truth).
    last = {"theta": batch["theta"][:, prefix - 1], "sbar": batch["sbar"][:, prefix - 1]}
    prev_pred = {k: preds[k][0][:, -1] for k in ("q", "pos", "root", "omega", "aff")}
    prev_pred["root_raw"] = root_raw[:, -1]
    for t in range(prefix, T - 1):
        # Inputs for step t from the previous prediction ...
        omega_p = norm.omega_inv(prev_pred["omega"]).clamp(0.0, math.pi)
        theta_p = torch.remainder(last["theta"] + omega_p, 2 * math.pi)
        sbar_p = (1 - SBAR_ALPHA) * last["sbar"] + SBAR_ALPHA * prev_pred["root_raw"][:, 1]
        kappa_p = kappa_torch(sbar_p, batch["ref"][:, t], last["sbar"], batch["ref"][:, t - 1])
        step_p = norm.step(theta_p, omega_p, sbar_p, kappa_p)
        # ... or from the ground truth, per sequence with probability tf_ratio.
        if tf_ratio >= 1.0:
            use_gt = torch.ones(B, dtype=torch.bool)
        elif tf_ratio <= 0.0:
            use_gt = torch.zeros(B, dtype=torch.bool)
        else:
            use_gt = torch.rand(B, generator=generator) < tf_ratio
        g1, g2, g3 = use_gt[:, None], use_gt[:, None, None], use_gt
        q_in = torch.where(g2, batch["q"][:, t], prev_pred["q"])
        aff_in = torch.where(g1, aff_z[:, t], prev_pred["aff"])
        root_in = torch.where(g1, root_z[:, t], prev_pred["root"])
        step_in = torch.where(g1, step_z[:, t], step_p)
        last = {"theta": torch.where(g3, batch["theta"][:, t], theta_p),
                "sbar": torch.where(g3, batch["sbar"][:, t], sbar_p)}
        out = model.step(q_in, aff_in, step_in, root_in, em[:, t], hidden)
        hidden = out["hidden"]
        root_raw, h, pos = decode(out)
        aff_p = norm.aff(affective_features(pos))
        for k, v in (("q_raw", out["q_raw"]), ("q", out["q"]), ("pos", pos), ("root", out["root"]),
                     ("omega", out["omega"]), ("h", h), ("aff", aff_p)):
            preds[k].append(v[:, None])
        prev_pred = {"q": out["q"], "pos": pos, "root": out["root"], "omega": out["omega"], "aff": aff_p,
                     "root_raw": root_raw}
    return {k: torch.cat(v, dim=1) for k, v in preds.items()}


def evaluate(model: GaitNet, norm: Normalizer, data: GaitSequences, config: GaitNetConfig,
             batch_size: int = 64) -> dict:
    """Free-running validation (teacher forcing 0 after the prefix): mean loss terms over ``data``."""
    model.eval()
    sums: dict[str, float] = {}
    n = 0
    with torch.no_grad():
        for start in range(0, len(data), batch_size):
            idx = np.arange(start, min(start + batch_size, len(data)))
            batch = data.batch(idx)
            pred = rollout(model, norm, batch, 0.0, config.prefix_len)
            loss, terms = total_loss(pred, ground_truth_targets(batch, norm), config.loss, config.model.use_affective)
            terms["total"] = loss.item()
            for k, v in terms.items():
                sums[k] = sums.get(k, 0.0) + v * len(idx)
            n += len(idx)
    model.train()
    return {k: v / max(n, 1) for k, v in sums.items()}


def save_checkpoint(path: Path, model: GaitNet, norm: Normalizer, config: GaitNetConfig, **extra) -> None:
    """Write model weights, config and normaliser (plus any training state in ``extra``).

    Format ``gait_net/2`` stores the config split by section (``GaitNetConfig.to_dict``); ``gait_net/1`` files
    (the flat config of before the split) are still read by :func:`load_checkpoint`.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    payload = {"format": CHECKPOINT_FORMAT, "config": config.to_dict(), "normalizer": norm.to_dict(),
               "model": model.state_dict(), **extra}
    tmp = path.with_suffix(path.suffix + ".tmp")
    torch.save(payload, tmp)
    tmp.replace(path)


def load_checkpoint(path: str | Path) -> tuple[GaitNet, Normalizer, dict]:
    """Load a file written by :func:`save_checkpoint` (either format); returns (model in eval mode, normaliser,
    payload). ``GaitNetConfig.from_dict(payload["config"])`` is the full config."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"gait network weights not found: {path}")
    try:
        payload = torch.load(path, map_location="cpu", weights_only=False)
    except Exception as exc:  # noqa: BLE001 - report any unreadable file with its name
        raise ValueError(f"{path}: not a readable gait network checkpoint ({exc})") from None
    for key in ("config", "normalizer", "model"):
        if key not in payload:
            raise ValueError(f"{path}: checkpoint lacks field {key!r}")
    model = GaitNet(GaitNetConfig.from_dict(payload["config"]).model)
    model.load_state_dict(payload["model"])
    model.eval()
    return model, Normalizer.from_dict(payload["normalizer"]), payload


def _train_epoch(model: GaitNet, norm: Normalizer, opt, train_set: GaitSequences, config: GaitNetConfig, tf: float,
                 rng: np.random.Generator, gen: torch.Generator, desc: str, progress: bool) -> dict[str, float]:
    """One epoch over the training walks with teacher-forcing ratio ``tf``; returns the mean loss terms."""
    from tqdm import tqdm

    tc = config.train
    # One row per corpus sequence per epoch, with a random subsampling offset when several exist.
    rows = rng.permutation(len(train_set))
    _, first = np.unique(train_set.base_index[rows], return_index=True)
    order = rows[np.sort(first)]
    batches = [order[i:i + tc.batch_size] for i in range(0, len(order), tc.batch_size)]
    sums: dict[str, float] = {}
    bar = tqdm(batches, desc=desc, disable=not progress, leave=False)
    for idx in bar:
        batch = splice_histories(train_set.batch(idx), config.prefix_len, tc.splice_frac, rng)
        pred = rollout(model, norm, batch, tf, config.prefix_len, gen)
        loss, terms = total_loss(pred, ground_truth_targets(batch, norm), config.loss, config.model.use_affective)
        opt.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), tc.grad_clip)
        opt.step()
        terms["total"] = loss.item()
        for k, v in terms.items():
            sums[k] = sums.get(k, 0.0) + v / len(batches)
        bar.set_postfix(loss=f"{loss.item():.3f}")
    return sums


def train(config: GaitNetConfig, data: GaitSequences, out_path: str | Path, checkpoint_path: str | Path | None = None,
          resume: bool = False, max_minutes: float | None = None, progress: bool = True, log=print) -> dict:
    """Train on ``data`` (its "train" split; "val" for validation); returns the history.

    Writes ``checkpoint_path`` (full training state) after every epoch and the final small weights file
    ``out_path`` (model, config, normaliser, history). ``resume`` continues from ``checkpoint_path``.
    ``max_minutes`` stops after the epoch that crosses the budget (the history records it).
    """
    tc = config.train
    torch.manual_seed(tc.seed)
    rng = np.random.default_rng(tc.seed)
    gen = torch.Generator().manual_seed(tc.seed)
    train_set = data.subset("train")
    val_set = data.subset((data.split == "val") & (data.offset == 0))
    if len(train_set) == 0:
        raise ValueError("the corpus has no 'train' sequences")
    norm = fit_normalizer(train_set)
    model = GaitNet(config.model)
    opt = torch.optim.Adam(model.parameters(), lr=tc.lr)
    sched = torch.optim.lr_scheduler.ExponentialLR(opt, gamma=tc.lr_decay)
    history: list[dict] = []
    start_epoch = 0
    # Training state lives under var/ (not next to the shipped weights) unless a path is given.
    checkpoint_path = Path(checkpoint_path) if checkpoint_path else CHECKPOINT_DIR / (Path(out_path).name + ".ckpt")
    if resume and checkpoint_path.exists():
        state = torch.load(checkpoint_path, map_location="cpu", weights_only=False)
        model.load_state_dict(state["model"])
        opt.load_state_dict(state["optimizer"])
        sched.load_state_dict(state["scheduler"])
        norm = Normalizer.from_dict(state["normalizer"])
        history = state["history"]
        start_epoch = state["epoch"] + 1
        rng.bit_generator.state = state["numpy_rng"]
        gen.set_state(state["torch_gen"])
        torch.set_rng_state(state["torch_rng"])
        log(f"resumed from {checkpoint_path} at epoch {start_epoch}")
    t0 = time.time()
    elapsed_before = history[-1]["elapsed_s"] if history else 0.0
    for epoch in range(start_epoch, tc.epochs):
        tf = tc.tf_decay ** epoch
        sums = _train_epoch(model, norm, opt, train_set, config, tf, rng, gen,
                            desc=f"epoch {epoch + 1}/{tc.epochs} tf={tf:.2f}", progress=progress)
        sched.step()
        val = evaluate(model, norm, val_set, config) if len(val_set) else {}
        elapsed = elapsed_before + time.time() - t0
        record = {"epoch": epoch + 1, "tf": tf, "lr": opt.param_groups[0]["lr"], "train": sums, "val": val,
                  "elapsed_s": elapsed}
        history.append(record)
        log(f"epoch {epoch + 1}: train {sums['total']:.4f} val {val.get('total', float('nan')):.4f} "
            f"tf {tf:.3f} ({elapsed / 60:.1f} min)")
        save_checkpoint(checkpoint_path, model, norm, config, optimizer=opt.state_dict(),
                        scheduler=sched.state_dict(), epoch=epoch, history=history,
                        numpy_rng=rng.bit_generator.state, torch_gen=gen.get_state(),
                        torch_rng=torch.get_rng_state())
        if max_minutes is not None and elapsed > 60 * max_minutes:
            log(f"stopping after epoch {epoch + 1}: time budget of {max_minutes} min used")
            break
    save_checkpoint(Path(out_path), model, norm, config, history=history,
                    trained_on="synthetic procedural corpus", num_parameters=model.num_parameters(),
                    corpus=getattr(data, "source", None))
    return {"history": history, "model": model, "normalizer": norm}


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description="Train the seed-000 emotive gait network on the gait corpus.")
    p.add_argument("--corpus", default=None, help="corpus .npz (default var/corpus/gait_corpus_synthetic.npz; "
                                                  "built with --num-sequences when missing)")
    p.add_argument("--num-sequences", type=int, default=1000)
    p.add_argument("--out", default=str(DEFAULT_WEIGHTS), help="weights file to write")
    p.add_argument("--checkpoint", default=None,
                   help="training-state checkpoint for --resume (default var/gait_runs/<OUT name>.ckpt)")
    p.add_argument("--resume", action="store_true", help="continue from the checkpoint")
    p.add_argument("--epochs", type=int, default=None)
    p.add_argument("--batch-size", type=int, default=None)
    p.add_argument("--seed", type=int, default=None)
    p.add_argument("--max-minutes", type=float, default=None, help="stop after the epoch that crosses this")
    p.add_argument("--paper-size", action="store_true", help="the released model's sizes (about 9.9M parameters)")
    p.add_argument("--no-affective", action="store_true", help="ablation: no affective inputs and no L_aff")
    p.add_argument("--no-root-loss", action="store_true", help="ablation: lambda_root = 0")
    p.add_argument("--set", action="append", default=[], metavar="FIELD=JSON",
                   help="override any config field by its flat name or as SECTION.FIELD (sections model, data, "
                        "train, loss), e.g. --set gru_hidden=256 --set tf_decay=0.97 --set loss.pose=0.5")
    p.add_argument("--offsets", type=int, default=4,
                   help="subsampling offsets per sequence (augmentation; every 4th frame from frame 0..N-1)")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    return p


def config_from_args(args) -> GaitNetConfig:
    """The GaitNetConfig of parsed options: default or ``--paper-size``, then ``--set``, then the named options."""
    config = GaitNetConfig.paper() if args.paper_size else GaitNetConfig()
    overrides = {}
    for item in args.set:
        if "=" not in item:
            raise SystemExit(f"--set expects FIELD=JSON, got {item!r}")
        key, value = item.split("=", 1)
        overrides[key] = json.loads(value)
    try:
        config = config.with_overrides(**overrides)
    except ValueError as exc:
        raise SystemExit(f"--set: {exc}") from None
    named = {k: v for k, v in (("epochs", args.epochs), ("batch_size", args.batch_size), ("seed", args.seed))
             if v is not None}
    config = dataclasses.replace(config, train=dataclasses.replace(config.train, **named))
    if args.no_affective:
        config = dataclasses.replace(config, model=dataclasses.replace(config.model, use_affective=False))
    if args.no_root_loss:
        config = dataclasses.replace(config, loss=dataclasses.replace(config.loss, root=0.0))
    return config


def run(args, log=print) -> dict:
    """Train from parsed command-line options (shared by ``python -m`` and ``manage.py train_gait``)."""
    torch.set_num_threads(args.threads)
    config = config_from_args(args)
    data = load_corpus_sequences(args.corpus, num_sequences=args.num_sequences, seed=0,
                                 frame_step=config.data.frame_step, seq_len=config.data.seq_len,
                                 offsets=tuple(range(args.offsets)))
    counts = ", ".join(f"{s}: {int(((data.split == s) & (data.offset == 0)).sum())}" for s in ("train", "val", "test"))
    log(f"{len(data)} sequences ({counts}), network {GaitNet(config.model).num_parameters()} parameters")
    result = train(config, data, args.out, args.checkpoint, args.resume, args.max_minutes, progress=not args.quiet,
                   log=log)
    log(f"wrote {args.out}")
    return result


def main(argv=None) -> int:
    run(build_parser().parse_args(argv))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
