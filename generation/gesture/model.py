"""The Text2Gestures transformer encoder-decoder (seed 003 section 3.4), in one file.

Encoder: token vectors W (B, S, 384) -> linear to d_model + sinusoidal positions -> N blocks of
(self-attention, feed-forward) with residuals -> F_W (eqs. 3-4). The agent attributes (acting task A one-hot 2,
intended emotion E as VAD 3, gender G one-hot 2, handedness H one-hot 2) are appended to every encoded token and
passed through two fully-connected layers (eq. 5).

Decoder: the past poses Q (B, T, 23*4) -> linear to d_model + sinusoidal positions of the absolute frame index ->
N blocks of (masked self-attention over the past ``window`` = 20 steps (eq. 6), attention to the encoded text
(eq. 7), feed-forward), then a linear head to 23 quaternions, normalised to unit length. Eq. 7 as printed takes the
query from the text and key/value from the poses, which would give one output per word, not per frame; as in
Vaswani et al. (and the released code, which uses the standard transformer decoder) the poses give the query and the
encoded text the keys and values.

Additions to the paper, all small: (1) the head predicts an offset that is added, before normalisation, to the
rest pose (``residual="rest"``, the shipped setting, chosen over ``"previous"`` (QuaterNet-style, added to the last
pose) by validation pose error) or to nothing (``"none"``); (2) each decoder input carries the gesture's progress
(fraction of the sentence's gesture elapsed, seconds left), because the decoder sees a bounded window and must know
when to return to the end-of-sequence rest pose (the paper pads every sequence to one length with the EoS pose, so
absolute position tells the same thing there); (3) the attributes are also appended to each decoder input, so the
pose stream is conditioned directly as well as through the encoded text. With N = 2 layers each looking back 20
steps, a decoder output depends on the last 2 * 19 + 1 = 39 input poses (:attr:`GestureNet.receptive_field`).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import torch
import torch.nn as nn
import torch.nn.functional as F

N_ATTRIBUTES = 9  # task (2) + VAD (3) + gender (2) + handedness (2)
N_PROGRESS = 2  # fraction elapsed, seconds left / 10


@dataclass
class GestureNetConfig:
    """Hyper-parameters; defaults follow seed 003 section 4 (N = 2, h = 2, FC 200, dropout 0.2, T = 20)."""

    n_joints: int = 23
    text_dim: int = 384
    d_model: int = 64
    n_head: int = 2
    n_layer: int = 2
    d_ff: int = 200
    dropout: float = 0.2
    window: int = 20
    max_frames: int = 512
    residual: str = "rest"  # the head's output is added to: the "rest" pose, the "previous" pose, or "none"

    def to_dict(self) -> dict:
        return asdict(self)


#: Trainable parameters of the published network (seed 003 section 5.2: "26,264,145 trainable parameters").
PAPER_PARAMETERS = 26_264_145


def paper_config() -> GestureNetConfig:
    """The published size: N = 2 layers, h = 2 heads, FC 200, dropout 0.2, window 20 (seed 003 section 5.2), at the
    width that gives the published parameter count.

    The paper does not print its model width; the released code's count is dominated by a word-embedding table and
    a vocabulary-sized output layer that this network does not have (its text vectors come from the pretrained
    encoder). ``d_model = 992`` (divisible by the 2 heads) gives 26,233,356 parameters, 0.12 % under the
    published 26,264,145.
    """
    return GestureNetConfig(d_model=992)


MODEL_PRESETS = {"small": GestureNetConfig, "paper": paper_config}


def sinusoidal_encoding(positions: torch.Tensor, dim: int) -> torch.Tensor:
    """Vaswani et al. positional encoding: positions (...,) float -> (..., dim)."""
    half = dim // 2
    freqs = torch.exp(-math.log(10000.0) * torch.arange(half, dtype=torch.float32, device=positions.device) / half)
    angles = positions.to(torch.float32)[..., None] * freqs
    return torch.cat((torch.sin(angles), torch.cos(angles)), dim=-1)


class MultiHeadAttention(nn.Module):
    """Multi-head scaled dot-product attention (eqs. 2-4, 6-7); query from x, keys/values from ``context``."""

    def __init__(self, cfg: GestureNetConfig):
        super().__init__()
        if cfg.d_model % cfg.n_head:
            raise ValueError(f"d_model {cfg.d_model} is not divisible by n_head {cfg.n_head}")
        self.n_head = cfg.n_head
        self.q = nn.Linear(cfg.d_model, cfg.d_model)
        self.kv = nn.Linear(cfg.d_model, 2 * cfg.d_model)
        self.proj = nn.Linear(cfg.d_model, cfg.d_model)  # W_concat
        self.dropout = cfg.dropout

    def forward(self, x: torch.Tensor, context: torch.Tensor, mask: torch.Tensor | None) -> torch.Tensor:
        """x (B, T, d), context (B, S, d), mask (B or 1, 1, T, S) bool, True = may attend -> (B, T, d)."""
        B, T, d = x.shape
        S = context.shape[1]
        h = self.n_head
        q = self.q(x).view(B, T, h, d // h).transpose(1, 2)
        k, v = self.kv(context).split(d, dim=-1)
        k = k.view(B, S, h, d // h).transpose(1, 2)
        v = v.view(B, S, h, d // h).transpose(1, 2)
        y = F.scaled_dot_product_attention(q, k, v, attn_mask=mask,
                                           dropout_p=self.dropout if self.training else 0.0)
        return self.proj(y.transpose(1, 2).reshape(B, T, d))


class FeedForward(nn.Module):
    """The two fully-connected layers of a block (d -> d_ff -> d)."""

    def __init__(self, cfg: GestureNetConfig):
        super().__init__()
        self.net = nn.Sequential(nn.Linear(cfg.d_model, cfg.d_ff), nn.GELU(), nn.Linear(cfg.d_ff, cfg.d_model),
                                 nn.Dropout(cfg.dropout))

    def forward(self, x):
        return self.net(x)


class EncoderBlock(nn.Module):
    """(SA - MH - FC) with residuals (pre-norm)."""

    def __init__(self, cfg: GestureNetConfig):
        super().__init__()
        self.ln1 = nn.LayerNorm(cfg.d_model)
        self.attn = MultiHeadAttention(cfg)
        self.ln2 = nn.LayerNorm(cfg.d_model)
        self.ff = FeedForward(cfg)

    def forward(self, x, mask):
        h = self.ln1(x)
        x = x + self.attn(h, h, mask)
        return x + self.ff(self.ln2(x))


class DecoderBlock(nn.Module):
    """(SA - MMH - SA - MH - FC) with residuals (pre-norm)."""

    def __init__(self, cfg: GestureNetConfig):
        super().__init__()
        self.ln1 = nn.LayerNorm(cfg.d_model)
        self.self_attn = MultiHeadAttention(cfg)
        self.ln2 = nn.LayerNorm(cfg.d_model)
        self.cross_attn = MultiHeadAttention(cfg)
        self.ln3 = nn.LayerNorm(cfg.d_model)
        self.ff = FeedForward(cfg)

    def forward(self, x, memory, self_mask, cross_mask):
        h = self.ln1(x)
        x = x + self.self_attn(h, h, self_mask)
        x = x + self.cross_attn(self.ln2(x), memory, cross_mask)
        return x + self.ff(self.ln3(x))


def window_mask(positions: torch.Tensor, window: int) -> torch.Tensor:
    """Causal band mask: query frame i sees key frames j with 0 <= pos_i - pos_j < window.

    positions (B, T) absolute frame indices -> (B, 1, T, T) bool.
    """
    diff = positions[:, :, None] - positions[:, None, :]
    return ((diff >= 0) & (diff < window))[:, None]


class GestureNet(nn.Module):
    """Text + attributes + past poses -> next poses as unit quaternions (23 joints)."""

    def __init__(self, cfg: GestureNetConfig | None = None):
        super().__init__()
        self.cfg = cfg = cfg or GestureNetConfig()
        self.text_in = nn.Linear(cfg.text_dim, cfg.d_model)
        self.text_drop = nn.Dropout(cfg.dropout)
        self.encoder = nn.ModuleList(EncoderBlock(cfg) for _ in range(cfg.n_layer))
        self.enc_ln = nn.LayerNorm(cfg.d_model)
        # Eq. 5: two FC layers on [F_W, A, E, G, H].
        self.condition = nn.Sequential(nn.Linear(cfg.d_model + N_ATTRIBUTES, cfg.d_ff), nn.GELU(),
                                       nn.Linear(cfg.d_ff, cfg.d_model))
        self.pose_in = nn.Linear(cfg.n_joints * 4 + N_PROGRESS + N_ATTRIBUTES, cfg.d_model)
        self.pose_drop = nn.Dropout(cfg.dropout)
        self.decoder = nn.ModuleList(DecoderBlock(cfg) for _ in range(cfg.n_layer))
        self.dec_ln = nn.LayerNorm(cfg.d_model)
        self.head = nn.Linear(cfg.d_model, cfg.n_joints * 4)
        if cfg.residual not in ("previous", "rest", "none"):
            raise ValueError(f"residual must be 'previous', 'rest' or 'none', got {cfg.residual!r}")
        if cfg.residual != "none":  # start as "hold the previous (or rest) pose"
            nn.init.zeros_(self.head.weight)
            nn.init.zeros_(self.head.bias)

    @property
    def receptive_field(self) -> int:
        """How many past input poses the stacked decoder's output depends on: n_layer * (window - 1) + 1."""
        return self.cfg.n_layer * (self.cfg.window - 1) + 1

    def num_parameters(self) -> int:
        return sum(p.numel() for p in self.parameters())

    def encode(self, tokens: torch.Tensor, token_mask: torch.Tensor, attributes: torch.Tensor) -> torch.Tensor:
        """tokens (B, S, 384), token_mask (B, S) bool (True = real token), attributes (B, 9) -> (B, S, d_model)."""
        S = tokens.shape[1]
        x = self.text_in(tokens) + sinusoidal_encoding(torch.arange(S, device=tokens.device), self.cfg.d_model)
        x = self.text_drop(x)
        mask = token_mask[:, None, None, :]
        for block in self.encoder:
            x = block(x, mask)
        x = self.enc_ln(x)
        attrs = attributes[:, None, :].expand(-1, S, -1)
        return self.condition(torch.cat((x, attrs), dim=-1))

    def decode(self, memory: torch.Tensor, token_mask: torch.Tensor, attributes: torch.Tensor,
               poses: torch.Tensor, positions: torch.Tensor, progress: torch.Tensor,
               rest: torch.Tensor | None = None) -> torch.Tensor:
        """Next pose after each input pose.

        Args:
            memory: (B, S, d) from :meth:`encode`; token_mask (B, S) bool; attributes (B, 9).
            poses: (B, T, J, 4) input (past) poses, unit quaternions.
            positions: (B, T) absolute frame index of each input pose.
            progress: (B, T, 2) progress features of the frame each output predicts.
            rest: (B, J, 4) start/end-of-sequence rest pose (needed when ``cfg.residual == "rest"``).

        Returns:
            (B, T, J, 4) unit quaternions; output t is the pose that follows input t.
        """
        B, T, J, _ = poses.shape
        flat = poses.reshape(B, T, J * 4)
        attrs = attributes[:, None, :].expand(-1, T, -1)
        x = self.pose_in(torch.cat((flat, progress, attrs), dim=-1))
        x = self.pose_drop(x + sinusoidal_encoding(positions, self.cfg.d_model))
        self_mask = window_mask(positions, self.cfg.window)
        cross_mask = token_mask[:, None, None, :]
        for block in self.decoder:
            x = block(x, memory, self_mask, cross_mask)
        out = self.head(self.dec_ln(x)).view(B, T, J, 4)
        if self.cfg.residual == "previous":
            out = out + poses
        elif self.cfg.residual == "rest":
            if rest is None:
                raise ValueError("this network predicts offsets from the rest pose: pass rest (B, J, 4)")
            out = out + rest[:, None]
        return out / out.norm(dim=-1, keepdim=True).clamp_min(1e-8)

    def forward(self, tokens, token_mask, attributes, poses, positions, progress, rest=None):
        """Teacher-forced pass over whole sequences; shapes as in :meth:`encode` and :meth:`decode`."""
        memory = self.encode(tokens, token_mask, attributes)
        return self.decode(memory, token_mask, attributes, poses, positions, progress, rest)
