"""Configuration of the affect-based autoregression gait network (seed 000, sections 4-5).

All sizes live here so that the default (sized to train in about 20 minutes on one CPU thread)
and the paper's released sizes (``GaitNetConfig.paper()``) are the same code path.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields

NUM_JOINTS = 21          # gait skeleton of seed 000 (Fig. 2)
NUM_EMOTIONS = 4         # happy, sad, angry, neutral (section 3.2.2)
NUM_AFFECTIVE = 18       # 11 angles, 4 distance ratios, 3 area ratios (section 3.2.3)
NUM_STEP_FEATURES = 5    # sin theta, cos theta, omega, s-bar, kappa (section 4.1)
NUM_ROOT_FEATURES = 3    # h, s, delta (section 4.1, eq. 3)


@dataclass
class GaitNetConfig:
    """Sizes and training settings.

    Network sizes (names follow section 4 of seed 000):
        enc1_sizes: hidden sizes of FC_enc1 on [affective features a_t, emotion m]; the last is H1.
        enc2_sizes: hidden sizes of FC_enc2 on [sin theta, cos theta, omega, s-bar, kappa, m]; the last is H2.
        gru_hidden: H3, hidden units of GRU_versors; gru_layers its depth.
        root_hidden: H4, units of the FC_root layer on [h, s, delta; gamma].
        versor_hidden: hidden layer of the 2-layer FC_versors head.
        residual: the versor head predicts a change added to the current rotations before normalising
            (QuaterNet-style); False predicts absolute rotations.
        use_affective: False gives the ablation without affective inputs and without L_aff (seed 000 5.6).
        emotion_skip: the emotion m also enters GRU_versors and FC_versors directly at every step (not only
            through the 8-unit encoders), so the label can steer the pose; False is the paper's wiring
            (and that of checkpoints saved before this field existed).

    Data and training (section 5.1, 5.3):
        seq_len: T = 60 network steps (240 frames sampled every ``frame_step``-th frame).
        prefix_frac: 0.3, the fraction of each sequence always given as ground truth (18 of 60 steps).
        lr, lr_decay: Adam 1e-3 decayed by 0.999 per epoch.
        tf_decay: teacher-forcing ratio decays as tf_decay ** epoch. The paper uses 0.995 over 500 epochs (final
            ratio 0.08); the default run has 28 epochs (the ~20 minute budget on a shared CPU), so 0.91 gives about
            the same final ratio (0.91 ** 27 = 0.08).
        lambda_*: loss weights of eq. 13 (1.0 in the paper); lambda_versor is the unit-norm term of eq. 8;
            lambda_phase weights the step-phase head (an addition of this implementation, see losses.py).
        pos_scale_m: positions in the pose and foot losses are measured in units of this many metres.
        splice_frac: fraction of training sequences whose ground-truth prefix is taken from another walk of a
            different dominant emotion (phase-aligned); the emotion input switches from that walk's label to the
            sequence's own label at the splice. Every corpus walk has one emotion throughout, so without this the
            motion history predicts the style and the network learns to ignore m (see train.splice_histories).
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

    seq_len: int = 60
    frame_step: int = 4
    prefix_frac: float = 0.3
    batch_size: int = 64
    epochs: int = 28
    lr: float = 1e-3
    lr_decay: float = 0.999
    tf_decay: float = 0.91
    grad_clip: float = 1.0

    lambda_motion: float = 1.0
    lambda_versor: float = 1.0
    lambda_pose: float = 1.0
    lambda_aff: float = 1.0
    lambda_root: float = 1.0
    lambda_fctc: float = 1.0
    lambda_phase: float = 1.0
    pos_scale_m: float = 0.1
    splice_frac: float = 0.3
    euler_order: str = "zyx"
    seed: int = 0
    notes: dict = field(default_factory=dict)

    @property
    def prefix_len(self) -> int:
        """Number of ground-truth steps given before prediction (18 for T = 60)."""
        return int(round(self.prefix_frac * self.seq_len))

    @property
    def h1(self) -> int:
        return self.enc1_sizes[-1] if self.use_affective else 0

    @property
    def h2(self) -> int:
        return self.enc2_sizes[-1]

    @classmethod
    def paper(cls, **overrides) -> GaitNetConfig:
        """The released model's sizes (REFERENCE.md section 1): 2-layer GRU with 1024 units, FC 16-16-8,
        versor head 1024-128-(J-1)*4, 500 epochs; about ten million parameters."""
        base = dict(enc1_sizes=(16, 16, 8), enc2_sizes=(16, 16, 8), gru_hidden=1024, gru_layers=2,
                    root_hidden=32, versor_hidden=128, epochs=500)
        base.update(overrides)
        return cls(**base)

    @classmethod
    def tiny(cls, **overrides) -> GaitNetConfig:
        """A very small network for tests."""
        base = dict(enc1_sizes=(8, 8), enc2_sizes=(8, 8), gru_hidden=32, gru_layers=1, root_hidden=8,
                    versor_hidden=32, batch_size=4, epochs=2)
        base.update(overrides)
        return cls(**base)

    def to_dict(self) -> dict:
        d = asdict(self)
        for k in ("enc1_sizes", "enc2_sizes"):
            d[k] = list(d[k])
        return d

    @classmethod
    def from_dict(cls, d: dict) -> GaitNetConfig:
        """Rebuild from :meth:`to_dict`; unknown keys raise a ValueError naming them."""
        names = {f.name for f in fields(cls)}
        unknown = sorted(set(d) - names)
        if unknown:
            raise ValueError(f"unknown GaitNetConfig fields {unknown}")
        d = dict(d)
        d.setdefault("emotion_skip", False)  # checkpoints saved before the field existed
        for k in ("enc1_sizes", "enc2_sizes"):
            if k in d:
                d[k] = tuple(d[k])
        return cls(**d)
