"""Configuration of the affect-based autoregression gait network (seed 000, sections 4-5).

As on the gesture side, the settings are split by what they configure:

- :class:`GaitModelConfig`: the network's architecture (what the weights' shapes depend on);
- :class:`GaitDataConfig`: how corpus walks become network sequences (sequence length, sampling, prefix),
  which generation needs as well (network rate, seed length);
- :class:`GaitTrainConfig`: the optimiser, curriculum and augmentation of a training run;
- :class:`GaitLossWeights`: the weights of the loss terms of eq. 13 and how the terms are measured.

:class:`GaitNetConfig` holds one of each. The default is sized to train in about 10-20 minutes on one free CPU thread;
``GaitNetConfig.paper()`` (``GaitModelConfig.paper()`` for the network alone) has the paper's released sizes,
so both are the same code path.

Weights files store ``GaitNetConfig.to_dict()``: {"model": {...}, "data": {...}, "train": {...}, "loss": {...},
"notes": {...}} (format ``gait_net/2``), every field written out; :meth:`GaitNetConfig.from_dict` reads that form
only. A field added later takes its default in files written before it, so a new field whose default changes
what a stored run means must come with the shipped weights re-saved. The flat names of :data:`FLAT_NAMES` serve
``--set FIELD=JSON`` and the keyword overrides of :meth:`GaitNetConfig.paper` / :meth:`GaitNetConfig.tiny`.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields, replace

from protocol.vocabulary import GAIT_EMOTIONS

NUM_JOINTS = 21                    # gait skeleton of seed 000 (Fig. 2)
NUM_EMOTIONS = len(GAIT_EMOTIONS)  # components of the emotion vector m (section 3.2.2)
NUM_AFFECTIVE = 18                 # 11 angles, 4 distance ratios, 3 area ratios (section 3.2.3)
NUM_STEP_FEATURES = 5              # sin theta, cos theta, omega, s-bar, kappa (section 4.1)
NUM_ROOT_FEATURES = 3              # h, s, delta (section 4.1, eq. 3)


def _from_dict(cls, d: dict, what: str):
    """``cls(**d)`` with list values of tuple fields made tuples; unknown keys raise a ValueError naming them."""
    names = {f.name: f for f in fields(cls)}
    unknown = sorted(set(d) - set(names))
    if unknown:
        raise ValueError(f"unknown {what} fields {unknown}")
    d = {k: tuple(v) if isinstance(getattr(cls(), k), tuple) else v for k, v in d.items()}
    return cls(**d)


def _to_dict(obj) -> dict:
    """``asdict`` with tuples written as lists (JSON-like, as stored in checkpoints)."""
    return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(obj).items()}


@dataclass
class GaitModelConfig:
    """The network's architecture (names follow section 4 of seed 000).

    enc1_sizes: hidden sizes of FC_enc1 on [affective features a_t, emotion m]; the last is H1.
    enc2_sizes: hidden sizes of FC_enc2 on [sin theta, cos theta, omega, s-bar, kappa, m]; the last is H2.
    gru_hidden: H3, hidden units of GRU_versors; gru_layers: its depth.
    root_hidden: H4, units of the FC_root layer on [h, s, delta; gamma].
    versor_hidden: hidden layer of the 2-layer FC_versors head.
    residual: the versor head predicts a change added to the current rotations before normalising
        (QuaterNet-style); False predicts absolute rotations.
    use_affective: False gives the ablation without affective inputs (FC_enc1) and without L_aff (seed 000 5.6).
    emotion_skip: the emotion m also enters GRU_versors and FC_versors directly at every step (not only
        through the 8-unit encoders), so the label can steer the pose; False is the paper's wiring.
    num_joints: J, joints of the gait skeleton; num_emotions: C, components of m (``GAIT_EMOTIONS``).
    """

    enc1_sizes: tuple[int, ...] = (16, 16, 8)
    enc2_sizes: tuple[int, ...] = (16, 16, 8)
    gru_hidden: int = 256
    gru_layers: int = 2
    root_hidden: int = 32
    versor_hidden: int = 128
    residual: bool = True
    use_affective: bool = True
    emotion_skip: bool = True
    num_joints: int = NUM_JOINTS
    num_emotions: int = NUM_EMOTIONS

    @property
    def h1(self) -> int:
        """Width of FC_enc1's output (0 without the affective branch)."""
        return self.enc1_sizes[-1] if self.use_affective else 0

    @property
    def h2(self) -> int:
        """Width of FC_enc2's output."""
        return self.enc2_sizes[-1]

    @classmethod
    def paper(cls, **overrides) -> GaitModelConfig:
        """The released model's sizes (REFERENCE.md section 1): 2-layer GRU with 1024 units, FC 16-16-8,
        versor head 1024-128-(J-1)*4; about ten million parameters."""
        base = dict(enc1_sizes=(16, 16, 8), enc2_sizes=(16, 16, 8), gru_hidden=1024, gru_layers=2,
                    root_hidden=32, versor_hidden=128)
        base.update(overrides)
        return cls(**base)

    @classmethod
    def tiny(cls, **overrides) -> GaitModelConfig:
        """A very small network for tests."""
        base = dict(enc1_sizes=(8, 8), enc2_sizes=(8, 8), gru_hidden=32, gru_layers=1, root_hidden=8,
                    versor_hidden=32)
        base.update(overrides)
        return cls(**base)

    def to_dict(self) -> dict:
        return _to_dict(self)

    @classmethod
    def from_dict(cls, d: dict) -> GaitModelConfig:
        return _from_dict(cls, d, "GaitModelConfig")


