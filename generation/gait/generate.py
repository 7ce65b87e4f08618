"""Emotive gait generation with the trained network (seed 000 sections 5.4.1-5.4.2).

``generate_gaits`` continues a seed gait (at least 18 network steps of 1/7.5 s, i.e. 2.4 s at 30 fps)
along a desired ground path with a desired emotion, constant or changing per step, for many agents in
one batch. Each step the network predicts the next pose (joint rotations, the root's rotation relative
to the path heading) and the root features h, s, delta and the phase increment omega; the root is then
moved by s along the predicted travel direction (facing + delta) and its height set to mean + h. The
path enters through the heading frame: its direction is the direction from the agent to a look-ahead
point ``lookahead_m`` ahead on the path (pure pursuit), and kappa is computed from it. The agent is thus
steered but not placed on the path: an agent whose predicted delta or speed is off drifts from it, which
is what the trajectory-following benchmark measures.

Output frames are interpolated from the network rate to ``fps_out`` (Motion.resample).
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch

from generation.core.device import resolve_device
from generation.core.foot_contact import plant_feet
from generation.core.motion import Motion
from generation.core.paths import GroundPath, straight
from generation.core.quaternion import np_qfix, np_qnormalize
from generation.procedural.emotion import gait_params_for_emotion
from generation.procedural.walk import WalkParams, walk
from protocol.vocabulary import GAIT_EMOTIONS

from .config import NUM_EMOTIONS, NUM_JOINTS, GaitDataConfig, GaitNetConfig
from .data import (
    SBAR_ALPHA,
    Normalizer,
    affective_features,
    facing_yaw,
    heading_frame_positions,
    kappa_torch,
    prepare_sequences,
    world_rotations,
    wrap,
)
from .model import GaitNet
from .real_seeds import real_seed
from .train import load_checkpoint
from .weights import DEFAULT_WEIGHTS_NAME, TrainingData, is_real, training_data_of, weights_path


@dataclass
class LoadedGaitNet:
    """A trained network with its normaliser, full config and the information saved with it.

    ``config`` defaults to the default data, training and loss settings around the model's own architecture.
    """

    model: GaitNet
    normalizer: Normalizer
    path: str
    info: dict = field(default_factory=dict)
    config: GaitNetConfig | None = None
    # what the weights were trained on (a weights file's record; a network built in code: the procedural corpus)
    training_data: TrainingData = field(default_factory=TrainingData.procedural)

    def __post_init__(self):
        if self.config is None:
            self.config = GaitNetConfig(model=self.model.config)
        elif self.config.model != self.model.config:
            raise ValueError(f"{self.path}: the config's architecture {self.config.model} is not the model's "
                             f"{self.model.config}")

    @property
    def fps(self) -> float:
        """Network rate in steps per second (30 fps corpus / frame_step)."""
        return 30.0 / self.config.data.frame_step

    @property
    def emotion_guidance(self) -> float:
        """The emotion-guidance scale generation uses by default with these weights (``info["emotion_guidance"]``,
        chosen on the validation walks and stored in the weights file; 0 when the file has none)."""
        return float(self.info.get("emotion_guidance", 0.0))

    @property
    def device(self) -> torch.device:
        """Where the model's weights are."""
        return next(self.model.parameters()).device

    def on(self, device: str | torch.device | None) -> LoadedGaitNet:
        """This network on ``device`` (:func:`generation.core.device.resolve_device`): itself when it is there
        already, otherwise a copy (cached per device), so that the shared default model is never moved."""
        dev = resolve_device(device)
        if dev == self.device:
            return self
        copies = self.__dict__.setdefault("_copies", {})
        if str(dev) not in copies:
            model = copy.deepcopy(self.model).to(dev).eval()
            copies[str(dev)] = LoadedGaitNet(model, self.normalizer, self.path, dict(self.info), self.config,
                                             self.training_data)
        return copies[str(dev)]


