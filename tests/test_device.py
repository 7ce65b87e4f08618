"""Device selection and mixed precision (generation.core.device) and the gait network on a chosen device:
device-independent checkpoints, the same training path on the CPU and on CUDA, --device / --amp / --config options.

The CUDA comparisons are skipped with a reason on machines without a GPU (the 2-core CI VM has none)."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from generation.core import device as devmod
from generation.core.device import autocast_context, cpu_state_dict, resolve_device, to_cpu
from generation.core.paths import straight
from generation.gait.config import GaitNetConfig
from generation.gait.generate import LoadedGaitNet, generate_gaits
from generation.gait.model import GaitNet
from generation.gait.train import _Step, fit_normalizer, load_checkpoint, splice_histories, train
from generation.procedural.walk import WalkParams, walk

torch.set_num_threads(1)
NO_CUDA = "no CUDA device on this machine (the CPU/GPU comparison needs one)"
CPU_GPU_VAL_RTOL = 2e-3   # stated tolerance: relative difference of the validation loss, CPU vs CUDA run


# ---- resolve_device ------------------------------------------------------------------------------
def test_auto_and_cpu(monkeypatch):
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    assert resolve_device("auto") == torch.device("cpu")
    assert resolve_device(None) == torch.device("cpu")
    assert resolve_device(" CPU ") == torch.device("cpu")
    assert resolve_device(torch.device("cpu")) == torch.device("cpu")
    monkeypatch.setattr(torch.cuda, "is_available", lambda: True)
    assert resolve_device("auto") == torch.device("cuda", 0)


def test_cuda_requests_fail_clearly_without_cuda(monkeypatch):
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    for spec in ("cuda", "cuda:0", "CUDA:1"):
        with pytest.raises(ValueError, match="CUDA is not available"):
            resolve_device(spec)


def test_cuda_index_range_and_unknown_names(monkeypatch):
    monkeypatch.setattr(torch.cuda, "is_available", lambda: True)
    monkeypatch.setattr(torch.cuda, "device_count", lambda: 2)
    assert resolve_device("cuda") == torch.device("cuda", 0)
    assert resolve_device("cuda:1") == torch.device("cuda", 1)
    with pytest.raises(ValueError, match=r"2 CUDA device\(s\) \(cuda:0 .. cuda:1\)"):
        resolve_device("cuda:2")
    for bad in ("gpu", "mps", "cuda:x", "cuda:-1", ""):
        with pytest.raises(ValueError, match="unknown device"):
            resolve_device(bad)


def test_autocast_context_and_cpu_copies():
    a = torch.randn(4, 4)
    with autocast_context(torch.device("cpu"), False):
        assert (a @ a).dtype == torch.float32
    with autocast_context("cpu", True):
        assert (a @ a).dtype == torch.bfloat16
    assert devmod.amp_dtype(torch.device("cpu")) == torch.bfloat16
    assert not devmod.needs_grad_scaler(torch.device("cpu"), True)
    net = torch.nn.Linear(3, 2)
    sd = cpu_state_dict(net)
    assert set(sd) == {"weight", "bias"} and all(v.device.type == "cpu" and not v.requires_grad for v in sd.values())
    with torch.no_grad():
        net.weight.add_(1.0)                  # a copy even on the CPU: later changes to the module do not reach it
    assert not torch.equal(sd["weight"], net.weight)
    nested = to_cpu({"a": [torch.ones(2), (torch.zeros(1), 3)], "b": "x"})
    assert nested["b"] == "x" and nested["a"][1][1] == 3 and torch.equal(nested["a"][0], torch.ones(2))


# ---- the gait network on a device ----------------------------------------------------------------
@pytest.fixture(scope="module")
def tiny_data():
    from generation.gait.data import prepare_sequences
    from generation.gait.weights import TrainingData
    rng = np.random.default_rng(1)
    rots, roots = [], []
    for _ in range(6):
        m = walk(WalkParams(cadence_spm=rng.uniform(95, 125), stride_m=rng.uniform(1.1, 1.5)), straight(12.0), 240,
                 30.0, phase=float(rng.random()))
        rots.append(m.rotations)
        roots.append(m.root_positions)
    split = np.array(["train", "train", "train", "train", "val", "val"])
    return prepare_sequences(np.stack(rots), np.stack(roots), np.eye(4)[[0, 1, 2, 3, 0, 1]], split,
                             np.full(6, 1.75), np.array(["female"] * 6), training_data=TrainingData.procedural())


TINY = dict(epochs=1, batch_size=2, tf_decay=0.5)


def _train(tiny_data, tmp_path, device, name):
    cfg = GaitNetConfig.tiny(**TINY)
    return train(cfg, tiny_data, tmp_path / f"{name}.pt", tmp_path / f"{name}.ckpt", progress=False,
                 log=lambda *_: None, device=device)


def test_cpu_training_writes_device_independent_files(tiny_data, tmp_path):
    a = _train(tiny_data, tmp_path, "cpu", "a")
    b = _train(tiny_data, tmp_path, None, "b") if not torch.cuda.is_available() else a   # auto = cpu here
    assert a["history"][-1]["val"]["total"] == b["history"][-1]["val"]["total"]
    assert a["history"][-1]["device"] == "cpu"
    state = torch.load(tmp_path / "a.ckpt", map_location="cpu", weights_only=False)
    tensors = [v for v in state["model"].values()]
    tensors += [v for s in state["optimizer"]["state"].values() for v in s.values() if isinstance(v, torch.Tensor)]
    assert tensors and all(t.device.type == "cpu" for t in tensors)
    model, _, payload = load_checkpoint(tmp_path / "a.pt", device="cpu")
    assert next(model.parameters()).device.type == "cpu" and payload["trained_on"] == "synthetic procedural corpus"


@pytest.mark.skipif(not torch.cuda.is_available(), reason=NO_CUDA)
def test_cpu_and_cuda_runs_of_one_seed_give_the_same_validation_loss(tiny_data, tmp_path):
    cpu = _train(tiny_data, tmp_path, "cpu", "cpu")
    gpu = _train(tiny_data, tmp_path, "cuda", "gpu")
    v_cpu, v_gpu = cpu["history"][-1]["val"]["total"], gpu["history"][-1]["val"]["total"]
    assert gpu["history"][-1]["device"].startswith("cuda")
    assert abs(v_cpu - v_gpu) <= CPU_GPU_VAL_RTOL * abs(v_cpu), (v_cpu, v_gpu)
    # The GPU-trained file loads on the CPU (map_location) and generates there.
    model, norm, _ = load_checkpoint(tmp_path / "gpu.pt", device="cpu")
    net = LoadedGaitNet(model, norm, "gpu.pt", config=GaitNetConfig.tiny(**TINY))
    seed = walk(WalkParams(), straight(10.0), 80, 30.0)
    args = ([seed], [straight(10.0)], np.array([[0, 0, 1.0, 0]]))
    (m_cpu,) = generate_gaits(*args, steps=10, model=net, foot_cleanup=False)
    (m_gpu,) = generate_gaits(*args, steps=10, model=net, foot_cleanup=False, device="cuda")
    np.testing.assert_allclose(m_cpu.root_positions, m_gpu.root_positions, atol=1e-3)


def test_generation_device_argument_keeps_the_callers_model(tiny_data):
    torch.manual_seed(0)
    cfg = GaitNetConfig.tiny()
    net = LoadedGaitNet(GaitNet(cfg.model), fit_normalizer(tiny_data.subset("train")), "tiny.pt", config=cfg)
    seed = walk(WalkParams(), straight(10.0), 80, 30.0)
    args = ([seed], [straight(10.0)], np.array([[1.0, 0, 0, 0]]))
    (a,) = generate_gaits(*args, steps=8, model=net)
    (b,) = generate_gaits(*args, steps=8, model=net, device="cpu")
    np.testing.assert_array_equal(a.rotations, b.rotations)
    assert net.on("cpu") is net and net.device.type == "cpu"
    if not torch.cuda.is_available():
        with pytest.raises(ValueError, match="CUDA is not available"):
            generate_gaits(*args, steps=8, model=net, device="cuda")


@pytest.mark.slow
def test_paper_config_builds_and_takes_one_training_step(tiny_data):
    """The published size end to end: GaitNetConfig.paper() (9.9 M parameters), one optimisation step on two
    sequences (5-30 s on one thread of the shared 2-core VM, hence slow)."""
    torch.manual_seed(0)
    cfg = GaitNetConfig.paper(batch_size=2, extra_steps=2)
    assert cfg.train.epochs == 500 and cfg.train.tf_decay == 0.995
    model = GaitNet(cfg.model)
    assert 9.5e6 < model.num_parameters() < 10.5e6
    data = tiny_data.subset("train")
    norm = fit_normalizer(data)
    step = _Step(model, norm, torch.optim.Adam(model.parameters(), lr=cfg.train.lr), cfg)
    before = [p.detach().clone() for p in model.parameters()]
    batch = splice_histories(data.batch([0, 1]), cfg.prefix_len, 0.0, np.random.default_rng(0))
    loss, terms = step(batch, 0.5, torch.Generator().manual_seed(0))
    assert np.isfinite(loss) and {"motion", "pose", "aff", "style"} <= set(terms)
    assert any(not torch.equal(p, q) for p, q in zip(before, model.parameters()))


def test_command_line_device_amp_and_config_options(capsys):
    from generation.gait.train import amp_for, build_parser, config_from_args
    args = build_parser().parse_args(["--config", "paper", "--device", "cpu", "--amp", "--epochs", "1"])
    assert args.device == "cpu" and args.amp
    cfg = config_from_args(args)
    assert cfg.model == GaitNetConfig.paper().model and cfg.train.epochs == 1
    assert config_from_args(build_parser().parse_args([])) == GaitNetConfig()
    assert config_from_args(build_parser().parse_args(["--paper-size"])).model == GaitNetConfig.paper().model
    messages = []
    assert amp_for(torch.device("cpu"), True, messages.append) is False and "ignored on the CPU" in messages[0]
    with pytest.raises(SystemExit):
        build_parser().parse_args(["--config", "huge"])


@pytest.mark.skipif(torch.cuda.is_available(), reason="this machine has CUDA; the error path needs a CPU-only one")
def test_train_gait_command_rejects_cuda_on_a_cpu_machine():
    from django.core.management import CommandError, call_command
    with pytest.raises(CommandError, match="CUDA is not available"):
        call_command("train_gait", "--device", "cuda", "--epochs", "1")
