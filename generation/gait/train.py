"""Training of the gait network (seed 000 section 5.3) with curriculum teacher forcing.

Run ``python -m generation.gait.train --help`` (or ``python manage.py train_gait``); docs/benchmarks/gait.md has
the commands that made ``generation/data/weights/gait_net_default.pt`` (a default run fine-tuned with ``--init``).
``--device auto|cpu|cuda[:N]`` picks where it runs, ``--amp`` mixed precision on CUDA, ``--config paper`` the
published size. Weights and checkpoints are written device-independent (tensors on the CPU).

Each sequence has T = 60 steps. The first ``prefix_len`` (18) steps are always ground truth; at every
later step each sequence's input is the ground truth with probability ``tf_decay ** epoch`` (the
teacher-forcing ratio) and the network's own previous prediction otherwise (the curriculum of section 5.3,
after Pavllo et al.). The network predicts step t + 1 from step t; the losses of eq. 8-13 are taken over
all predicted steps.

After the last ground-truth step the rollout continues ``extra_steps`` free-running steps whose window statistics
enter the style term (:func:`generation.gait.losses.style_loss`), against drift in long generated walks.

A fraction ``splice_frac`` of each batch gets the ground-truth prefix of a walk with another emotion and a label
that switches to the sequence's own at the splice (:func:`splice_histories`), so that the emotion input, not the
motion history, decides the style. With ``uniform_label_frac`` > 0 a fraction of the sequences get the uniform
emotion vector instead of their label (:func:`uniform_labels`; the reference of emotion guidance at generation).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from generation.core.device import (
    DEVICE_CHOICES,
    autocast_context,
    cpu_state_dict,
    describe,
    needs_grad_scaler,
    resolve_device,
    to_cpu,
)
from generation.core.digest import file_sha256
from generation.core.splits import SPLITS
from generation.mocap.real_corpus import real_corpus_path

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
from .real_data import STAGES as REAL_STAGES
from .real_data import concat_sequences, load_real_sequences
from .soft_labels import SoftLabelError, load_soft_label_sequences
from .weights import TrainingData

DEFAULT_WEIGHTS = Path(__file__).resolve().parent.parent / "data" / "weights" / "gait_net_default.pt"
CHECKPOINT_DIR = Path("var/gait_runs")
CHECKPOINT_FORMAT = "gait_net/3"
#: Formats this code reads: gait_net/2 files say what they were trained on in prose only (weights.training_data_of).
READABLE_FORMATS = ("gait_net/2", CHECKPOINT_FORMAT)


def fit_normalizer(data: GaitSequences) -> Normalizer:
    """Standardisation statistics from a (training) set of sequences."""
    step = torch.stack((data.omega, data.sbar, data.kappa), dim=-1)
    as_np = lambda t: t.detach().cpu().numpy().astype(np.float64)  # noqa: E731
    return Normalizer.fit(as_np(data.aff), as_np(data.root), as_np(step))


def ground_truth_targets(batch: dict, norm: Normalizer) -> dict:
    """Targets for predictions of steps 1..T-1 (shapes (B, T-1, ...)), with ``emotion`` (B, C): each walk's own
    label (the last step's input where the batch has per-step labels)."""
    h = batch["root"][:, 1:, 0]
    pos = heading_frame_positions(batch["q"][:, 1:], batch["mean_height"][:, None] + h, batch["offsets"][:, None])
    return {"q": batch["q"][:, 1:], "pos": pos, "aff": norm.aff(batch["aff"][:, 1:]),
            "root": norm.root(batch["root"][:, 1:]), "omega": norm.omega(batch["omega"][:, 1:]),
            "aff_style_scale": norm.style_scale(batch["aff"]),
            "emotion": batch["emotion"] if batch["emotion"].dim() == 2 else batch["emotion"][:, -1]}


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
    dominant = batch["emotion"].argmax(-1).cpu().numpy()
    theta = batch["theta"][:, prefix - 1].cpu().numpy()
    chosen = np.flatnonzero(rng.random(B) < frac)
    src = np.arange(B)
    for b in chosen:
        cand = np.flatnonzero(dominant != dominant[b])
        if len(cand):
            dphase = np.abs(np.remainder(theta[cand] - theta[b] + math.pi, 2 * math.pi) - math.pi)
            src[b] = cand[np.argmin(dphase)]
    device = batch["q"].device
    swap = torch.as_tensor(src != np.arange(B), device=device)
    if not swap.any():
        return out
    src_t = torch.as_tensor(src, device=device)
    for k in ("q", "root", "theta", "omega", "sbar", "kappa", "aff"):
        v = batch[k].clone()
        w = swap.view((B,) + (1,) * (v.dim() - 1))
        v[:, :prefix] = torch.where(w, batch[k][src_t, :prefix], v[:, :prefix])
        out[k] = v
    em[:, :prefix - 1] = torch.where(swap[:, None, None], batch["emotion"][src_t, None], em[:, :prefix - 1])
    return out


def uniform_labels(batch: dict, frac: float, rng: np.random.Generator) -> dict:
    """Replace the per-step emotion input (B, T, C) of a fraction ``frac`` of the sequences by the uniform vector
    (classifier-free guidance training; the targets stay the walk's own). Returns a new batch."""
    em = batch["emotion"]
    drop = torch.as_tensor(rng.random(em.shape[0]) < frac, device=em.device)
    return dict(batch, emotion=torch.where(drop[:, None, None], torch.full_like(em, 1.0 / em.shape[-1]), em))


_PRED_KEYS = ("q_raw", "q", "pos", "root", "omega", "h", "aff")


def _decoder(norm: Normalizer, batch: dict):
    """decode(out) -> (raw root features, root height deviation h in metres, heading-frame positions) of a network
    output for ``batch`` (one step: (B, ...) or many: (B, L, ...))."""
    offsets, mean_h = batch["offsets"], batch["mean_height"]
    B = offsets.shape[0]

    def decode(out):
        root_raw = norm.root_inv(out["root"])
        h = root_raw[..., 0]
        pos = heading_frame_positions(out["q"], mean_h.view((B,) + (1,) * (h.dim() - 1)) + h,
                                      offsets if h.dim() == 1 else offsets[:, None])
        return root_raw, h, pos
    return decode


def _runner(model: GaitNet, amp: bool):
    """run(fn, *inputs): a forward call of ``model`` (``model`` or ``model.step``) inside the mixed-precision
    region when ``amp``; outputs other than the GRU state come back as float32."""
    device = next(model.parameters()).device

    def run(fn, *inputs):
        with autocast_context(device, amp):
            out = fn(*inputs)
        return {k: (v if k == "hidden" or not amp else v.float()) for k, v in out.items()}
    return run


def _decoded(out: dict, decode, norm: Normalizer) -> dict:
    """One step's prediction with its decoded root, height, positions and standardised affective features."""
    root_raw, h, pos = decode(out)
    return {"q_raw": out["q_raw"], "q": out["q"], "pos": pos, "root": out["root"], "omega": out["omega"], "h": h,
            "aff": norm.aff(affective_features(pos)), "root_raw": root_raw}


def _predicted_step_inputs(norm: Normalizer, prev: dict, last: dict, ref: torch.Tensor, ref_prev: torch.Tensor):
    """(theta, s-bar, standardised step features (B, 5)) of the next input step advanced from the previous
    prediction ``prev`` and the previous input step's ``last`` theta and s-bar (as generation does)."""
    omega_p = norm.omega_inv(prev["omega"]).clamp(0.0, math.pi)
    theta_p = torch.remainder(last["theta"] + omega_p, 2 * math.pi)
    sbar_p = (1 - SBAR_ALPHA) * last["sbar"] + SBAR_ALPHA * prev["root_raw"][:, 1]
    kappa_p = kappa_torch(sbar_p, ref, last["sbar"], ref_prev)
    return theta_p, sbar_p, norm.step(theta_p, omega_p, sbar_p, kappa_p)


def _teacher_mask(B: int, tf_ratio: float, generator: torch.Generator | None, device: torch.device) -> torch.Tensor:
    """(B,) True where a sequence's next input is the ground truth. The draw is made on the CPU generator, so that
    runs on the CPU and on a GPU make the same choices."""
    if tf_ratio >= 1.0:
        use_gt = torch.ones(B, dtype=torch.bool)
    elif tf_ratio <= 0.0:
        use_gt = torch.zeros(B, dtype=torch.bool)
    else:
        use_gt = torch.rand(B, generator=generator) < tf_ratio
    return use_gt.to(device)


def _continue_free(run, model: GaitNet, norm: Normalizer, decode, prev: dict, last: dict, hidden, ref: torch.Tensor,
                   emotion: torch.Tensor, steps: int) -> dict:
    """``steps`` free-running predictions past the end of the ground truth (heading ``ref`` (B,) and ``emotion``
    (B, C) of the last step): {"ext_aff": (B, steps, 18), "ext_pos": (B, steps, J, 3)}."""
    aff, pos = [], []
    for _ in range(steps):
        theta_p, sbar_p, step_p = _predicted_step_inputs(norm, prev, last, ref, ref)
        out = run(model.step, prev["q"], prev["aff"], step_p, prev["root"], emotion, hidden)
        last, hidden, prev = {"theta": theta_p, "sbar": sbar_p}, out["hidden"], _decoded(out, decode, norm)
        aff.append(prev["aff"][:, None])
        pos.append(prev["pos"][:, None])
    return {"ext_aff": torch.cat(aff, dim=1), "ext_pos": torch.cat(pos, dim=1)}


def rollout(model: GaitNet, norm: Normalizer, batch: dict, tf_ratio: float, prefix: int,
            generator: torch.Generator | None = None, extra_steps: int = 0, amp: bool = False) -> dict:
    """Run the network over a batch of sequences; returns predictions for steps 1..T-1.

    Args:
        batch: from :meth:`GaitSequences.batch` (B sequences of T steps, on the model's device); ``emotion`` is
            (B, C) or per step (B, T, C).
        tf_ratio: probability of feeding the ground truth (rather than the prediction) after the prefix.
        prefix: number of leading steps always fed from the ground truth (>= 1).
        generator: CPU generator of the teacher-forcing draws.
        extra_steps: free-running steps predicted after step T-1 (:func:`_continue_free`).
        amp: forward passes under :func:`generation.core.device.autocast_context`.

    Returns:
        dict of (B, T-1, ...) tensors: q_raw, q, pos (heading frame, root at the predicted height), aff
        (standardised, of the predicted pose), root (standardised), omega (standardised), and the raw
        predicted root height ``h`` (B, T-1) in metres; with ``extra_steps``, ``ext_aff`` (B, E, 18) and
        ``ext_pos`` (B, E, J, 3) of the continuation.
    """
    B, T = batch["q"].shape[:2]
    device = batch["q"].device
    # Full teacher forcing is the same as a ground-truth prefix covering the whole sequence (one GRU call).
    prefix = T - 1 if tf_ratio >= 1.0 else max(1, min(prefix, T - 1))
    em = batch["emotion"] if batch["emotion"].dim() == 3 else batch["emotion"][:, None].expand(B, T, -1)
    aff_z, root_z = norm.aff(batch["aff"]), norm.root(batch["root"])
    step_z = norm.step(batch["theta"], batch["omega"], batch["sbar"], batch["kappa"])
    decode, run = _decoder(norm, batch), _runner(model, amp)
    out = run(model, batch["q"][:, :prefix], aff_z[:, :prefix], step_z[:, :prefix], root_z[:, :prefix],
              em[:, :prefix])
    first = _decoded(out, decode, norm)
    preds = {k: [first[k]] for k in _PRED_KEYS}
    hidden = out["hidden"]
    # Current inputs (step prefix - 1 was ground truth).
    last = {"theta": batch["theta"][:, prefix - 1], "sbar": batch["sbar"][:, prefix - 1]}
    prev = {k: v[:, -1] for k, v in first.items()}
    for t in range(prefix, T - 1):
        # Inputs for step t from the previous prediction or, per sequence with probability tf_ratio, the truth.
        theta_p, sbar_p, step_p = _predicted_step_inputs(norm, prev, last, batch["ref"][:, t], batch["ref"][:, t - 1])
        g3 = _teacher_mask(B, tf_ratio, generator, device)
        g1, g2 = g3[:, None], g3[:, None, None]
        q_in = torch.where(g2, batch["q"][:, t], prev["q"])
        aff_in = torch.where(g1, aff_z[:, t], prev["aff"])
        root_in = torch.where(g1, root_z[:, t], prev["root"])
        step_in = torch.where(g1, step_z[:, t], step_p)
        last = {"theta": torch.where(g3, batch["theta"][:, t], theta_p),
                "sbar": torch.where(g3, batch["sbar"][:, t], sbar_p)}
        out = run(model.step, q_in, aff_in, step_in, root_in, em[:, t], hidden)
        hidden, prev = out["hidden"], _decoded(out, decode, norm)
        for k in _PRED_KEYS:
            preds[k].append(prev[k][:, None])
    result = {k: torch.cat(v, dim=1) for k, v in preds.items()}
    if extra_steps > 0:
        result.update(_continue_free(run, model, norm, decode, prev, last, hidden, batch["ref"][:, -1], em[:, -1],
                                     extra_steps))
    return result


def evaluate(model: GaitNet, norm: Normalizer, data: GaitSequences, config: GaitNetConfig,
             batch_size: int = 64, amp: bool = False) -> dict:
    """Free-running validation (teacher forcing 0 after the prefix, plus ``train.extra_steps`` past the end): mean
    loss terms over ``data`` (on the model's device)."""
    model.eval()
    sums: dict[str, float] = {}
    n = 0
    with torch.no_grad():
        for start in range(0, len(data), batch_size):
            idx = np.arange(start, min(start + batch_size, len(data)))
            batch = data.batch(idx)
            pred = rollout(model, norm, batch, 0.0, config.prefix_len, extra_steps=config.train.extra_steps,
                           amp=amp)
            loss, terms = total_loss(pred, ground_truth_targets(batch, norm), config.loss, config.model.use_affective,
                                     style_from=config.prefix_len - 1)
            terms["total"] = loss.item()
            for k, v in terms.items():
                sums[k] = sums.get(k, 0.0) + v * len(idx)
            n += len(idx)
    model.train()
    return {k: v / max(n, 1) for k, v in sums.items()}


def save_checkpoint(path: Path, model: GaitNet, norm: Normalizer, config: GaitNetConfig, *,
                    training_data: TrainingData, **extra) -> None:
    """Write model weights, config, normaliser and what they were trained on (``training_data``: its record,
    ``trained_on`` its description, ``corpus`` its corpus file), plus any training state in ``extra``,
    device-independent: the weights and every tensor of ``extra`` (optimizer state) are copied to the CPU first.

    Format ``gait_net/3`` (:data:`CHECKPOINT_FORMAT`) stores the config split by section (``GaitNetConfig.to_dict``)
    and, from the weights' own record, ``training_data`` (:class:`generation.gait.weights.TrainingData`).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    payload = {"format": CHECKPOINT_FORMAT, "config": config.to_dict(), "normalizer": norm.to_dict(),
               "model": cpu_state_dict(model), "training_data": training_data.record(),
               "trained_on": training_data.description, "corpus": training_data.corpus, **to_cpu(extra)}
    tmp = path.with_suffix(path.suffix + ".tmp")
    torch.save(payload, tmp)
    tmp.replace(path)


def load_checkpoint(path: str | Path, device: str | torch.device | None = "cpu") -> tuple[GaitNet, Normalizer, dict]:
    """Load a file written by :func:`save_checkpoint` (read onto the CPU whatever device wrote it);
    returns (model in eval mode on ``device``, normaliser, payload). ``GaitNetConfig.from_dict(payload["config"])``
    is the full config."""
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
    if payload.get("format") not in READABLE_FORMATS:
        raise ValueError(f"{path}: checkpoint format {payload.get('format')!r}, expected one of {READABLE_FORMATS}")
    model = GaitNet(GaitNetConfig.from_dict(payload["config"]).model)
    model.load_state_dict(payload["model"])
    model.to(resolve_device(device))
    model.eval()
    return model, Normalizer.from_dict(payload["normalizer"]), payload


@dataclasses.dataclass
class _Step:
    """What one optimisation step needs besides the batch: model, normaliser, optimizer, config, the gradient
    scaler of fp16 autocast (None otherwise) and the mixed-precision flag."""

    model: GaitNet
    norm: Normalizer
    opt: torch.optim.Optimizer
    config: GaitNetConfig
    scaler: object | None = None
    amp: bool = False

    def __call__(self, batch: dict, tf: float, gen: torch.Generator) -> tuple[float, dict]:
        cfg = self.config
        pred = rollout(self.model, self.norm, batch, tf, cfg.prefix_len, gen, cfg.train.extra_steps, self.amp)
        loss, terms = total_loss(pred, ground_truth_targets(batch, self.norm), cfg.loss, cfg.model.use_affective,
                                 style_from=cfg.prefix_len - 1)
        self.opt.zero_grad()
        if self.scaler is not None:
            self.scaler.scale(loss).backward()
            self.scaler.unscale_(self.opt)
        else:
            loss.backward()
        torch.nn.utils.clip_grad_norm_(self.model.parameters(), cfg.train.grad_clip)
        if self.scaler is not None:
            self.scaler.step(self.opt)
            self.scaler.update()
        else:
            self.opt.step()
        return loss.item(), terms


def _train_epoch(step: _Step, train_set: GaitSequences, tf: float, rng: np.random.Generator, gen: torch.Generator,
                 desc: str, progress: bool) -> dict[str, float]:
    """One epoch over the training walks with teacher-forcing ratio ``tf``; returns the mean loss terms.

    ``train_set`` already lives on the model's device (moved once before training: the corpus is small), so a
    batch is an index into it and nothing is copied from the host per step."""

    tc = step.config.train
    # One row per corpus sequence per epoch, with a random subsampling offset when several exist.
    rows = rng.permutation(len(train_set))
    _, first = np.unique(train_set.base_index[rows], return_index=True)
    order = rows[np.sort(first)]
    batches = [order[i:i + tc.batch_size] for i in range(0, len(order), tc.batch_size)]
    sums: dict[str, float] = {}
    bar = tqdm(batches, desc=desc, disable=not progress, leave=False)
    for idx in bar:
        batch = splice_histories(train_set.batch(idx), step.config.prefix_len, tc.splice_frac, rng)
        if tc.uniform_label_frac > 0:
            batch = uniform_labels(batch, tc.uniform_label_frac, rng)
        total, terms = step(batch, tf, gen)
        terms["total"] = total
        for k, v in terms.items():
            sums[k] = sums.get(k, 0.0) + v / len(batches)
        bar.set_postfix(loss=f"{total:.3f}")
    return sums


def _initialise_from(path: str | Path, step: _Step, log) -> dict:
    """Copy the weights and normaliser of the weights file ``path`` into ``step`` (fine-tuning); returns
    {"path", "sha256", "epochs"} for the new file's record. The architectures must match."""
    model, norm, payload = load_checkpoint(path)
    if model.config != step.model.config:
        raise ValueError(f"--init {path}: its architecture {model.config} is not this run's {step.model.config}")
    step.model.load_state_dict(model.state_dict())
    if norm.aff_style_std is None:   # a file saved before the field: take it from this run's training walks
        norm.aff_style_std = step.norm.aff_style_std
    step.norm = norm
    log(f"initialised from {path} ({len(payload.get('history', []))} epochs)")
    return {"path": str(path), "sha256": file_sha256(path), "epochs": len(payload.get("history", []))}


def _resume(path: Path, step: _Step, sched, rng, gen, log) -> tuple[list, int]:
    """Restore the training state of ``path`` (read onto the CPU, moved onto the model's device by the
    load_state_dict calls); returns (history, first epoch to run)."""
    state = torch.load(path, map_location="cpu", weights_only=False)
    step.model.load_state_dict(state["model"])
    step.opt.load_state_dict(state["optimizer"])
    sched.load_state_dict(state["scheduler"])
    if step.scaler is not None and state.get("grad_scaler"):
        step.scaler.load_state_dict(state["grad_scaler"])
    step.norm = Normalizer.from_dict(state["normalizer"])
    rng.bit_generator.state = state["numpy_rng"]
    gen.set_state(state["torch_gen"])
    torch.set_rng_state(state["torch_rng"])
    log(f"resumed from {path} at epoch {state['epoch'] + 1}")
    return state["history"], state["epoch"] + 1


def train(config: GaitNetConfig, data: GaitSequences, out_path: str | Path, checkpoint_path: str | Path | None = None,
          resume: bool = False, max_minutes: float | None = None, progress: bool = True, log=print,
          device: str | torch.device | None = "auto", amp: bool = False, init: str | Path | None = None,
          keep_epochs: bool = False, refit_normalizer: bool = False) -> dict:
    """Train on ``data`` (its "train" split; "val" for validation); returns the history.

    Writes ``checkpoint_path`` (full training state) after every epoch and the final small weights file
    ``out_path`` (model, config, normaliser, history), both device-independent. ``resume`` continues from
    ``checkpoint_path``. ``max_minutes`` stops after the epoch that crosses the budget (the history records it).
    ``device``: "auto" (CUDA when available), "cpu", "cuda" or "cuda:N" (:func:`generation.core.device.resolve_device`);
    the model is initialised on the CPU from the seed and then moved, and the teacher-forcing draws come from a CPU
    generator, so a run of the same seed follows the same path on either device. ``amp``: mixed-precision forward
    passes (bf16 autocast, fp16 with a gradient scaler on GPUs without bf16). ``init``: start from the weights
    and normaliser of this weights file (same architecture; fine-tuning) instead of a random initialisation.
    ``keep_epochs``: also write the weights after every epoch to ``<out stem>_eNN.pt`` (for choosing an epoch on
    the validation walks afterwards). ``refit_normalizer``: with ``init``, standardise with this run's training
    walks instead of the initial file's statistics (another corpus, such as real capture after procedural walks).
    """
    if data.training_data is None:
        raise ValueError("the training sequences do not say what they are (GaitSequences.training_data)")
    tc = config.train
    dev = resolve_device(device)
    torch.manual_seed(tc.seed)
    rng = np.random.default_rng(tc.seed)
    gen = torch.Generator().manual_seed(tc.seed)
    train_set = data.subset("train").to(dev)
    val_set = data.subset((data.split == "val") & (data.offset == 0)).to(dev)
    if len(train_set) == 0:
        raise ValueError("the corpus has no 'train' sequences")
    model = GaitNet(config.model).to(dev)
    opt = torch.optim.Adam(model.parameters(), lr=tc.lr)
    sched = torch.optim.lr_scheduler.ExponentialLR(opt, gamma=tc.lr_decay)
    scaler = torch.amp.GradScaler("cuda") if needs_grad_scaler(dev, amp) else None
    step = _Step(model, fit_normalizer(train_set), opt, config, scaler, amp)
    fitted = step.norm
    init_info = _initialise_from(init, step, log) if init else None
    if refit_normalizer:
        step.norm = fitted
    history: list[dict] = []
    start_epoch = 0
    # Training state lives under var/ (not next to the shipped weights) unless a path is given.
    checkpoint_path = Path(checkpoint_path) if checkpoint_path else CHECKPOINT_DIR / (Path(out_path).name + ".ckpt")
    if resume and checkpoint_path.exists():
        history, start_epoch = _resume(checkpoint_path, step, sched, rng, gen, log)
    log(f"training on {describe(dev)}{', mixed precision' if amp else ''}")
    t0 = time.time()
    elapsed_before = history[-1]["elapsed_s"] if history else 0.0
    for epoch in range(start_epoch, tc.epochs):
        tf = tc.tf_start * tc.tf_decay ** epoch
        sums = _train_epoch(step, train_set, tf, rng, gen, desc=f"epoch {epoch + 1}/{tc.epochs} tf={tf:.2f}",
                            progress=progress)
        sched.step()
        val = evaluate(model, step.norm, val_set, config, amp=amp) if len(val_set) else {}
        elapsed = elapsed_before + time.time() - t0
        history.append({"epoch": epoch + 1, "tf": tf, "lr": opt.param_groups[0]["lr"], "train": sums, "val": val,
                        "elapsed_s": elapsed, "device": str(dev), "amp": bool(amp)})
        log(f"epoch {epoch + 1}: train {sums['total']:.4f} val {val.get('total', float('nan')):.4f} "
            f"tf {tf:.3f} ({elapsed / 60:.1f} min)")
        save_checkpoint(checkpoint_path, model, step.norm, config, training_data=data.training_data,
                        optimizer=opt.state_dict(),
                        scheduler=sched.state_dict(), epoch=epoch, history=history,
                        numpy_rng=rng.bit_generator.state, torch_gen=gen.get_state(),
                        torch_rng=torch.get_rng_state(), grad_scaler=scaler.state_dict() if scaler else None)
        if keep_epochs:
            out = Path(out_path)
            _save_weights(out.with_name(f"{out.stem}_e{epoch + 1:02d}{out.suffix}"), model, step.norm, config,
                          history, data, init_info)
        if max_minutes is not None and elapsed > 60 * max_minutes:
            log(f"stopping after epoch {epoch + 1}: time budget of {max_minutes} min used")
            break
    _save_weights(Path(out_path), model, step.norm, config, history, data, init_info)
    return {"history": history, "model": model, "normalizer": step.norm}


def _save_weights(path: Path, model: GaitNet, norm: Normalizer, config: GaitNetConfig, history: list[dict],
                  data: GaitSequences, init_info: dict | None) -> None:
    """The small, device-independent weights file (model, config, normaliser, history, provenance)."""
    save_checkpoint(path, model, norm, config, training_data=data.training_data, history=history,
                    num_parameters=model.num_parameters(), initialised_from=init_info)


CONFIG_NAMES = ("small", "paper")


def named_config(name: str) -> GaitNetConfig:
    """The configuration called ``name`` on the command line: "small" (``GaitNetConfig()``) or "paper"
    (``GaitNetConfig.paper()``)."""
    if name not in CONFIG_NAMES:
        raise ValueError(f"unknown gait config {name!r}: use one of {', '.join(CONFIG_NAMES)}")
    return GaitNetConfig.paper() if name == "paper" else GaitNetConfig()


def amp_for(device: torch.device, amp: bool, log=print) -> bool:
    """Whether mixed precision is used: ``amp`` on CUDA; on the CPU it is ignored with a message (bf16 autocast
    measured slower than float32 on the CPU, see docs/benchmarks/device.md)."""
    if amp and device.type != "cuda":
        log("--amp ignored on the CPU: bf16 autocast was slower than float32 there "
            "(benchmarks/bench_device.py); training in float32")
        return False
    return bool(amp)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description="Train the seed-000 emotive gait network on the gait corpus.")
    p.add_argument("--corpus", default=None, help="corpus .npz (default var/corpus/gait_corpus_synthetic.npz; "
                                                  "built with --num-sequences when missing)")
    p.add_argument("--num-sequences", type=int, default=1000)
    p.add_argument("--real", choices=REAL_STAGES, default=None,
                   help="train on the real-capture corpus instead (generation.gait.real_data): pretrain = forward "
                        "locomotion of both Bandai Namco datasets, labelled where the style is a gait emotion; "
                        "finetune = dataset 1's happy/sad/angry/normal walks; --corpus then names the real corpus "
                        "file (default $REAL_CORPUS, else var/mocap/bandai-namco.npz)")
    p.add_argument("--soft-labels", default=None, metavar="CLIP_NORMS.csv",
                   help="train on the rated walks of a clip_norms.csv (docs/study.md) with each one's perceived "
                        "share vector as its emotion target (with --real finetune: beside the real takes)")
    p.add_argument("--motions", default=None, metavar="DIR",
                   help="where the rated clips' motions are (<clip_id>.bvh; default $MEDIA_ROOT/motions)")
    p.add_argument("--clips", default=None, metavar="CLIPS.csv",
                   help="the clip catalogue, to tell a clip it does not know from a missing motion file (default: "
                        "clips.csv beside the motions folder, i.e. $MEDIA_ROOT/clips.csv, when there)")
    p.add_argument("--norms-study", default=None,
                   help="the study the norms come from, recorded in the weights (default: the CSV's folder name)")
    p.add_argument("--min-ratings", type=int, default=1, help="soft labels only from walks with this many ratings")
    p.add_argument("--refit-normalizer", action="store_true",
                   help="with --init: standardise with this run's training walks, not the initial file's")
    p.add_argument("--out", default=str(DEFAULT_WEIGHTS), help="weights file to write")
    p.add_argument("--checkpoint", default=None,
                   help="training-state checkpoint for --resume (default var/gait_runs/<OUT name>.ckpt)")
    p.add_argument("--resume", action="store_true", help="continue from the checkpoint")
    p.add_argument("--init", default=None, metavar="WEIGHTS.pt",
                   help="fine-tune: start from this weights file's network and normaliser (same architecture); "
                        "combine with --set tf_start=... for a lower starting teacher-forcing ratio")
    p.add_argument("--epochs", type=int, default=None)
    p.add_argument("--batch-size", type=int, default=None)
    p.add_argument("--seed", type=int, default=None)
    p.add_argument("--max-minutes", type=float, default=None, help="stop after the epoch that crosses this")
    p.add_argument("--config", choices=CONFIG_NAMES, default="small",
                   help="small: the CPU default that trained the shipped weights (GRU 2 x 256, 28 epochs); paper: "
                        "the published size end to end (GaitNetConfig.paper(): GRU 2 x 1024, 9.9 M parameters, "
                        "500 epochs, teacher forcing 0.995^epoch)")
    p.add_argument("--paper-size", action="store_true", help="same as --config paper")
    p.add_argument("--device", default="auto", help=f"{DEVICE_CHOICES} (auto: CUDA when available, else the CPU)")
    p.add_argument("--amp", action="store_true",
                   help="mixed precision (autocast of the forward passes: bf16, or fp16 with a gradient scaler on "
                        "GPUs without bf16); on the CPU it is ignored with a message (it measured slower there, "
                        "docs/benchmarks/device.md)")
    p.add_argument("--no-affective", action="store_true", help="ablation: no affective inputs and no L_aff")
    p.add_argument("--no-root-loss", action="store_true", help="ablation: lambda_root = 0")
    p.add_argument("--set", action="append", default=[], metavar="FIELD=JSON",
                   help="override any config field by its flat name or as SECTION.FIELD (sections model, data, "
                        "train, loss), e.g. --set gru_hidden=256 --set tf_decay=0.97 --set loss.pose=0.5")
    p.add_argument("--offsets", type=int, default=4,
                   help="subsampling offsets per sequence (augmentation; every 4th frame from frame 0..N-1)")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--keep-epochs", action="store_true",
                   help="also write the weights after every epoch to <out stem>_eNN.pt")
    return p


