"""Where the networks run: device selection and optional mixed precision (shared by the gait and gesture nets).

``resolve_device("auto")`` picks CUDA when torch sees a GPU and the CPU otherwise; ``"cpu"``, ``"cuda"`` and
``"cuda:N"`` ask for one explicitly and fail with a clear message when it does not exist.
``autocast_context(device, enabled)`` is the mixed-precision region for network forward passes: bf16 autocast on
CUDA GPUs that support it (fp16 otherwise, which needs a gradient scaler: :func:`needs_grad_scaler`), bf16 on the
CPU, and a no-op when ``enabled`` is False.

Weights are saved device-independent (:func:`cpu_state_dict`) and loaded with ``map_location="cpu"`` before being
moved, so a file trained on a GPU loads on a machine without one.
"""
from __future__ import annotations

import contextlib
import re

import torch

DEVICE_CHOICES = "auto, cpu, cuda or cuda:N"
_CUDA_RE = re.compile(r"^cuda(?::(\d+))?$")


def resolve_device(spec: str | torch.device | None = "auto") -> torch.device:
    """The torch device named by ``spec``.

    Args:
        spec: "auto" or None (CUDA device 0 when ``torch.cuda.is_available()``, else the CPU), "cpu", "cuda"
            (device 0), "cuda:N", or a ``torch.device``. Case and surrounding spaces are ignored.

    Raises:
        ValueError: an unknown name, CUDA asked for on a machine without it, or N out of range.
    """
    if isinstance(spec, torch.device):
        spec = str(spec)
    name = "auto" if spec is None else str(spec).strip().lower()
    if name == "auto":
        return torch.device("cuda", 0) if torch.cuda.is_available() else torch.device("cpu")
    if name == "cpu":
        return torch.device("cpu")
    match = _CUDA_RE.match(name)
    if not match:
        raise ValueError(f"unknown device {spec!r}: use {DEVICE_CHOICES}")
    if not torch.cuda.is_available():
        raise ValueError(f"device {spec!r} asked for, but CUDA is not available on this machine "
                         f"(torch {torch.__version__}, built with CUDA {torch.version.cuda}); use --device cpu or auto")
    index = int(match.group(1) or 0)
    count = torch.cuda.device_count()
    if index >= count:
        raise ValueError(f"device {spec!r} asked for, but this machine has {count} CUDA device(s) "
                         f"(cuda:0 .. cuda:{count - 1})")
    return torch.device("cuda", index)


def amp_dtype(device: torch.device) -> torch.dtype:
    """The autocast dtype on ``device``: bf16 on the CPU and on GPUs that support it, fp16 on older GPUs."""
    if device.type == "cuda" and not torch.cuda.is_bf16_supported():
        return torch.float16
    return torch.bfloat16


def needs_grad_scaler(device: torch.device, enabled: bool) -> bool:
    """True when mixed precision on ``device`` is fp16 and so needs ``torch.amp.GradScaler`` in training."""
    return bool(enabled) and device.type == "cuda" and amp_dtype(device) == torch.float16


def autocast_context(device: torch.device | str, enabled: bool):
    """A context manager for the forward passes: autocast to :func:`amp_dtype` on ``device`` when ``enabled``,
    otherwise a no-op (full float32). Compute losses outside it, on float32 outputs."""
    device = resolve_device(device) if not isinstance(device, torch.device) else device
    if not enabled:
        return contextlib.nullcontext()
    return torch.autocast(device_type=device.type, dtype=amp_dtype(device))


def cpu_state_dict(module: torch.nn.Module) -> dict:
    """``module.state_dict()`` with every tensor detached and copied to the CPU (device-independent files).

    Always a copy, also when the module is on the CPU (where ``.to("cpu")`` would return the parameters' own
    storage): a kept state then does not change with later optimiser steps."""
    return {k: v.detach().to("cpu", copy=True) for k, v in module.state_dict().items()}


def to_cpu(obj):
    """A copy of nested dicts / lists / tuples with every tensor moved to the CPU (optimizer states, RNG states)."""
    if isinstance(obj, torch.Tensor):
        return obj.detach().to("cpu")
    if isinstance(obj, dict):
        return {k: to_cpu(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return type(obj)(to_cpu(v) for v in obj)
    return obj


def describe(device: torch.device) -> str:
    """A one-line description of ``device`` for logs ("cpu (2 threads)", "cuda:0 (NVIDIA H200)")."""
    if device.type == "cuda":
        return f"{device} ({torch.cuda.get_device_name(device)})"
    return f"cpu ({torch.get_num_threads()} threads)"


__all__ = ["DEVICE_CHOICES", "amp_dtype", "autocast_context", "cpu_state_dict", "describe", "needs_grad_scaler",
           "resolve_device", "to_cpu"]