@dataclass
class GaitDataConfig:
    """Network sequences (section 5.1); generation uses the same rate and prefix.

    seq_len: T = 60 network steps per training sequence.
    frame_step: every ``frame_step``-th frame of the 30 fps corpus is a network step (7.5 steps per second).
    prefix_frac: 0.3, the fraction of each sequence always given as ground truth (18 of 60 steps); a seed gait
        for generation needs at least that many steps.
    """

    seq_len: int = 60
    frame_step: int = 4
    prefix_frac: float = 0.3

    @property
    def prefix_len(self) -> int:
        """Number of ground-truth steps given before prediction (18 for T = 60)."""
        return int(round(self.prefix_frac * self.seq_len))

    def to_dict(self) -> dict:
        return _to_dict(self)

    @classmethod
    def from_dict(cls, d: dict) -> GaitDataConfig:
        return _from_dict(cls, d, "GaitDataConfig")


@dataclass
class GaitTrainConfig:
    """A training run (section 5.3).

    batch_size, epochs: sequences per batch and passes over the training walks.
    lr, lr_decay: Adam 1e-3 decayed by 0.999 per epoch.
    tf_decay: the teacher-forcing ratio decays as tf_decay ** epoch. The paper uses 0.995 over 500 epochs (final
        ratio 0.08); the default run has 28 epochs (the ~20 minute budget on a shared CPU), so 0.91 gives about the
        same final ratio (0.91 ** 27 = 0.08).
    grad_clip: maximum gradient norm.
    splice_frac: fraction of training sequences whose ground-truth prefix is taken from another walk of a different
        dominant emotion (phase-aligned); the emotion input switches from that walk's label to the sequence's own
        label at the splice. Every corpus walk has one emotion throughout, so without this the motion history
        predicts the style and the network learns to ignore m (see train.splice_histories).
    tf_start: the teacher-forcing ratio of the first epoch (ratio tf_start * tf_decay ** epoch); below 1 for
        fine-tuning a trained network (``--init``), which starts where a full schedule would end.
    extra_steps: after the last ground-truth step, the rollout keeps predicting this many steps free-running
        (inputs from its own predictions, the path heading and emotion of the last step); they have no per-step
        target and enter only the style term (``GaitLossWeights.style``), which asks them to keep the walk's style
        statistics. This trains the long rollouts of generation (200+ steps) against drifting to an average gait.
    uniform_label_frac: fraction of training sequences whose emotion input is replaced by the uniform vector
        (1/C each) at every step, as in classifier-free guidance training: the uniform vector then means "no
        emotion asked, continue the history", the reference that emotion guidance at generation extrapolates from
        (``generate_gaits(emotion_guidance=...)``). 0 (the default) leaves every label as it is.
    seed: seeds torch and numpy (runs are repeatable).
    """

    batch_size: int = 64
    epochs: int = 28
    lr: float = 1e-3
    lr_decay: float = 0.999
    tf_decay: float = 0.91
    grad_clip: float = 1.0
    splice_frac: float = 0.3
    extra_steps: int = 30
    tf_start: float = 1.0
    uniform_label_frac: float = 0.0
    seed: int = 0

    def to_dict(self) -> dict:
        return _to_dict(self)

    @classmethod
    def from_dict(cls, d: dict) -> GaitTrainConfig:
        return _from_dict(cls, d, "GaitTrainConfig")