def config_from_args(args) -> GaitNetConfig:
    """The GaitNetConfig of parsed options: default or ``--paper-size``, then ``--set``, then the named options."""
    name = "paper" if getattr(args, "paper_size", False) else getattr(args, "config", "small")
    try:
        config = named_config(name)
    except ValueError as exc:
        raise SystemExit(f"--config: {exc}") from None
    overrides = {}
    for item in args.set:
        if "=" not in item:
            raise SystemExit(f"--set expects FIELD=JSON, got {item!r}")
        key, value = item.split("=", 1)
        try:
            overrides[key] = json.loads(value)
        except json.JSONDecodeError:
            raise SystemExit(f"--set {key}: the value must be JSON (a number, true/false, a list or a quoted "
                             f"string), got {value!r}") from None
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
    try:
        device = resolve_device(getattr(args, "device", "auto"))
    except ValueError as exc:
        raise SystemExit(f"--device: {exc}") from None
    amp = amp_for(device, getattr(args, "amp", False), log)
    config = config_from_args(args)
    if getattr(args, "soft_labels", None):
        data = _soft_label_data(args, config, log)
    elif getattr(args, "real", None):
        data = load_real_sequences(args.real, config.data, path=args.corpus)
    else:
        data = load_corpus_sequences(args.corpus, num_sequences=args.num_sequences, seed=0,
                                     frame_step=config.data.frame_step, seq_len=config.data.seq_len,
                                     offsets=tuple(range(args.offsets)))
    counts = ", ".join(f"{s}: {int(((data.split == s) & (data.offset == 0)).sum())}" for s in SPLITS)
    log(f"{len(data)} sequences ({counts}), network {GaitNet(config.model).num_parameters()} parameters")
    result = train(config, data, args.out, args.checkpoint, args.resume, args.max_minutes, progress=not args.quiet,
                   log=log, device=device, amp=amp, init=getattr(args, "init", None),
                   keep_epochs=getattr(args, "keep_epochs", False),
                   refit_normalizer=getattr(args, "refit_normalizer", False))
    log(f"wrote {args.out}")
    return result


