"""Training and generation speed of the gait network per device (docs/benchmarks/device.md).

Measures on this machine's CPU (and on CUDA when torch sees a GPU):
1. seconds per training epoch of the small (default) and the paper-size (``GaitNetConfig.paper()``) config: a few
   batches of the real corpus are timed (teacher forcing 0.5, spliced histories, the free-running continuation,
   backward and Adam step) and extrapolated to one epoch (one row per training walk, plus the validation pass);
   the table says so;
2. the same with mixed precision (``--amp``: bf16 autocast on the CPU, bf16/fp16 on CUDA);
3. generation speed of ``generate_gaits`` (1 and 10 agents, 100 network steps, 30 fps output, foot planting off)
   in ms per agent per output frame, next to the paper's 4 ms per agent per frame (two GTX 1080 Ti, including
   rendering). The paper-size network is timed with untrained weights (speed does not depend on the values).

Usage: python -m benchmarks.bench_device [--batches 2] [--threads 1] [--no-doc]
Writes var/benchmarks/bench_device.json and rewrites the gait part of docs/benchmarks/device.md (the Gesture
subsection below the marker is kept).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np
import torch

from generation.core.device import autocast_context, describe, resolve_device
from generation.core.paths import straight
from generation.gait.config import GaitNetConfig
from generation.gait.generate import LoadedGaitNet, generate_gaits, load_default_model
from generation.gait.model import GaitNet
from generation.gait.train import _Step, evaluate, fit_normalizer, splice_histories

DOC = Path("docs/benchmarks/device.md")
GESTURE_MARKER = "### Gesture"
NO_GPU = "not measured: no GPU lent this session"
PAPER_MS_PER_AGENT_FRAME = 4.0


def _sync(device: torch.device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def epoch_seconds(config: GaitNetConfig, data, device: torch.device, batches: int, amp: bool) -> dict:
    """Seconds per epoch of ``config`` on ``device``: ``batches`` training batches timed (after one warm-up batch)
    and extrapolated to all training walks, plus one timed validation pass."""
    torch.manual_seed(0)
    train_set = data.subset("train").to(device)
    val_set = data.subset("val").to(device)
    model = GaitNet(config.model).to(device)
    step = _Step(model, fit_normalizer(train_set), torch.optim.Adam(model.parameters(), lr=1e-3), config,
                 amp=amp)
    rng, gen = np.random.default_rng(0), torch.Generator().manual_seed(0)
    bs = config.train.batch_size
    times = []
    for i in range(batches + 1):
        idx = rng.choice(len(train_set), bs, replace=False)
        batch = splice_histories(train_set.batch(idx), config.prefix_len, config.train.splice_frac, rng)
        _sync(device)
        t0 = time.perf_counter()
        step(batch, 0.5, gen)
        _sync(device)
        if i:  # the first batch is a warm-up
            times.append(time.perf_counter() - t0)
    n_batches = int(np.ceil(len(train_set) / bs))
    t0 = time.perf_counter()
    evaluate(model, step.norm, val_set, config, amp=amp)
    _sync(device)
    val_s = time.perf_counter() - t0
    per_batch = float(np.mean(times))
    return {"s_per_batch": per_batch, "batches_timed": batches, "batches_per_epoch": n_batches,
            "validation_s": val_s, "s_per_epoch": per_batch * n_batches + val_s,
            "parameters": model.num_parameters(), "batch_size": bs}


def amp_ratio_interleaved(config: GaitNetConfig, data, device: torch.device, pairs: int = 3,
                          batch_size: int = 16) -> dict:
    """Time of a training batch with mixed precision over its float32 time, measured as alternating float32 / amp
    batches (same model, same batches) so that a changing load from other jobs hits both alike; median ratio."""
    config = config.with_overrides(batch_size=batch_size)
    torch.manual_seed(0)
    train_set = data.subset("train").to(device)
    model = GaitNet(config.model).to(device)
    norm = fit_normalizer(train_set)
    opt = torch.optim.Adam(model.parameters(), lr=1e-3)
    steps = {amp: _Step(model, norm, opt, config, amp=amp) for amp in (False, True)}
    rng, gen = np.random.default_rng(0), torch.Generator().manual_seed(0)
    ratios, t_amp, t_fp32 = [], [], []
    for i in range(pairs + 1):
        idx = rng.choice(len(train_set), batch_size, replace=False)
        batch = splice_histories(train_set.batch(idx), config.prefix_len, config.train.splice_frac, rng)
        times = {}
        for amp in ((False, True) if i % 2 else (True, False)):
            _sync(device)
            t0 = time.perf_counter()
            steps[amp](batch, 0.5, gen)
            _sync(device)
            times[amp] = time.perf_counter() - t0
        if i:  # the first pair is a warm-up
            ratios.append(times[True] / times[False])
            t_amp.append(times[True])
            t_fp32.append(times[False])
    return {"ratio_median": float(np.median(ratios)), "ratios": ratios, "s_amp": t_amp, "s_fp32": t_fp32,
            "batch_size": batch_size}


def generation_speed(net: LoadedGaitNet, device: torch.device, steps: int = 100, repeats: int = 2) -> dict:
    """ms per agent per 30 fps frame of generate_gaits for 1 and 10 agents (best of ``repeats``)."""
    seed = None
    out = {}
    for n in (1, 10):
        best = float("inf")
        for _ in range(repeats):
            _sync(device)
            t0 = time.perf_counter()
            ms = generate_gaits([seed] * n, [straight(40.0)] * n, np.tile([0.25, 0.25, 0.25, 0.25], (n, 1)),
                                steps=steps, model=net, device=device, foot_cleanup=False, rng_seed=1)
            _sync(device)
            best = min(best, time.perf_counter() - t0)
        frames = ms[0].num_frames
        out[f"{n}_agents"] = {"ms_per_agent_per_frame": 1000 * best / (n * frames),
                              "ms_per_frame_all_agents": 1000 * best / frames, "frames": frames, "steps": steps}
    return out


def _cpu_amp_check() -> bool:
    """Whether bf16 autocast works on this CPU at all (it needs a torch build with CPU autocast)."""
    try:
        with autocast_context(torch.device("cpu"), True):
            torch.randn(2, 2) @ torch.randn(2, 2)
        return True
    except RuntimeError:
        return False


def measure(batches: int) -> dict:
    from generation.gait.data import load_corpus_sequences
    data = load_corpus_sequences()   # offset 0 only: an epoch takes one row per training walk anyway
    devices = [torch.device("cpu")] + ([resolve_device("cuda")] if torch.cuda.is_available() else [])
    small, paper = GaitNetConfig(), GaitNetConfig.paper()
    shipped = load_default_model()
    paper_net = LoadedGaitNet(GaitNet(paper.model).eval(), shipped.normalizer, "untrained-paper-size", config=paper)
    res = {"machine": {"cpu": platform.processor() or platform.machine(), "cores": os.cpu_count(),
                       "torch_threads": torch.get_num_threads(), "torch": torch.__version__,
                       "load_average_start": os.getloadavg()},
           "devices": {}}
    for dev in devices:
        r = {"name": describe(dev)}
        r["small"] = epoch_seconds(small, data, dev, batches, amp=False)
        r["paper"] = epoch_seconds(paper, data, dev, max(1, batches // 2), amp=False)
        if dev.type == "cuda" or _cpu_amp_check():
            r["small_amp"] = epoch_seconds(small, data, dev, batches, amp=True)
            r["amp_interleaved"] = amp_ratio_interleaved(small, data, dev)
        r["generation_small"] = generation_speed(shipped, dev)
        r["generation_paper"] = generation_speed(paper_net, dev)
        res["devices"][dev.type] = r
    res["machine"]["load_average_end"] = os.getloadavg()
    return res


def _fmt_epoch(r: dict | None, key: str, epochs: int) -> str:
    if r is None:
        return NO_GPU
    e = r[key]
    return (f"{e['s_per_epoch']:.0f} s/epoch ({e['s_per_batch']:.1f} s/batch x {e['batches_per_epoch']} + "
            f"{e['validation_s']:.0f} s validation; {epochs} epochs = {e['s_per_epoch'] * epochs / 3600:.1f} h)")


def _fmt_gen(r: dict | None, key: str, n: str) -> str:
    if r is None:
        return NO_GPU
    g = r[key][f"{n}_agents"]
    return f"{g['ms_per_agent_per_frame']:.2f} ms ({g['ms_per_frame_all_agents']:.1f} ms per frame, all agents)"


def gait_markdown(res: dict) -> str:
    cpu, gpu = res["devices"]["cpu"], res["devices"].get("cuda")
    m = res["machine"]
    la0, la1 = m["load_average_start"], m["load_average_end"]
    rows = [
        ("training, small config (0.72 M parameters, batch 64)", _fmt_epoch(cpu, "small", 28),
         _fmt_epoch(gpu, "small", 28)),
        ("training, small config, `--amp` (bf16 autocast)",
         _fmt_epoch(cpu, "small_amp", 28) if "small_amp" in cpu else "bf16 autocast unavailable",
         _fmt_epoch(gpu, "small_amp", 28) if gpu else NO_GPU),
        ("training, paper config (9.9 M parameters, batch 64)", _fmt_epoch(cpu, "paper", 500),
         _fmt_epoch(gpu, "paper", 500)),
    ]
    for n in ("1", "10"):
        rows.append((f"generation, small network, {n} agent(s), ms per agent per 30 fps frame",
                     _fmt_gen(cpu, "generation_small", n), _fmt_gen(gpu, "generation_small", n)))
        rows.append((f"generation, paper-size network, {n} agent(s), ms per agent per 30 fps frame",
                     _fmt_gen(cpu, "generation_paper", n), _fmt_gen(gpu, "generation_paper", n)))
    table = "\n".join(f"| {a} | {b} | {c} |" for a, b, c in rows)
    amp_note = ""
    if "amp_interleaved" in cpu:
        ratio = cpu["amp_interleaved"]["ratio_median"]
        amp_note = (f"bf16 autocast on this CPU took {ratio:.2f}x the float32 time per training batch (median of "
                    f"{len(cpu['amp_interleaved']['ratios'])} alternating float32 / bf16 batches of "
                    f"{cpu['amp_interleaved']['batch_size']}, so that the other jobs' load hits both alike; the "
                    f"separate rows above were timed minutes apart under a changing load). ")
    return f"""## Devices: training and generation speed