_DEFAULT: dict[str, LoadedGaitNet] = {}


def load_model(path: str | Path, device: str | torch.device | None = "cpu") -> LoadedGaitNet:
    """Load weights written by the training command (on any device) onto ``device``."""
    model, norm, payload = load_checkpoint(path, device)
    info = {k: payload[k] for k in ("num_parameters", "corpus", "initialised_from", "emotion_guidance")
            if k in payload}
    training = training_data_of(payload)
    info["trained_on"] = training.description
    info["epochs"] = len(payload.get("history", []))
    info["weights_name"] = next((n for n in ("real", "procedural") if Path(path).name == weights_path(n).name),
                                Path(path).stem)
    return LoadedGaitNet(model, norm, str(path), info, GaitNetConfig.from_dict(payload["config"]), training)


def load_default_model(device: str | torch.device | None = None, weights: str | None = None) -> LoadedGaitNet:
    """Shipped weights by name (``generation.gait.weights``: "real", the default, or "procedural"), cached after
    the first call, on the CPU; with ``device``, a copy on that device, also cached."""
    name = DEFAULT_WEIGHTS_NAME if weights is None else weights
    path = weights_path(name)
    if name not in _DEFAULT:
        if not path.exists():
            raise FileNotFoundError(
                f"{name} gait weights missing: {path}; docs/benchmarks/gait.md has the training commands")
        _DEFAULT[name] = load_model(path)
    return _DEFAULT[name] if device is None else _DEFAULT[name].on(device)


# ---- emotions --------------------------------------------------------------------------------
def normalize_emotion(e) -> np.ndarray:
    """l1-normalise emotion vectors (..., 4) (components ``GAIT_EMOTIONS``); negative entries are an error."""
    e = np.asarray(e, dtype=np.float64)
    if e.shape[-1] != NUM_EMOTIONS:
        raise ValueError(f"emotion vectors must have {NUM_EMOTIONS} entries ({', '.join(GAIT_EMOTIONS)}), "
                         f"got shape {e.shape}")
    if (e < 0).any() or not np.isfinite(e).all():
        raise ValueError("emotion vectors must be finite and non-negative")
    total = e.sum(-1, keepdims=True)
    if (total <= 0).any():
        raise ValueError("an emotion vector sums to zero")
    return e / total


def emotion_transition(initial, final, steps: int) -> np.ndarray:
    """(steps, 4) per-step emotions from ``initial`` to ``final`` (section 5.4.2): each component linearly
    interpolated over the steps, then each step's vector normalised to sum to one."""
    a, b = normalize_emotion(initial), normalize_emotion(final)
    w = np.linspace(0.0, 1.0, steps)[:, None]
    return normalize_emotion((1 - w) * a + w * b)


# ---- seeds -----------------------------------------------------------------------------------
def _seed_motion(seed, emotion0: np.ndarray, n_frames: int, rng: np.random.Generator, real: bool = False) -> Motion:
    """A Motion from a seed given as Motion, WalkParams, a params dict, or None (with ``real``, a stretch of the
    shipped captured walk of the emotion, :func:`generation.gait.real_seeds.real_seed`; else a procedural walk)."""
    if isinstance(seed, Motion):
        return seed
    if seed is None and real:
        return real_seed(emotion0, n_frames, rng)
    if seed is None:
        params = gait_params_for_emotion(emotion0, rng)
    elif isinstance(seed, WalkParams):
        params = seed
    elif isinstance(seed, dict):
        params = WalkParams.from_dict(seed)
    else:
        raise TypeError(f"a seed must be a Motion, WalkParams, a params dict or None, got {type(seed).__name__}")
    return walk(params, straight(30.0), n_frames, 30.0, phase=float(rng.random()))


