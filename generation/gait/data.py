"""Training data for the gait network: network-rate sequences, control features and normalisation.

A corpus sequence (240 frames at 30 fps) is sampled every 4th frame (T = 60 steps at 7.5 fps, seed 000
section 5.1). Per step we compute, on the ground plane (x, z; y-up):

- ``ref``: the heading of the desired trajectory, the direction of the root's ground track from step
  t - k to t + k (k = 4 steps, one stride), i.e. a low-pass tangent of the root trajectory; at generation
  time it is the direction towards a look-ahead point on the desired path.
- ``q``: local joint rotations (T, J, 4); the root's rotation is expressed relative to the yaw ``ref``.
- root joint features (section 3.2.4): h (root height minus its mean), s (ground distance since the last
  step, metres per step), delta (signed angle from the root's facing direction to its travel direction
  x_t - x_{t-1}; the paper's unsigned delta is its absolute value; the sign lets generation place the root).
- stepping features: theta (stepping phase: 0 at left foot contact, pi at right foot contact, linear in
  between; from ``generation.core.features``), omega (theta_t - theta_{t-1} modulo 2 pi), s-bar (causal
  exponential low-pass of s, so that generation can compute it the same way), kappa (norm of the change of
  the low-pass tangent s-bar * (sin ref, cos ref) between steps: the curvature term of section 3.2.4 on
  the smoothed trajectory).
- the 18 pose affective features a_t (``generation.core.features.gait_affective_features``).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from generation.core.digest import file_sha256
from generation.core.features import gait_affective_features, movement_features
from generation.core.kinematics import forward_kinematics, np_forward_kinematics
from generation.core.quaternion import np_qfix, np_qmul, np_qrot, qmul
from generation.core.rigging import yaw_quat
from generation.core.skeleton import GAIT_PARENTS, gait_skeleton
from generation.procedural.corpus import GaitCorpus, build_gait_corpus

from .weights import TrainingData

DEFAULT_CORPUS = Path("var/corpus/gait_corpus_synthetic.npz")
SBAR_ALPHA = 0.3      # low-pass coefficient of s-bar per network step
REF_HALF_WINDOW = 4   # steps each side for the trajectory tangent


# ---- small geometry helpers (numpy, float64) ---------------------------------------------------
def wrap(a):
    """Wrap radians to (-pi, pi]."""
    return np.remainder(np.asarray(a) + np.pi, 2 * np.pi) - np.pi


def facing_yaw(root_rot: np.ndarray) -> np.ndarray:
    """(...,) heading of the root's +z axis projected on the ground, from (..., 4) quaternions."""
    f = np_qrot(root_rot, np.tile(np.array([0.0, 0.0, 1.0]), root_rot.shape[:-1] + (1,)))
    return np.arctan2(f[..., 0], f[..., 2])


def trajectory_heading(xz: np.ndarray, k: int = REF_HALF_WINDOW) -> np.ndarray:
    """(..., T) heading of the low-pass tangent of a ground track (..., T, 2) (x, z)."""
    T = xz.shape[-2]
    idx = np.arange(T)
    d = xz[..., np.minimum(idx + k, T - 1), :] - xz[..., np.maximum(idx - k, 0), :]
    return np.arctan2(d[..., 0], d[..., 1])


def lowpass(s: np.ndarray, alpha: float = SBAR_ALPHA) -> np.ndarray:
    """Causal exponential low-pass along the last axis, starting at the first value."""
    out = np.empty_like(s)
    out[..., 0] = s[..., 0]
    for t in range(1, s.shape[-1]):
        out[..., t] = (1 - alpha) * out[..., t - 1] + alpha * s[..., t]
    return out