SOFT_LABEL_WEIGHTS = Path("var/weights/gait_net_soft_labels.pt")
"""Where a soft-label run writes unless --out says otherwise (never over the shipped weights)."""


def _soft_label_data(args, config: GaitNetConfig, log) -> GaitSequences:
    """The rated walks of ``--soft-labels`` (and, with ``--real``, that stage's real takes beside them); points
    ``--out`` away from the shipped weights."""
    if args.motions is None:
        raise SystemExit("--soft-labels: say where the clips' motions are (--motions DIR or MEDIA_ROOT)")
    try:
        soft = load_soft_label_sequences(args.soft_labels, args.motions, config.data, study=args.norms_study,
                                         min_ratings=args.min_ratings, catalogue=getattr(args, "clips", None))
    except (SoftLabelError, ValueError) as exc:
        raise SystemExit(f"--soft-labels: {exc}") from None
    if Path(args.out).resolve() == Path(DEFAULT_WEIGHTS).resolve():
        args.out = str(SOFT_LABEL_WEIGHTS)
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        log(f"--soft-labels: writing {args.out} (the shipped weights are never replaced; --out to choose)")
    info = soft.training_data.corpus["soft_labels"]
    log(f"soft labels: {info['n_clips']} rated walks, {info['n_ratings']} ratings, study {info['study']}")
    if not getattr(args, "real", None):
        return soft
    real = load_real_sequences(args.real, config.data, path=args.corpus)
    soft.base_index = soft.base_index + int(real.base_index.max()) + 1
    both = concat_sequences([real, soft])
    return dataclasses.replace(both, clip_names=(*real.clip_names, *soft.clip_names),
                               training_data=real.training_data.with_soft_labels(soft.training_data))


def with_edge_paths(args: argparse.Namespace, real_corpus: str | Path,
                    media_root: str | Path | None) -> argparse.Namespace:
    """``args`` with the paths its edge (the command line, the Django command) fills in where they are left out:
    with ``--real``, ``--corpus`` = ``real_corpus``; ``--motions`` = ``media_root/motions`` (when given)."""
    if getattr(args, "real", None) and args.corpus is None:
        args.corpus = str(real_corpus)
    if getattr(args, "motions", None) is None and media_root:
        args.motions = Path(media_root) / "motions"
    return args


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    # $REAL_CORPUS: the real corpus of --real; $MEDIA_ROOT: the study app's media folder (rated clips' motions)
    run(with_edge_paths(args, real_corpus_path(os.environ), os.environ.get("MEDIA_ROOT")))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