def _seed_sequence(motion: Motion, frame_step: int, max_steps: int, min_steps: int, index: int):
    if motion.skeleton.num_joints != NUM_JOINTS:
        raise ValueError(f"seed gait {index}: needs the 21-joint gait skeleton, "
                         f"got {motion.skeleton.num_joints} joints")
    m = motion.resample(30.0)
    steps = (m.num_frames - 1) // frame_step + 1
    if steps < min_steps:
        raise ValueError(f"seed gait {index}: {motion.num_frames} frames at {motion.fps} fps give {steps} network "
                         f"steps; at least {min_steps} are needed "
                         f"({(min_steps - 1) * frame_step + 1} frames at 30 fps)")
    steps = min(steps, max_steps)
    need = frame_step * (steps - 1) + 1
    m = m.slice(m.num_frames - need)
    uniform = np.full((1, NUM_EMOTIONS), 1.0 / NUM_EMOTIONS)  # the seed's label is not used
    return prepare_sequences(m.rotations[None], m.root_positions[None], uniform, np.array(["seed"]),
                             np.array([m.skeleton.height]), np.array([m.skeleton.build]), fps=30.0,
                             frame_step=frame_step, seq_len=steps, skeletons=[m.skeleton])


# ---- path following --------------------------------------------------------------------------
class _PathTracker:
    """Projection of an agent onto a path and the pure-pursuit heading."""

    def __init__(self, path: GroundPath, extra_m: float, spacing: float = 0.05):
        self.s = np.arange(-2.0, path.length + extra_m, spacing)
        self.pts = path.point_at(self.s)
        self.i = int(np.searchsorted(self.s, 0.0))

    def project(self, xz: np.ndarray) -> tuple[float, float]:
        """(arc length, distance) of the nearest path point, searched near the previous projection."""
        lo = max(0, self.i - 20)
        hi = min(len(self.s), self.i + 60)
        d = np.linalg.norm(self.pts[lo:hi] - xz, axis=-1)
        k = int(np.argmin(d))
        self.i = lo + k
        return float(self.s[self.i]), float(d[k])

    def pursuit_heading(self, xz: np.ndarray, lookahead_m: float) -> float:
        s, _ = self.project(xz)
        j = min(len(self.s) - 1, int(np.searchsorted(self.s, s + lookahead_m)))
        d = self.pts[j] - xz
        return float(np.arctan2(d[0], d[1]))


def distance_to_path(path: GroundPath, xz: np.ndarray, spacing: float = 0.02, beyond_end_m: float = 100.0
                     ) -> np.ndarray:
    """(T,) distance in metres of ground points (T, 2) from the path, including its straight extension
    ``beyond_end_m`` past the end (where generation keeps walking when the path is shorter than the walk)."""
    s = np.arange(-1.0, path.length + beyond_end_m, spacing)
    pts = path.point_at(s)
    out = np.empty(len(xz))
    for i, p in enumerate(xz):
        out[i] = np.linalg.norm(pts - p, axis=-1).min()
    return out


# ---- generation ------------------------------------------------------------------------------
def _check_inputs(seeds, paths: list[GroundPath], emotions, steps: int) -> tuple[list, np.ndarray]:
    """(seeds as a list of N, emotions as l1-normalised (N, steps, 4)); ValueError on inconsistent inputs."""
    N = len(paths)
    if seeds is None:
        seeds = [None] * N
    if len(seeds) != N:
        raise ValueError(f"got {len(seeds)} seeds for {N} paths")
    if steps < 1:
        raise ValueError(f"steps must be positive, got {steps}")
    emotions = np.asarray(emotions, dtype=np.float64)
    if emotions.ndim == 2:
        emotions = np.repeat(emotions[:, None], steps, axis=1)
    if emotions.shape != (N, steps, NUM_EMOTIONS):
        raise ValueError(f"emotions must be ({N}, {NUM_EMOTIONS}) or ({N}, {steps}, {NUM_EMOTIONS}), "
                         f"got {emotions.shape}")
    return seeds, normalize_emotion(emotions)