Machine: 2-core CI VM, no GPU, shared with parallel jobs (load average {la0[0]:.1f} at the start, {la1[0]:.1f} at the
end of this run: the other helpers' tests and trainings), {m['torch_threads']} torch thread, torch {m['torch']}.
Date: 2026-12-01. Script: `benchmarks/bench_device.py` (JSON in `var/benchmarks/bench_device.json`).

Seconds per epoch are **extrapolated**: {cpu['small']['batches_timed']} training batches of the small config and
{cpu['paper']['batches_timed']} of the paper config were timed after a warm-up batch (teacher forcing 0.5, 30 %
spliced histories, the free-running continuation, backward pass and Adam step) and multiplied by the batches of an
epoch (one row per training walk: {cpu['small']['batches_per_epoch']} batches of 64), plus one timed validation
pass. Generation: `generate_gaits` end to end (seed walk, network, path steering, 30 fps output; foot planting off),
100 network steps, best of 2; the paper-size network with untrained weights (speed only). The paper reports 4 ms per
agent per frame (two GTX 1080 Ti, rendering included). {amp_note}Under this shared load the CPU figures are upper
bounds; the GPU column is empty because no GPU was lent to this session (`--device cuda` is implemented and tested
for its error message; `tests/test_device.py` compares a CPU and a CUDA run of one seed when a GPU is present).

### Gait network

| measurement | CPU, {m['torch_threads']} torch thread | GPU |
|---|---|---|
{table}
| paper (two GTX 1080 Ti) | | {PAPER_MS_PER_AGENT_FRAME:.0f} ms per agent per frame |
"""


GESTURE_PLACEHOLDER = f"""{GESTURE_MARKER}

(The gesture helper adds its rows here: same columns, `benchmarks/bench_gesture.py` or its own script.)

| measurement | CPU | GPU |
|---|---|---|
| (to be filled) | | {NO_GPU} |
"""


def write_doc(res: dict, path: Path = DOC) -> None:
    """Rewrite the gait part of ``path``; keep everything from the Gesture subsection on (or add a placeholder)."""
    tail = GESTURE_PLACEHOLDER
    if path.exists():
        text = path.read_text()
        if GESTURE_MARKER in text:
            tail = text[text.index(GESTURE_MARKER):]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(gait_markdown(res) + "\n" + tail)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batches", type=int, default=2, help="training batches timed per config (after a warm-up)")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--no-doc", action="store_true", help="do not rewrite docs/benchmarks/device.md")
    ap.add_argument("--out", default="var/benchmarks/bench_device.json")
    ap.add_argument("--amp-only", action="store_true",
                    help="only (re)measure the interleaved float32 / bf16 comparison into an existing --out JSON")
    args = ap.parse_args(argv)
    torch.set_num_threads(args.threads)
    if args.amp_only:
        from generation.gait.data import load_corpus_sequences
        res = json.loads(Path(args.out).read_text())
        res["devices"]["cpu"]["amp_interleaved"] = amp_ratio_interleaved(GaitNetConfig(), load_corpus_sequences(),
                                                                         torch.device("cpu"))
    else:
        res = measure(args.batches)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(res, indent=1, default=float))
    print(gait_markdown(res))
    if not args.no_doc:
        write_doc(res)
        print(f"wrote {DOC}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