def kappa_from(sbar: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """(..., T) norm of the change of the low-pass tangent sbar * (sin ref, cos ref); 0 at t = 0."""
    u = sbar[..., None] * np.stack((np.sin(ref), np.cos(ref)), axis=-1)
    k = np.zeros_like(sbar)
    k[..., 1:] = np.linalg.norm(np.diff(u, axis=-2), axis=-1)
    return k


def kappa_torch(sbar: torch.Tensor, ref: torch.Tensor, sbar_prev: torch.Tensor, ref_prev: torch.Tensor
                ) -> torch.Tensor:
    """One step of :func:`kappa_from` in torch: norm of the change of the low-pass tangent from
    ``sbar_prev * (sin ref_prev, cos ref_prev)`` to ``sbar * (sin ref, cos ref)`` (training and generation)."""
    u = torch.stack((sbar * torch.sin(ref), sbar * torch.cos(ref)), -1)
    u0 = torch.stack((sbar_prev * torch.sin(ref_prev), sbar_prev * torch.cos(ref_prev)), -1)
    return (u - u0).norm(dim=-1)


def root_features(root_pos: np.ndarray, root_rot: np.ndarray) -> dict:
    """Root joint features of a (..., T, 3) root track and (..., T, 4) root rotations (per network step).

    Returns dict of (..., T) arrays: h, s, delta, ref, mean_height.
    """
    xz = root_pos[..., [0, 2]]
    tau = np.diff(xz, axis=-2)
    tau = np.concatenate((tau[..., :1, :], tau), axis=-2)          # backward difference; t=0 copies t=1
    s = np.linalg.norm(tau, axis=-1)
    travel = np.arctan2(tau[..., 0], tau[..., 1])
    delta = np.where(s > 1e-4, wrap(travel - facing_yaw(root_rot)), 0.0)
    mean_h = root_pos[..., 1].mean(-1)
    return {"h": root_pos[..., 1] - mean_h[..., None], "s": s, "delta": delta,
            "ref": trajectory_heading(xz), "mean_height": mean_h}


def to_heading_frame(rotations: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Replace the root rotation (joint 0) of (..., T, J, 4) by its rotation relative to yaw ``ref`` (..., T)."""
    out = rotations.copy()
    out[..., 0, :] = np_qmul(yaw_quat(-ref), rotations[..., 0, :])
    return out


def from_heading_frame(rotations: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Inverse of :func:`to_heading_frame`."""
    out = np.array(rotations, dtype=np.float64, copy=True)
    out[..., 0, :] = np_qmul(yaw_quat(ref), out[..., 0, :])
    return out


# ---- torch helpers used in training and generation ---------------------------------------------
def heading_frame_positions(q: torch.Tensor, root_y: torch.Tensor, offsets: torch.Tensor) -> torch.Tensor:
    """Joint positions (..., J, 3) of rotations (..., J, 4) with the root at (0, root_y, 0), heading frame.

    ``offsets`` is (..., J, 3) (per-sample skeletons) or (J, 3).
    """
    root = torch.zeros(q.shape[:-2] + (3,), dtype=q.dtype, device=q.device)
    root = root + torch.nn.functional.pad(root_y[..., None], (1, 1))
    return forward_kinematics(q, root, offsets, GAIT_PARENTS)


def affective_features(positions: torch.Tensor) -> torch.Tensor:
    """The 18 pose affective features (..., 18) of positions (..., 21, 3) (``generation.core.features``)."""
    return gait_affective_features(positions)


def step_phase(positions_30: np.ndarray, fps: float, skeleton) -> np.ndarray:
    """Stepping phase theta (..., T) in [0, 2 pi) of (..., T, J, 3) positions (``generation.core.features``)."""
    return np.remainder(np.asarray(movement_features(positions_30, fps, skeleton)["step_phase"]), 2 * np.pi)


# ---- normalisation -----------------------------------------------------------------------------
@dataclass
class Normalizer:
    """Per-feature mean and std (training split) for affective, root and step features.

    ``aff_style_std`` (18,) is the spread across training walks of each walk's time-mean affective feature (the
    scale on which an observer of whole walks compares them; some features, such as the shoulder / lower-back area
    ratio, barely vary within or between walks, so their per-frame std is floored for the inputs and L_aff, but a
    0.1 % offset of their mean is several walk-to-walk standard deviations). None in files saved before it existed.
    """

    aff_mean: np.ndarray   # (18,)
    aff_std: np.ndarray
    root_mean: np.ndarray  # (3,) h, s, delta
    root_std: np.ndarray
    step_mean: np.ndarray  # (3,) omega, s-bar, kappa
    step_std: np.ndarray
    aff_style_std: np.ndarray | None = None

    CLIP = 6.0
    AFF_STD_FLOOR = 0.02  # radians / ratio units: nearly constant features must not dominate L_aff
    STYLE_STD_FLOOR = 1e-4   # floor of aff_style_std (the corpus's smallest is 3.3e-4, an area ratio)
    MAX_STYLE_SCALE = 100.0  # cap of style_scale (the corpus's largest is 61): a few walks must not explode it

    @classmethod
    def fit(cls, aff: np.ndarray, root: np.ndarray, step: np.ndarray) -> Normalizer:
        """Statistics of (N, T, F) arrays (or (M, F) rows; then without ``aff_style_std``)."""
        def ms(x, floor=1e-6):
            x = x.reshape(-1, x.shape[-1])
            return x.mean(0), np.maximum(x.std(0), floor)
        (am, asd), (rm, rsd), (sm, ssd) = ms(aff, cls.AFF_STD_FLOOR), ms(root), ms(step)
        style = np.maximum(aff.mean(-2).std(0), cls.STYLE_STD_FLOOR) if aff.ndim == 3 else None
        return cls(am, asd, rm, rsd, sm, ssd, style)

    def to_dict(self) -> dict:
        names = ("aff_mean", "aff_std", "root_mean", "root_std", "step_mean", "step_std", "aff_style_std")
        return {k: np.asarray(getattr(self, k)).tolist() for k in names if getattr(self, k) is not None}

    @classmethod
    def from_dict(cls, d: dict) -> Normalizer:
        return cls(**{k: np.asarray(v, dtype=np.float64) for k, v in d.items()})

    def style_scale(self, ref: torch.Tensor) -> torch.Tensor:
        """(18,) factors turning standardised affective features (:meth:`aff`) into units of ``aff_style_std``
        (ones when it is unknown)."""
        if self.aff_style_std is None:
            return torch.ones(len(self.aff_std), dtype=ref.dtype, device=ref.device)
        return (self._t("aff_std", ref) / self._t("aff_style_std", ref)).clamp(max=self.MAX_STYLE_SCALE)

    def _t(self, name, ref: torch.Tensor) -> torch.Tensor:
        return torch.as_tensor(getattr(self, name), dtype=ref.dtype, device=ref.device)

    def aff(self, a: torch.Tensor) -> torch.Tensor:
        # Area ratios explode when the feet pass each other; clip after standardising.
        return ((a - self._t("aff_mean", a)) / self._t("aff_std", a)).clamp(-self.CLIP, self.CLIP)

    def root(self, r: torch.Tensor) -> torch.Tensor:
        return (r - self._t("root_mean", r)) / self._t("root_std", r)

    def root_inv(self, r: torch.Tensor) -> torch.Tensor:
        return r * self._t("root_std", r) + self._t("root_mean", r)

    def step(self, theta: torch.Tensor, omega: torch.Tensor, sbar: torch.Tensor, kappa: torch.Tensor):
        """(..., 5) [sin theta, cos theta, omega, s-bar, kappa] with the last three standardised."""
        raw = torch.stack((omega, sbar, kappa), dim=-1)
        z = (raw - self._t("step_mean", raw)) / self._t("step_std", raw)
        return torch.cat((torch.sin(theta)[..., None], torch.cos(theta)[..., None], z), dim=-1)

    def omega_inv(self, z: torch.Tensor) -> torch.Tensor:
        return z * float(self.step_std[0]) + float(self.step_mean[0])

    def omega(self, w: torch.Tensor) -> torch.Tensor:
        return (w - float(self.step_mean[0])) / float(self.step_std[0])


# ---- the prepared data set ---------------------------------------------------------------------
@dataclass
class GaitSequences:
    """Network-rate training sequences (float32 tensors), N sequences of T steps.

    Attributes:
        q: (N, T, J, 4) rotations, root relative to the trajectory heading ``ref``.
        root: (N, T, 3) raw [h, s, delta] (metres per step, radians).
        theta, omega, sbar, kappa, ref: (N, T).
        aff: (N, T, 18) raw affective features.
        emotion: (N, 4).
        offsets: (N, J, 3) per-sequence skeleton offsets (metres).
        mean_height: (N,) mean root height (metres).
        root_pos: (N, T, 3) world root positions, rotations_world: (N, T, J, 4) world-frame rotations.
        split: (N,) array of "train" / "val" / "test".
        fps: network rate (7.5 for a 30 fps corpus sampled every 4th frame).
        base_index: (N,) corpus sequence each row comes from; offset: (N,) first frame of the subsampling
            (rows with offsets 1..3 are the same walk sampled from a later frame: data augmentation).
        training_data: what the sequences are (:class:`generation.gait.weights.TrainingData`; it goes into the
            weights file trained on them); None for sequences that are not training data (seed walks).
        clip_names: for real capture, the clip of each ``base_index``.
    """

    q: torch.Tensor
    root: torch.Tensor
    theta: torch.Tensor
    omega: torch.Tensor
    sbar: torch.Tensor
    kappa: torch.Tensor
    ref: torch.Tensor
    aff: torch.Tensor
    emotion: torch.Tensor
    offsets: torch.Tensor
    mean_height: torch.Tensor
    root_pos: torch.Tensor
    rotations_world: torch.Tensor
    split: np.ndarray
    fps: float
    base_index: np.ndarray | None = None
    offset: np.ndarray | None = None
    training_data: TrainingData | None = None
    clip_names: tuple[str, ...] = ()

    def __post_init__(self):
        n = self.q.shape[0]
        if self.base_index is None:
            self.base_index = np.arange(n)
        if self.offset is None:
            self.offset = np.zeros(n, dtype=int)

    def __len__(self) -> int:
        return self.q.shape[0]

    def subset(self, which: str | np.ndarray) -> GaitSequences:
        """Sequences of a split name or a boolean/int index array."""
        idx = np.flatnonzero(self.split == which) if isinstance(which, str) else np.asarray(which)
        if idx.dtype == bool:
            idx = np.flatnonzero(idx)
        it = torch.as_tensor(idx, dtype=torch.long)
        kw = {}
        for k in self.__dataclass_fields__:
            v = getattr(self, k)
            kw[k] = v[it] if isinstance(v, torch.Tensor) else (v[idx] if isinstance(v, np.ndarray) else v)
        return GaitSequences(**kw)

    def to(self, device: torch.device | str) -> GaitSequences:
        """A copy with every tensor on ``device`` (training moves the whole, small, training set once, so that
        batches are gathered on the device itself); the numpy fields stay on the host."""
        kw = {k: (v.to(device) if isinstance(v, torch.Tensor) else v)
              for k, v in ((k, getattr(self, k)) for k in self.__dataclass_fields__)}
        return GaitSequences(**kw)

    @property
    def device(self) -> torch.device:
        return self.q.device

    def batch(self, idx) -> dict:
        """Dict of tensors for sequences ``idx`` (on the device the sequences live on)."""
        it = torch.as_tensor(np.asarray(idx), dtype=torch.long, device=self.q.device)
        return {k: getattr(self, k)[it] for k in ("q", "root", "theta", "omega", "sbar", "kappa", "ref", "aff",
                                                  "emotion", "offsets", "mean_height", "root_pos")}


def prepare_sequences(rotations: np.ndarray, root_positions: np.ndarray, emotion: np.ndarray, split: np.ndarray,
                      heights: np.ndarray, builds: np.ndarray, fps: float = 30.0, frame_step: int = 4,
                      seq_len: int = 60, skeletons: list | None = None, offsets: tuple[int, ...] = (0,),
                      training_data: TrainingData | None = None) -> GaitSequences:
    """Turn corpus arrays into network sequences.

    Args:
        rotations: (N, F, 21, 4) local rotations at ``fps`` (F >= frame_step * seq_len frames used).
        root_positions: (N, F, 3) metres.
        emotion: (N, 4) soft labels; split: (N,) strings; heights: (N,) metres; builds: (N,) "male"/"female".
        skeletons: optional list of N gait skeletons used instead of ``gait_skeleton(height, build)``.
        offsets: first frames of the subsampling; each offset adds N rows (augmentation), in offset-major order.
        training_data: what the arrays are (:attr:`GaitSequences.training_data`).
    """
    rotations = np.asarray(rotations, dtype=np.float64)
    root_positions = np.asarray(root_positions, dtype=np.float64)
    N, F = rotations.shape[:2]
    need = frame_step * (seq_len - 1) + 1
    offsets = tuple(int(o) for o in offsets)
    if rotations.ndim != 4 or rotations.shape[2:] != (21, 4):
        raise ValueError(f"rotations must be (N, F, 21, 4), got {rotations.shape}")
    if F < need + max(offsets):
        raise ValueError(f"sequences have {F} frames; {need + max(offsets)} are needed for {seq_len} steps every "
                         f"{frame_step} from offset {max(offsets)}")
    if root_positions.shape != (N, F, 3):
        raise ValueError(f"root_positions must be ({N}, {F}, 3), got {root_positions.shape}")
    emotion = np.asarray(emotion, dtype=np.float64)
    if emotion.shape != (N, 4):
        raise ValueError(f"emotion must be ({N}, 4), got {emotion.shape}")
    if skeletons is None:
        skeletons = [gait_skeleton(float(h), str(b)) for h, b in zip(heights, builds)]
    bone_offsets = np.stack([sk.offsets for sk in skeletons])
    # Stepping phase at the capture rate (contacts are better resolved there), then subsampled.
    theta_full = np.zeros((N, F))
    for i, sk in enumerate(skeletons):
        pos = np_forward_kinematics(rotations[i], root_positions[i], sk)
        theta_full[i] = step_phase(pos, fps, sk)
    parts = []
    for o in offsets:
        sl = slice(o, o + need, frame_step)
        parts.append(_network_rate(rotations[:, sl], root_positions[:, sl], theta_full[:, sl], bone_offsets))
    K = len(offsets)
    f32 = lambda a: torch.as_tensor(np.asarray(a), dtype=torch.float32)  # noqa: E731
    cat = {k: torch.cat([f32(p[k]) for p in parts]) if k != "aff" else torch.cat([p[k] for p in parts]).float()
           for k in parts[0]}
    return GaitSequences(
        q=cat["q"], root=cat["root"], theta=cat["theta"], omega=cat["omega"], sbar=cat["sbar"], kappa=cat["kappa"],
        ref=cat["ref"], aff=cat["aff"], emotion=f32(np.tile(emotion, (K, 1))), offsets=f32(np.tile(bone_offsets,
                                                                                                  (K, 1, 1))),
        mean_height=cat["mean_height"], root_pos=cat["root_pos"], rotations_world=cat["rotations_world"],
        split=np.tile(np.asarray(split).astype(str), K), fps=fps / frame_step,
        base_index=np.tile(np.arange(N), K), offset=np.repeat(np.asarray(offsets, dtype=int), N),
        training_data=training_data)


def _network_rate(rot: np.ndarray, rp: np.ndarray, theta: np.ndarray, bone_offsets: np.ndarray) -> dict:
    """Features of subsampled sequences: rotations (N, T, J, 4), root (N, T, 3), phase (N, T)."""
    rot = np_qfix(rot)
    rf = root_features(rp, rot[..., 0, :])
    omega = np.remainder(np.diff(theta, axis=-1, prepend=theta[:, :1]), 2 * np.pi)
    omega[:, 0] = omega[:, 1]
    sbar = lowpass(rf["s"])
    kappa = kappa_from(sbar, rf["ref"])
    q = np_qfix(to_heading_frame(rot, rf["ref"]))
    q_t = torch.as_tensor(q, dtype=torch.float32)
    with torch.no_grad():
        pos = heading_frame_positions(q_t, torch.as_tensor(rf["h"] + rf["mean_height"][:, None], dtype=torch.float32),
                                      torch.as_tensor(bone_offsets, dtype=torch.float32)[:, None])
        aff = affective_features(pos)
    return {"q": q, "root": np.stack((rf["h"], rf["s"], rf["delta"]), -1), "theta": theta, "omega": omega,
            "sbar": sbar, "kappa": kappa, "ref": rf["ref"], "aff": aff, "mean_height": rf["mean_height"],
            "root_pos": rp, "rotations_world": rot}


def load_corpus_sequences(path: str | Path | None = None, num_sequences: int = 1000, seed: int = 0,
                          frame_step: int = 4, seq_len: int = 60, offsets: tuple[int, ...] = (0,)) -> GaitSequences:
    """Load (or build and save, when missing) the synthetic gait corpus and prepare network sequences
    (one row per corpus sequence and subsampling offset)."""
    path = Path(path) if path is not None else DEFAULT_CORPUS
    if path.exists():
        corpus = GaitCorpus.load(path)
    else:
        corpus = build_gait_corpus(num_sequences, seed)
        path.parent.mkdir(parents=True, exist_ok=True)
        corpus.save(path)
    training = TrainingData.procedural({"path": str(path), "sha256": file_sha256(path)})
    return prepare_sequences(corpus.rotations, corpus.root_positions, corpus.emotion, corpus.split, corpus.height,
                             corpus.build, fps=corpus.fps, frame_step=frame_step, seq_len=seq_len, offsets=offsets,
                             training_data=training)


def quat_torch_yaw(yaw: torch.Tensor) -> torch.Tensor:
    """(..., 4) torch rotation by yaw about +y."""
    z = torch.zeros_like(yaw)
    return torch.stack((torch.cos(yaw / 2), z, torch.sin(yaw / 2), z), dim=-1)


def world_rotations(q_heading: torch.Tensor, ref: torch.Tensor) -> torch.Tensor:
    """Rotations (..., J, 4) with the root put back from the heading frame ``ref`` (...) to the world."""
    root = qmul(quat_torch_yaw(ref), q_heading[..., 0, :])
    return torch.cat((root[..., None, :], q_heading[..., 1:, :]), dim=-2)
