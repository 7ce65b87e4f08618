"""Devices of the gesture network: --device / --amp, device-independent weights, CPU vs GPU agreement, the
paper-size preset."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from generation.gesture import config
from generation.gesture.model import PAPER_PARAMETERS, GestureNet, GestureNetConfig, paper_config
from generation.gesture.train import TrainConfig, build_parser, config_from_args, preset_config, train

HAS_CUDA = torch.cuda.is_available()
NO_GPU = "no CUDA GPU on this machine (torch.cuda.is_available() is False)"
# CPU and GPU runs of the same seed draw every random number from the same CPU generator and start from the same
# CPU-initialised weights; what differs is float32 rounding (GPU kernels sum in another order, TF32 is off by
# default for matmuls in torch 2.x). Two epochs of a tiny network stay within this relative tolerance.
CPU_GPU_RTOL = 1e-3


@pytest.fixture(scope="module")
def tiny_data(tmp_path_factory):
    from generation.gesture.data import build_dataset, load_sentences

    rows = [r for r in load_sentences() if r.emotion in ("sad", "proud")][::6]  # 10 sentences
    return build_dataset(variants=1, seed=0, cache_dir=tmp_path_factory.mktemp("gesture_cache"), rows=rows)


def _tiny_cfg(tmp_path, device: str, **kw) -> TrainConfig:
    base = dict(epochs=2, batch_size=4, max_minutes=None, rollout_every=0, device=device,
                model=GestureNetConfig(d_model=16, d_ff=32, dropout=0.0),
                out=str(tmp_path / f"w_{device.replace(':', '')}.pt"),
                checkpoint=str(tmp_path / f"ck_{device.replace(':', '')}.pt"))
    base.update(kw)
    return TrainConfig(**base)


# ---- device choice -----------------------------------------------------------------------------------
def test_cli_device_and_preset_options():
    cfg = config_from_args(build_parser().parse_args(["--device", "cpu"]))
    assert (cfg.device, cfg.amp, cfg.preset, cfg.model.d_model, cfg.max_minutes) == ("cpu", False, "small", 64, 20.0)
    paper = config_from_args(build_parser().parse_args(["--config", "paper", "--device", "auto", "--amp"]))
    assert paper.model.d_model == 992 and paper.epochs == 600 and paper.max_minutes is None and paper.amp
    short = config_from_args(build_parser().parse_args(["--config", "paper", "--epochs", "3", "--max-minutes", "5"]))
    assert (short.epochs, short.max_minutes, short.model.d_model) == (3, 5.0, 992)
    with pytest.raises(ValueError, match="unknown gesture config"):
        config_from_args(build_parser().parse_args(["--config", "huge"]))
    with pytest.raises(ValueError, match="unknown device"):
        config_from_args(build_parser().parse_args(["--device", "tpu"]))


@pytest.mark.skipif(HAS_CUDA, reason="checks the error on a machine without CUDA")
def test_asking_for_cuda_without_a_gpu_is_a_clear_error():
    with pytest.raises(ValueError, match="CUDA is not available"):
        config_from_args(build_parser().parse_args(["--device", "cuda"]))
    from django.core.management import CommandError, call_command

    with pytest.raises(CommandError, match="CUDA is not available"):
        call_command("train_gesture", "--device", "cuda:0", "--quiet")


def test_training_on_the_cpu_writes_device_independent_weights(tmp_path, tiny_data):
    from generation.gesture.generate import load_model

    summary = train(_tiny_cfg(tmp_path, "cpu"), data=tiny_data, progress=False)
    assert summary["device"] == "cpu" and summary["epochs_run"] == 2
    assert all("epoch_seconds" in h for h in summary["history"])
    blob = torch.load(tmp_path / "w_cpu.pt", map_location="cpu", weights_only=False)
    assert all(v.device.type == "cpu" and v.dtype == torch.float32 for v in blob["state_dict"].values())
    assert blob["trained_on"] == "synthetic procedural gestures" and blob["device"] == "cpu"
    net = load_model(tmp_path / "w_cpu.pt", device="cpu")
    assert next(net.parameters()).device.type == "cpu"


def test_generation_device_argument_on_the_cpu():
    from generation.gesture.generate import generate_gesture, load_model

    net = load_model(config.DEFAULT_WEIGHTS, device="auto")
    a = generate_gesture("Look at that!", emotion="surprised", model=net, fps=10.0, device="cpu")
    b = generate_gesture("Look at that!", emotion="surprised", model=net, fps=10.0)
    assert next(net.parameters()).device.type == "cpu"
    np.testing.assert_array_equal(a.rotations, b.rotations)
    with pytest.raises(ValueError, match="unknown device"):
        generate_gesture("Look at that!", model=net, device="gpu7")


def test_device_corpus_batches_match_the_dataset_batches(tiny_data):
    idx = tiny_data.indices("train")[:3]
    a = tiny_data.batch(idx, noise=0.05, generator=torch.Generator().manual_seed(3))
    b = tiny_data.on_device("cpu").batch(idx, noise=0.05, generator=torch.Generator().manual_seed(3))
    for k in a:
        torch.testing.assert_close(a[k], b[k], rtol=0, atol=0)
    assert a["inputs"].shape[0] == 3 and a["mask"].dtype == torch.bool


# ---- GPU ---------------------------------------------------------------------------------------------
@pytest.mark.skipif(not HAS_CUDA, reason=NO_GPU)
def test_generation_on_cuda_matches_the_cpu():
    from generation.gesture.generate import generate_gesture, load_model

    cpu = generate_gesture("Look at that!", emotion="angry", model=load_model(config.DEFAULT_WEIGHTS), fps=10.0)
    gpu_net = load_model(config.DEFAULT_WEIGHTS, device="cuda")
    gpu = generate_gesture("Look at that!", emotion="angry", model=gpu_net, fps=10.0)
    assert next(gpu_net.parameters()).device.type == "cuda"
    np.testing.assert_allclose(gpu.rotations, cpu.rotations, atol=1e-3)


@pytest.mark.skipif(not HAS_CUDA, reason=NO_GPU)
def test_cpu_and_gpu_runs_of_one_seed_reach_the_same_validation_loss(tmp_path, tiny_data):
    cpu = train(_tiny_cfg(tmp_path, "cpu"), data=tiny_data, progress=False)
    gpu = train(_tiny_cfg(tmp_path, "cuda"), data=tiny_data, progress=False)
    assert gpu["device"].startswith("cuda")
    for a, b in zip(cpu["history"], gpu["history"]):
        assert b["val"]["total"] == pytest.approx(a["val"]["total"], rel=CPU_GPU_RTOL)
    amp = train(_tiny_cfg(tmp_path, "cuda", amp=True, out=str(tmp_path / "amp.pt")), data=tiny_data,
                progress=False)
    assert np.isfinite(amp["history"][-1]["val"]["total"])


# ---- the published size ------------------------------------------------------------------------------
def test_paper_preset_has_the_published_parameter_count():
    n = GestureNet(paper_config()).num_parameters()
    assert abs(n - PAPER_PARAMETERS) / PAPER_PARAMETERS < 0.05, n
    cfg = preset_config("paper")
    assert cfg.epochs == 600 and cfg.max_minutes is None and cfg.preset == "paper"
    assert (cfg.model.n_layer, cfg.model.n_head, cfg.model.d_ff, cfg.model.window) == (2, 2, 200, 20)


def test_paper_preset_trains_one_tiny_step(tmp_path, tiny_data):
    """One epoch of one batch of the 26 M-parameter network: finite losses, weights written and loadable (about 3 s
    on an idle core, 30 s on the loaded CI VM)."""
    import dataclasses

    from generation.gesture.generate import load_model

    split = np.full(len(tiny_data), "test", dtype=object)
    split[tiny_data.indices("train")[:2]] = "train"
    data = dataclasses.replace(tiny_data, split=split.astype(str))  # 2 training examples, no validation
    cfg = preset_config("paper", epochs=1, batch_size=2, rollout_every=0, device="cpu", sampling=0.0,
                        out=str(tmp_path / "paper.pt"), checkpoint=str(tmp_path / "paper_ck.pt"))
    summary = train(cfg, data=data, progress=False)
    assert summary["epochs_run"] == 1 and np.isfinite(summary["history"][0]["train"]["total"])
    assert load_model(tmp_path / "paper.pt").num_parameters() == GestureNet(paper_config()).num_parameters()


def test_amp_is_ignored_with_a_warning_on_the_cpu(tmp_path, tiny_data):
    with pytest.warns(UserWarning, match="ignored on cpu"):
        summary = train(_tiny_cfg(tmp_path, "cpu", amp=True, epochs=1), data=tiny_data, progress=False)
    assert np.isfinite(summary["history"][0]["val"]["total"])
