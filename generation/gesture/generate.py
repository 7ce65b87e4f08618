"""Generate seated emotive gestures from a sentence with the trained network (seed 003 sections 3, 5.2, 5.5).

At generation the decoder starts from the start-of-sequence rest pose and predicts one pose per step from the
past ``window`` = 20 steps, at the network's frame rate (10 fps); the result is resampled (slerp) to the requested
frame rate. The gesture length follows the sentence (:func:`generation.gesture.config.gesture_seconds`); the
network is trained to come back to the seated rest pose at the end; the first 0.2 s and the last 0.3 s are eased
onto the exact rest pose so clips always start and end there. The shipped network is trained on SYNTHETIC
procedural gestures.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from generation.core.device import resolve_device
from generation.core.motion import Motion
from generation.core.quaternion import qslerp
from generation.core.skeleton import gesture_skeleton

from . import config
from .data import SYNTHETIC_LABEL, attribute_vector, nrc_vad, progress_features, rest_rotations
from .model import GestureNet, GestureNetConfig
from .text import count_words, get_encoder

END_BLEND_S = 0.3
START_BLEND_S = 0.2


class GestureModelUnavailable(RuntimeError):
    """The weights file is missing or not a gesture-network file."""


def load_model(path: str | Path, device: torch.device | str | None = "cpu") -> GestureNet:
    """A trained network in eval mode from a weights file written by :func:`generation.gesture.train.save_weights`.

    The file holds CPU tensors and is read with ``map_location="cpu"`` (a GPU-trained file loads on any machine);
    the network is then moved to ``device`` ("cpu", "cuda", "cuda:N" or "auto", see
    :func:`generation.core.device.resolve_device`).
    """
    path = Path(path)
    if not path.is_file():
        raise GestureModelUnavailable(f"{path}: gesture network weights not found; train them with "
                                      "`python -m generation.gesture.train` (or manage.py train_gesture)")
    try:
        blob = torch.load(path, map_location="cpu", weights_only=False)
        net = GestureNet(GestureNetConfig(**blob["config"]))
        net.load_state_dict(blob["state_dict"])
    except (KeyError, TypeError, RuntimeError, OSError) as exc:
        raise GestureModelUnavailable(f"{path}: not a gesture network weights file ({exc})") from exc
    net.train_fps = float(blob.get("train_fps", config.TRAIN_FPS))
    net.real_statistics = blob.get("real_statistics")   # real-capture ranges the training used, with their licence
    net.eval()
    return net.to(resolve_device(device))


def _real_statistics_credit(net: GestureNet) -> dict:
    """Clip metadata crediting the real capture whose statistics shaped the weights (loss, selection), if any."""
    stats = getattr(net, "real_statistics", None)
    if not stats:
        return {}
    return {"real_statistics_source": stats.get("source", ""), "real_statistics_licence": stats.get("licence", ""),
            "real_statistics_citation": stats.get("citation", "")}


_DEFAULT: GestureNet | None = None


def load_default_model() -> GestureNet:
    """The shipped network (``generation/data/weights/gesture_net_default.pt``), loaded once per process."""
    global _DEFAULT
    if _DEFAULT is None:
        _DEFAULT = load_model(config.DEFAULT_WEIGHTS)
    return _DEFAULT


@torch.no_grad()
def rollout(net: GestureNet, tokens: torch.Tensor, token_mask: torch.Tensor, attributes: torch.Tensor,
            rest: torch.Tensor, lengths: torch.Tensor, fps: float, noise: float = 0.0,
            generator: torch.Generator | None = None) -> torch.Tensor:
    """Autoregressive decoding of a batch.

    Args:
        tokens (B, S, 384), token_mask (B, S) bool, attributes (B, 9), rest (B, J, 4) start-of-sequence pose,
        lengths (B,) frames to generate per sample, fps the network's frame rate, noise optional input jitter.

    All tensors must be on the network's device; ``noise`` is drawn from the CPU ``generator`` and moved there,
    so a seed gives the same jitter on every device.

    Returns:
        (B, max(lengths), J, 4) unit quaternions on the network's device; frames past a sample's length are
        meaningless.
    """
    net.eval()
    device = tokens.device
    memory = net.encode(tokens, token_mask, attributes)
    B = tokens.shape[0]
    T = int(lengths.max())
    # Each self-attention layer looks back ``window`` steps, so the stacked decoder's output depends on the last
    # n_layer * (window - 1) + 1 inputs; feeding exactly those reproduces the teacher-forced computation.
    W = net.receptive_field
    rest = rest.to(torch.float32)
    history = [rest]  # input poses at positions 0, 1, ...; position 0 is the SoS pose
    outputs = []
    for _ in range(T):
        start = max(0, len(history) - W)
        window = torch.stack(history[start:], dim=1)
        if noise > 0:
            window = window + (noise * torch.randn(window.shape, generator=generator)).to(device)
            window = window / window.norm(dim=-1, keepdim=True)
        positions = torch.arange(start, len(history), device=device)[None].expand(B, -1)
        progress = progress_features(positions, lengths, fps)
        nxt = net.decode(memory, token_mask, attributes, window, positions, progress, rest)[:, -1]
        outputs.append(nxt)
        history.append(nxt)
    return torch.stack(outputs, dim=1)


def _place(net: GestureNet, device: torch.device | str | None) -> torch.device:
    """Move ``net`` to ``device`` (None: leave it) and return the device it is on."""
    if device is not None:
        net.to(resolve_device(device))
    return next(net.parameters()).device


def blend_rest_ends(rotations: np.ndarray, rest: np.ndarray, n_start: int, n_end: int) -> np.ndarray:
    """Pin the first and last frames of (T, J, 4) to the rest pose (J, 4), easing in/out with smoothstep slerps.

    Frame 0 becomes exactly ``rest`` and frames 1..n_start-1 move from it onto the network's poses; the last
    ``n_end`` frames move onto ``rest``, the last one exactly. Returns a new (T, J, 4) array.
    """
    out = np.array(rotations, dtype=np.float64)
    T = len(out)
    rest_t = torch.as_tensor(rest, dtype=torch.float64)

    def _slerp_towards_rest(frames: slice, w_rest: np.ndarray):
        seg = torch.as_tensor(out[frames])
        w = torch.as_tensor(w_rest)[:, None].expand(seg.shape[:-1])
        out[frames] = qslerp(seg, rest_t.expand_as(seg), w).numpy()

    n_start, n_end = min(n_start, T), min(n_end, T)
    if n_start > 0:
        s = np.linspace(0.0, 1.0, n_start + 1)[:-1]
        _slerp_towards_rest(slice(0, n_start), 1.0 - s * s * (3 - 2 * s))
    if n_end > 0:
        s = np.linspace(0.0, 1.0, n_end + 1)[1:]
        _slerp_towards_rest(slice(T - n_end, T), s * s * (3 - 2 * s))
    return out


def decode_examples(net: GestureNet, data, idx, batch_size: int = 64,
                    device: torch.device | str | None = None) -> list[np.ndarray]:
    """Generate the gesture of each dataset example ``idx`` from its text and attributes only.

    ``device``: where to run (None = where the network is; otherwise the network is moved there).
    Returns a list of (L_i, J, 4) float64 arrays at the data's frame rate, L_i the example's length, with the same
    rest-pose blending as :func:`generate_gesture` (the ground truth is never fed to the decoder).
    """
    dev = _place(net, device)
    idx = np.asarray(idx)
    out: list[np.ndarray] = []
    for start in range(0, len(idx), batch_size):
        chunk = idx[start:start + batch_size]
        S = int(data.token_lengths[chunk].max())

        def put(a):
            return torch.from_numpy(np.ascontiguousarray(a)).to(dev)

        rot = rollout(net, put(data.tokens[chunk, :S]),
                      torch.arange(S, device=dev)[None] < put(data.token_lengths[chunk])[:, None],
                      put(data.attributes[chunk]), put(data.rest[chunk]), put(data.lengths[chunk]),
                      data.fps).double().cpu().numpy()
        for n, i in enumerate(chunk):
            L = int(data.lengths[i])
            out.append(blend_rest_ends(rot[n, :L], data.rest[i], int(round(START_BLEND_S * data.fps)),
                                       int(round(END_BLEND_S * data.fps))))
    return out


def generate_gesture(sentence: str, task: str = "narration", emotion: str = "joyous", gender: str = "female",
                     handedness: str = "right", fps: float = 30.0, model: GestureNet | None = None, seed: int = 0,
                     noise: float = 0.0, device: torch.device | str | None = None) -> Motion:
    """A seated gesture Motion for ``sentence`` on the 23-joint skeleton of the gender's build.

    Args:
        sentence: the text the agent says (at least one word).
        task: "narration" or "conversation". emotion: one of the 11 MPI categories
            (protocol.vocabulary.GESTURE_EMOTIONS).
        gender: "female" or "male" (picks the body build). handedness: "left" or "right".
        fps: output frame rate. model: a network (default: the shipped one). seed, noise: the network is
        deterministic; with ``noise`` > 0 the decoder inputs are jittered (seeded) for variations.
        device: where the network runs ("cpu", "cuda", "cuda:N", "auto"; None = where the model is). The model is
        moved there; the result is the same Motion (numpy, CPU) whichever device computed it.

    Returns:
        Motion (T, 23, 4) at ``fps``, root fixed at the seated root position; metadata names the intent.
    """
    return generate_gestures(sentence, [emotion], task, gender, handedness, fps, model, seed, noise, device)[0]


def generate_gestures(sentence: str, emotions, task: str = "narration", gender: str = "female",
                      handedness: str = "right", fps: float = 30.0, model: GestureNet | None = None, seed: int = 0,
                      noise: float = 0.0, device: torch.device | str | None = None) -> list[Motion]:
    """:func:`generate_gesture` for one sentence said with each of ``emotions``, decoded as one batch (the text is
    encoded once): a list of Motions in the order of ``emotions``; the other arguments as there."""
    if task not in config.TASKS:
        raise ValueError(f"task must be one of {config.TASKS}, got {task!r}")
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps}")
    emotions = list(emotions)
    if not emotions:
        raise ValueError("emotions is empty: give at least one emotion")
    vads = [nrc_vad(e) for e in emotions]
    attrs = np.stack([attribute_vector(task, vad, gender, handedness) for vad in vads])
    net = model if model is not None else load_default_model()
    dev = _place(net, device)
    net_fps = float(getattr(net, "train_fps", config.TRAIN_FPS))
    n_frames = config.gesture_frames(count_words(sentence), net_fps)
    B = len(emotions)
    tokens = torch.from_numpy(get_encoder().encode(sentence))[None].expand(B, -1, -1)
    skeleton = gesture_skeleton(build=gender)
    rest_rot, root = rest_rotations(gender)
    rest = torch.as_tensor(rest_rot, dtype=torch.float32)[None].expand(B, -1, -1)
    rots = rollout(net, tokens.to(dev), torch.ones(tokens.shape[:2], dtype=torch.bool, device=dev),
                   torch.from_numpy(attrs).to(dev), rest.to(dev), torch.full((B,), n_frames, device=dev), net_fps,
                   noise=noise, generator=torch.Generator().manual_seed(seed)).double().cpu().numpy()
    out = []
    for emotion, vad, rot in zip(emotions, vads, rots):
        rot = blend_rest_ends(rot, rest_rot, int(round(START_BLEND_S * net_fps)), int(round(END_BLEND_S * net_fps)))
        motion = Motion(skeleton, rot, np.repeat(root[None], len(rot), axis=0), net_fps, {
            "origin": "generated", "generator": "gesture_net", "sentence": sentence, "task": task,
            "emotion_label": emotion, "valence": vad[0], "arousal": vad[1], "dominance": vad[2], "gender": gender,
            "handedness": handedness, "trained_on": SYNTHETIC_LABEL, "network_fps": net_fps, "seed": seed,
            **_real_statistics_credit(net),
        })
        out.append(motion.resample(fps, smooth=True) if abs(fps - net_fps) > 1e-9 else motion)
    return out