@dataclass
class GaitLossWeights:
    """Weights of the loss terms of eq. 13 (1.0 in the paper) and how the terms are measured (losses.py).

    motion: L_motion (eq. 8, Euler-angle differences); versor: its unit-norm term.
    pose: L_pose (eq. 9); aff: L_aff (eq. 10; only with ``GaitModelConfig.use_affective``); root: L_root (eq. 11);
    fctc: L_fctc (eq. 12, foot contact); phase: the step-phase head (an addition of this implementation).
    style: L_style (an addition): the time mean and spread of the affective features and the motion amplitude of
        the predicted window and of the free-running continuation match the ground truth's
        (``losses.style_loss``; 0 leaves it out, as in the paper).
    bounce: L_bounce (an addition, default off): the pelvis bounce (standard deviation of the root height over the
        window) of the predicted window and of the free-running continuation matches the ground truth's
        (``losses.bounce_loss``); root-relative style statistics do not see it.
    class_style: L_class (an addition, default off): the batch's per-emotion mean offset of the walks' time-mean
        affective features from the ground truth's, in walk-to-walk units (``losses.class_style_loss``). The
        per-walk style term weighs a shift shared by every walk of an emotion no more than walk-level noise,
        yet such a shift is what moves a whole class across an observer's boundary.
    pos_scale_m: positions in the pose and foot losses are measured in units of this many metres.
    euler_order: axis order of the Euler angles compared by L_motion.
    """

    motion: float = 1.0
    versor: float = 1.0
    pose: float = 1.0
    aff: float = 1.0
    root: float = 1.0
    fctc: float = 1.0
    phase: float = 1.0
    style: float = 1.0
    class_style: float = 0.0
    bounce: float = 0.0
    pos_scale_m: float = 0.1
    euler_order: str = "zyx"

    def __post_init__(self):
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "euler_order":
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                raise ValueError(f"loss weight {f.name} must be a finite number >= 0, got {v!r}")
        if self.pos_scale_m <= 0:
            raise ValueError(f"loss pos_scale_m must be > 0 metres, got {self.pos_scale_m!r}")

    def to_dict(self) -> dict:
        return _to_dict(self)

    @classmethod
    def from_dict(cls, d: dict) -> GaitLossWeights:
        return _from_dict(cls, d, "GaitLossWeights")


SECTIONS = {"model": GaitModelConfig, "data": GaitDataConfig, "train": GaitTrainConfig, "loss": GaitLossWeights}
"""GaitNetConfig attribute -> its dataclass."""

FLAT_NAMES: dict[str, tuple[str, str]] = {
    **{name: ("model", name) for name in ("enc1_sizes", "enc2_sizes", "gru_hidden", "gru_layers", "root_hidden",
                                          "versor_hidden", "residual", "use_affective", "emotion_skip",
                                          "num_joints", "num_emotions")},
    **{name: ("data", name) for name in ("seq_len", "frame_step", "prefix_frac")},
    **{name: ("train", name) for name in ("batch_size", "epochs", "lr", "lr_decay", "tf_decay", "grad_clip",
                                          "splice_frac", "extra_steps", "tf_start", "uniform_label_frac",
                                          "seed")},
    **{f"lambda_{name}": ("loss", name) for name in ("motion", "versor", "pose", "aff", "root", "fctc", "phase",
                                                                  "style", "class_style", "bounce")},
    "pos_scale_m": ("loss", "pos_scale_m"),
    "euler_order": ("loss", "euler_order"),
}
"""Flat field names (``--set``, the overrides of ``paper``/``tiny``) -> (section, field); loss weights take a
``lambda_`` prefix."""


