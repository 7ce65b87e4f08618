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


def load_model(path: str | Path) -> GestureNet:
    """A trained network in eval mode from a weights file written by :func:`generation.gesture.train.save_weights`."""
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
    net.eval()
    return net


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

    Returns:
        (B, max(lengths), J, 4) unit quaternions; frames past a sample's length are meaningless.
    """
    net.eval()
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
            window = window + noise * torch.randn(window.shape, generator=generator)
            window = window / window.norm(dim=-1, keepdim=True)
        positions = torch.arange(start, len(history))[None].expand(B, -1)
        progress = progress_features(positions, lengths, fps)
        nxt = net.decode(memory, token_mask, attributes, window, positions, progress, rest)[:, -1]
        outputs.append(nxt)
        history.append(nxt)
    return torch.stack(outputs, dim=1)


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


def decode_examples(net: GestureNet, data, idx, batch_size: int = 64) -> list[np.ndarray]:
    """Generate the gesture of each dataset example ``idx`` from its text and attributes only.

    Returns a list of (L_i, J, 4) float64 arrays at the data's frame rate, L_i the example's length, with the same
    rest-pose blending as :func:`generate_gesture` (the ground truth is never fed to the decoder).
    """
    idx = np.asarray(idx)
    out: list[np.ndarray] = []
    for start in range(0, len(idx), batch_size):
        chunk = idx[start:start + batch_size]
        S = int(data.token_lengths[chunk].max())
        lengths = torch.from_numpy(data.lengths[chunk])
        rot = rollout(net, torch.from_numpy(data.tokens[chunk, :S]),
                      torch.arange(S)[None] < torch.from_numpy(data.token_lengths[chunk])[:, None],
                      torch.from_numpy(data.attributes[chunk]), torch.from_numpy(data.rest[chunk]), lengths,
                      data.fps).double().numpy()
        for n, i in enumerate(chunk):
            L = int(data.lengths[i])
            out.append(blend_rest_ends(rot[n, :L], data.rest[i], int(round(START_BLEND_S * data.fps)),
                                       int(round(END_BLEND_S * data.fps))))
    return out


def generate_gesture(sentence: str, task: str = "narration", emotion: str = "joyous", gender: str = "female",
                     handedness: str = "right", fps: float = 30.0, model: GestureNet | None = None, seed: int = 0,
                     noise: float = 0.0) -> Motion:
    """A seated gesture Motion for ``sentence`` on the 23-joint skeleton of the gender's build.

    Args:
        sentence: the text the agent says (at least one word).
        task: "narration" or "conversation". emotion: one of the 11 MPI categories (study_protocol.GESTURE_EMOTIONS).
        gender: "female" or "male" (picks the body build). handedness: "left" or "right".
        fps: output frame rate. model: a network (default: the shipped one). seed, noise: the network is
        deterministic; with ``noise`` > 0 the decoder inputs are jittered (seeded) for variations.

    Returns:
        Motion (T, 23, 4) at ``fps``, root fixed at the seated root position; metadata names the intent.
    """
    if task not in config.TASKS:
        raise ValueError(f"task must be one of {config.TASKS}, got {task!r}")
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps}")
    vad = nrc_vad(emotion)
    attrs = attribute_vector(task, vad, gender, handedness)
    net = model if model is not None else load_default_model()
    net_fps = float(getattr(net, "train_fps", config.TRAIN_FPS))
    n_words = count_words(sentence)
    n_frames = config.gesture_frames(n_words, net_fps)
    tokens = torch.from_numpy(get_encoder().encode(sentence))[None]
    skeleton = gesture_skeleton(build=gender)
    rest_rot, root = rest_rotations(gender)
    generator = torch.Generator().manual_seed(seed)
    rot = rollout(net, tokens, torch.ones(tokens.shape[:2], dtype=torch.bool), torch.from_numpy(attrs)[None],
                  torch.as_tensor(rest_rot, dtype=torch.float32)[None], torch.tensor([n_frames]), net_fps,
                  noise=noise, generator=generator)[0].double().numpy()
    rot = blend_rest_ends(rot, rest_rot, int(round(START_BLEND_S * net_fps)), int(round(END_BLEND_S * net_fps)))
    motion = Motion(skeleton, rot, np.repeat(root[None], len(rot), axis=0), net_fps, {
        "origin": "generated", "generator": "gesture_net", "sentence": sentence, "task": task,
        "emotion_label": emotion, "valence": vad[0], "arousal": vad[1], "dominance": vad[2], "gender": gender,
        "handedness": handedness, "trained_on": SYNTHETIC_LABEL, "network_fps": net_fps, "seed": seed,
    })
    return motion.resample(fps) if abs(fps - net_fps) > 1e-9 else motion