_SEED_KEYS = ("q", "root", "theta", "omega", "sbar", "kappa", "ref", "aff", "offsets", "mean_height", "root_pos")


def _seed_batch(seeds: list, emotions: np.ndarray, data: GaitDataConfig, rng: np.random.Generator,
                real: bool = False) -> tuple[list[Motion], dict]:
    """The seed Motions and one batch of their network-rate features, each cut to the last L steps, L being
    the shortest seed's length (at most ``data.seq_len``): dict of tensors (N, L, ...) (offsets (N, J, 3),
    mean_height (N,))."""
    n_frames = data.frame_step * (data.seq_len - 1) + 1
    motions = [_seed_motion(s, emotions[i, 0], n_frames, rng, real) for i, s in enumerate(seeds)]
    seqs = [_seed_sequence(m, data.frame_step, data.seq_len, data.prefix_len, i) for i, m in enumerate(motions)]
    L = min(s.q.shape[1] for s in seqs)
    batch = {k: torch.cat([getattr(s, k)[:, -L:] if getattr(s, k).dim() > 1 and k != "offsets" else getattr(s, k)
                           for s in seqs]) for k in _SEED_KEYS}
    return motions, batch


@dataclass
class _Placement:
    """Rigid move of each seed: its last root ground point onto the path start, its last heading onto the path's
    heading at arc length 0."""

    rot_yaw: np.ndarray  # (N,) radians added to the seed's headings
    last_xz: np.ndarray  # (N, 2) the seed's last root ground point
    start: np.ndarray    # (N, 2) the path starts

    @classmethod
    def onto_paths(cls, paths: list[GroundPath], seed: dict) -> _Placement:
        rot_yaw = np.array([p.heading_at(0.0) for p in paths]) - seed["ref"][:, -1].double().numpy()
        last_xz = seed["root_pos"][:, -1][:, [0, 2]].double().numpy()
        return cls(rot_yaw, last_xz, np.stack([p.point_at(0.0) for p in paths]))

    def move(self, xz: np.ndarray, i: int) -> np.ndarray:
        """Ground points (..., 2) of seed ``i`` moved with it."""
        c, s = math.cos(self.rot_yaw[i]), math.sin(self.rot_yaw[i])
        d = xz - self.last_xz[i]
        # rotation about +y by yaw maps (x, z) -> (x cos + z sin, -x sin + z cos)
        return np.stack((d[..., 0] * c + d[..., 1] * s, -d[..., 0] * s + d[..., 1] * c), -1) + self.start[i]


def _path_trackers(paths: list[GroundPath], norm: Normalizer, steps: int) -> list[_PathTracker]:
    """One tracker per path, sampled far enough beyond its end for ``steps`` steps at (three times) the mean speed."""
    speed_guess = float(norm.root_mean[1])  # metres per network step
    return [_PathTracker(p, extra_m=steps * max(speed_guess, 0.1) * 3 + 10.0) for p in paths]


def _advance_root(xz: np.ndarray, world: np.ndarray, s_step: torch.Tensor, delta: torch.Tensor) -> np.ndarray:
    """Move ground points (N, 2) by the predicted step length along the travel direction: the root's facing
    (from world rotations (N, J, 4)) turned by the predicted delta."""
    travel = facing_yaw(world[:, 0]) + delta.numpy()
    return xz + s_step.numpy()[:, None] * np.stack((np.sin(travel), np.cos(travel)), -1)