@dataclass
class GaitNetConfig:
    """Everything a gait network run is made of: architecture, data, training and loss weights (and free notes).

    ``GaitNetConfig()`` is the CPU default (GRU 2 x 256, 28 epochs, style term and a 30-step free-running
    continuation). The shipped weights are the previous default run (without the style term) fine-tuned with it;
    docs/benchmarks/gait.md has the commands.
    """

    model: GaitModelConfig = field(default_factory=GaitModelConfig)
    data: GaitDataConfig = field(default_factory=GaitDataConfig)
    train: GaitTrainConfig = field(default_factory=GaitTrainConfig)
    loss: GaitLossWeights = field(default_factory=GaitLossWeights)
    notes: dict = field(default_factory=dict)

    @property
    def prefix_len(self) -> int:
        """Number of ground-truth steps given before prediction (``data.prefix_len``)."""
        return self.data.prefix_len

    @classmethod
    def paper(cls, **overrides) -> GaitNetConfig:
        """The released model (:meth:`GaitModelConfig.paper`, about 9.9 M parameters) trained for 500 epochs with
        the paper's teacher-forcing decay 0.995 per epoch (the other settings are the default's).
        ``overrides`` use the flat names (:data:`FLAT_NAMES`), e.g. ``paper(epochs=10)``."""
        return cls(model=GaitModelConfig.paper(), train=GaitTrainConfig(epochs=500, tf_decay=0.995)
                   ).with_overrides(**overrides)

    @classmethod
    def tiny(cls, **overrides) -> GaitNetConfig:
        """A very small network for tests (batches of 4, 2 epochs, 4 free-running extra steps); flat-name
        ``overrides`` as in :meth:`paper`."""
        return cls(model=GaitModelConfig.tiny(), train=GaitTrainConfig(batch_size=4, epochs=2, extra_steps=4)
                   ).with_overrides(**overrides)

    def with_overrides(self, **overrides) -> GaitNetConfig:
        """A copy with fields replaced; keys are flat names (``gru_hidden``, ``lambda_root``) or
        ``section.field`` (``model.gru_hidden``, ``loss.root``). Unknown names raise a ValueError."""
        sections = {name: getattr(self, name).to_dict() for name in SECTIONS}
        notes = dict(self.notes)
        unknown = []
        for key, value in overrides.items():
            if key == "notes":
                notes = dict(value)
                continue
            section, _, name = key.partition(".")
            if not name:
                section, name = FLAT_NAMES.get(key, (None, key))
            if section not in sections or name not in {f.name for f in fields(SECTIONS[section])}:
                unknown.append(key)
                continue
            sections[section][name] = value
        if unknown:
            raise ValueError(f"unknown GaitNetConfig fields {sorted(unknown)}")
        return replace(self, notes=notes, **{k: SECTIONS[k].from_dict(v) for k, v in sections.items()})

    def to_dict(self) -> dict:
        """{"model": {...}, "data": {...}, "train": {...}, "loss": {...}, "notes": {...}} (checkpoint format 2)."""
        return {**{name: getattr(self, name).to_dict() for name in SECTIONS}, "notes": dict(self.notes)}

    @classmethod
    def from_dict(cls, d: dict) -> GaitNetConfig:
        """Rebuild from :meth:`to_dict` ({"model": {...}, "data": {...}, "train": {...}, "loss": {...}, "notes"});
        a missing field takes its default. Unknown keys, or a dict that is not split by section, raise a
        ValueError naming them."""
        unknown = sorted(set(d) - set(SECTIONS) - {"notes"})
        if unknown:
            raise ValueError(f"unknown GaitNetConfig fields {unknown} (expected the sections {sorted(SECTIONS)} "
                             "and notes, as GaitNetConfig.to_dict writes them)")
        not_sections = sorted(name for name in SECTIONS if name in d and not isinstance(d[name], dict))
        if not_sections:
            raise ValueError(f"GaitNetConfig sections {not_sections} must be mappings of fields")
        return cls(**{name: SECTIONS[name].from_dict(dict(d.get(name, {}))) for name in SECTIONS},
                   notes=dict(d.get("notes", {})))