def _predict_seed(net: LoadedGaitNet, seed: dict, emotions: np.ndarray) -> tuple[dict, torch.Tensor]:
    """Run the network (on its device) over the seed steps (the seed's emotion is the first step's): (prediction
    of the step after the seed, on the CPU; GRU state, on the network's device)."""
    norm, dev = net.normalizer, net.device
    N, L = seed["q"].shape[:2]
    em_seed = torch.as_tensor(emotions[:, :1], dtype=torch.float32).expand(N, L, NUM_EMOTIONS)
    inputs = (seed["q"], norm.aff(seed["aff"]), norm.step(seed["theta"], seed["omega"], seed["sbar"], seed["kappa"]),
              norm.root(seed["root"]), em_seed)
    out = net.model(*(x.to(dev) for x in inputs))
    return {k: v[:, -1].cpu() for k, v in out.items() if k != "hidden"}, out["hidden"]


def _predict_next(net: LoadedGaitNet, seed: dict, pred: dict, hidden: torch.Tensor, h: torch.Tensor,
                  step_in: torch.Tensor, emotion: torch.Tensor) -> tuple[dict, torch.Tensor]:
    """One network step fed with its previous prediction ``pred`` (root height deviation ``h``, step features
    ``step_in``; CPU tensors): (the next prediction on the CPU, GRU state on the network's device). The forward
    kinematics, affective features and network run on the network's device."""
    dev = net.device
    q = pred["q"].to(dev)
    pos = heading_frame_positions(q, (seed["mean_height"] + h.float()).to(dev), seed["offsets"].to(dev))
    out = net.model.step(q, net.normalizer.aff(affective_features(pos)), step_in.to(dev), pred["root"].to(dev),
                         emotion.to(dev), hidden)
    return {k: v.cpu() for k, v in out.items() if k != "hidden"}, out["hidden"]


def _guided(cond: dict, plain: dict, scale: float) -> dict:
    """Emotion guidance: the prediction conditioned on the requested emotion moved ``scale`` times further from
    the prediction conditioned on the emotion-neutral (uniform) vector, in every output (unnormalised rotations,
    then re-normalised; standardised root features and phase increment)."""
    out = {k: v + scale * (v - plain[k]) for k, v in cond.items() if k in ("q_raw", "root", "omega")}
    out["q"] = out["q_raw"] / out["q_raw"].norm(dim=-1, keepdim=True).clamp_min(1e-8)
    return out


def _rollout(net: LoadedGaitNet, seed: dict, emotions: np.ndarray, trackers: list[_PathTracker],
             placement: _Placement, lookahead_m: float, guidance: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The autoregressive rollout (section 5.4.1) after the seed, one step per emotion row.

    Each step turns the prediction into world rotations in the heading frame of the pure-pursuit direction,
    moves the root by the predicted step (its height mean + h), then advances the phase, s-bar and kappa
    and feeds the prediction back. Returns world rotations (N, steps, J, 4) and root positions (N, steps, 3).
    With ``guidance`` > 0 a second GRU state is run with the uniform emotion vector on the same (guided) inputs
    and each step's prediction is :func:`_guided`.
    """
    norm, (N, steps) = net.normalizer, emotions.shape[:2]
    net.model.eval()
    out_rot = np.zeros((N, steps, NUM_JOINTS, 4))
    out_root = np.zeros((N, steps, 3))
    with torch.no_grad():
        pred, hidden = _predict_seed(net, seed, emotions)
        if guidance:
            uniform = np.full_like(emotions, 1.0 / NUM_EMOTIONS)
            em_plain = torch.as_tensor(uniform[:, 0], dtype=torch.float32)
            plain, hidden_plain = _predict_seed(net, seed, uniform)
            pred = _guided(pred, plain, guidance)
        theta, sbar = seed["theta"][:, -1].double(), seed["sbar"][:, -1].double()
        ref_prev = torch.as_tensor(placement.rot_yaw) + seed["ref"][:, -1].double()
        xz = placement.start.copy()
        em_all = torch.as_tensor(emotions, dtype=torch.float32)
        for k in range(steps):
            root_raw = norm.root_inv(pred["root"]).double()
            h, s_step, delta = root_raw[:, 0], root_raw[:, 1].clamp_min(0.0), root_raw[:, 2]
            omega = norm.omega_inv(pred["omega"]).double().clamp(0.0, math.pi)
            ref = torch.tensor([t.pursuit_heading(xz[i], lookahead_m) for i, t in enumerate(trackers)],
                               dtype=torch.float64)
            world = world_rotations(pred["q"].double(), ref).numpy()
            xz = _advance_root(xz, world, s_step, delta)
            out_rot[:, k] = world
            out_root[:, k, 0], out_root[:, k, 2] = xz[:, 0], xz[:, 1]
            out_root[:, k, 1] = (seed["mean_height"].double() + h).numpy()
            if k == steps - 1:
                break
            theta = torch.remainder(theta + omega, 2 * math.pi)
            sbar_new = (1 - SBAR_ALPHA) * sbar + SBAR_ALPHA * s_step
            kappa = kappa_torch(sbar_new, ref, sbar, ref_prev)
            sbar, ref_prev = sbar_new, ref
            step_in = norm.step(theta.float(), omega.float(), sbar.float(), kappa.float())
            cond, hidden = _predict_next(net, seed, pred, hidden, h, step_in, em_all[:, k + 1])
            if guidance:
                plain, hidden_plain = _predict_next(net, seed, pred, hidden_plain, h, step_in, em_plain)
                cond = _guided(cond, plain, guidance)
            pred = cond
    return out_rot, out_root


def _with_seed(seed: dict, placement: _Placement, i: int, rot: np.ndarray, root: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """Agent ``i``'s generated rotations and root positions preceded by its (moved) seed steps."""
    seed_rot = world_rotations(seed["q"][i].double(), seed["ref"][i].double() + placement.rot_yaw[i]).numpy()
    seed_root = seed["root_pos"][i].double().numpy().copy()
    seed_root[:, [0, 2]] = placement.move(seed_root[:, [0, 2]], i)
    return np.concatenate((seed_rot, rot)), np.concatenate((seed_root, root))


def _metadata(net: LoadedGaitNet, emotions: np.ndarray, path: GroundPath, seed_motion: Motion) -> dict:
    """Metadata of one generated gait with per-step emotions (steps, 4)."""
    first, last = emotions[0], emotions[-1]
    real = is_real(net.training_data)
    credit = {"training_data_licence": "CC BY-NC 4.0",
              "training_data_citation": "Kobayashi et al. 2023, arXiv:2306.08861"} if real else {}
    seed_take = seed_motion.metadata.get("seed_take")
    return {
        "origin": "generated", "generator": "gait_net",
        "emotion": [round(float(v), 6) for v in first],
        "final_emotion": None if np.allclose(first, last, atol=1e-6) else [round(float(v), 6) for v in last],
        "trained_on": net.training_data.description,
        "synthetic": True,
        "path_kind": path.kind, "steps": len(emotions), "network_fps": net.fps,
        "seed_origin": seed_motion.metadata.get("origin", "unknown"),
        **({"seed_take": seed_take} if seed_take else {}),
        "weights": Path(net.path).name, "weights_name": net.info.get("weights_name", Path(net.path).stem),
        **credit,
    }


def generate_gaits(seeds, paths: list[GroundPath], emotions, steps: int = 200, fps_out: float = 30.0,
                   model: LoadedGaitNet | None = None, lookahead_m: float = 1.0, include_seed: bool = False,
                   rng_seed: int = 0, foot_cleanup: bool = True, device: str | torch.device | None = None,
                   emotion_guidance: float | None = None) -> list[Motion]:
    """Generate emotive gaits for N agents in one batch.

    Args:
        seeds: list of N seed gaits: a :class:`Motion` on the 21-joint skeleton with at least 18 network steps
            (69 frames at 30 fps, any frame rate is resampled), a ``WalkParams`` / params dict (a procedural
            seed walk is made), or None (procedural seed from
            ``generation.procedural.emotion.gait_params_for_emotion``).
        paths: N desired ground paths; the seed is moved and turned rigidly so that its last frame stands at
            the path start facing the path.
        emotions: (N, 4) constant emotion per agent, or (N, steps, 4) per step (e.g. from
            :func:`emotion_transition`); l1-normalised here.
        steps: number of network steps to generate (1/7.5 s each with the default frame step of 4).
        fps_out: frame rate of the returned motions (cubic splines through the network's poses,
            :meth:`Motion.resample` with ``smooth``).
        model: a :class:`LoadedGaitNet`; default :func:`load_default_model`.
        lookahead_m: pure-pursuit look-ahead along the path, metres.
        include_seed: prepend the (moved) seed steps to the output.
        rng_seed: seeds the procedural seed walks (their parameters and phase).
        foot_cleanup: plant the feet after generation (:func:`generation.core.foot_contact.plant_feet`: contacts
            detected in the output, the planted foot locked, legs solved with two-bone IK, no floor
            penetration); False returns the network's raw output (resampled). With real-trained weights the
            pelvis is also lowered where a planted ankle is out of the leg's reach (``lower_pelvis``): their raw
            stance knees are already the actors' (18-25 degrees), and locking the feet without it pulled the
            stance leg straight (angry and neutral 9 degrees, actors 14-30).
        device: where the network runs: None keeps the model where it is (the default model loads on the CPU),
            or "auto" / "cpu" / "cuda" / "cuda:N" (:func:`generation.core.device.resolve_device`; the model is
            copied there, the caller's is not moved). Path steering, resampling and foot planting stay on the CPU.
        emotion_guidance: scale w of emotion guidance (:func:`_guided`): each step's prediction p(m) becomes
            p(m) + w (p(m) - p(uniform)), so the requested emotion counts more against the seed's style; 0 is the
            plain network, None the scale stored with the weights (:attr:`LoadedGaitNet.emotion_guidance`).
            It doubles the network work per step.

    Returns:
        N Motions on each seed's skeleton, metadata {"origin": "generated", "generator": "gait_net", "emotion",
        "final_emotion" (None unless the emotion changes), "trained_on", "path_kind", "steps", "network_fps",
        "foot_cleanup" (when applied)}.
    """
    net = model if model is not None else load_default_model()
    if device is not None:
        net = net.on(device)
    seeds, emotions = _check_inputs(seeds, paths, emotions, steps)
    real_weights = is_real(net.training_data)
    seed_motions, seed = _seed_batch(seeds, emotions, net.config.data, np.random.default_rng(rng_seed),
                                     real_weights)
    placement = _Placement.onto_paths(paths, seed)
    guidance = net.emotion_guidance if emotion_guidance is None else float(emotion_guidance)
    if guidance < 0 or not math.isfinite(guidance):
        raise ValueError(f"emotion_guidance must be a finite number >= 0, got {guidance}")
    rot, root = _rollout(net, seed, emotions, _path_trackers(paths, net.normalizer, steps), placement, lookahead_m,
                         guidance)
    motions = []
    for i, path in enumerate(paths):
        r, rt = _with_seed(seed, placement, i, rot[i], root[i]) if include_seed else (rot[i], root[i])
        m = Motion(seed_motions[i].skeleton, wrap_quaternions(r), rt, net.fps,
                   _metadata(net, emotions[i], path, seed_motions[i]))
        m = m.resample(fps_out, smooth=True)
        motions.append(plant_feet(m, lower_pelvis=real_weights) if foot_cleanup else m)
    return motions


def wrap_quaternions(q: np.ndarray) -> np.ndarray:
    """Unit-normalise and make sign-continuous along time (T, J, 4)."""
    return np_qfix(np_qnormalize(q))


__all__ = ["LoadedGaitNet", "distance_to_path", "emotion_transition", "generate_gaits",
           "load_default_model", "load_model", "normalize_emotion", "wrap"]
