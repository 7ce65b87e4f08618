"""The affect-based autoregression network of seed 000 (section 4, Fig. 4), one step at a time.

Encoder (section 4.1):
    i1 = [a_t, m]                                   (18 + C)   -> FC_enc1 (3 ELU layers) -> H1
    i2 = [sin theta_t, cos theta_t, omega_t, s-bar_t, kappa_t, m]  (5 + C) -> FC_enc2 -> H2
    gamma_t = [FC_enc1(i1); FC_enc2(i2)]                                        (eq. 1)
    q~ = GRU_versors([q_t; gamma_t])                  (4J + H1 + H2) -> H3        (eq. 2)
    [h~, s~, delta~] = FC_root([h_t, s_t, delta_t; gamma_t])      (3 + H1 + H2) -> H4   (eq. 3)
Predictor (section 4.2):
    q^_{t+1} = normalise(FC_versors(q~))             2 ELU layers -> 4J          (eq. 4)
    h^, s^, delta^ = FC_h(h~), FC_s(s~), FC_delta(delta~)                        (eqs. 5-7)

Differences from the paper, on purpose:
- q_t holds all J joints: the root's rotation is expressed relative to the heading of the path (the
  character's travel direction), so pitch and roll of the pelvis (a sad bow) are kept; the paper keeps
  J-1 joints and recovers the root orientation from delta.
- one extra head FC_omega predicts the next step-phase increment omega so that generation can advance
  the stepping phase theta without ground truth (the paper derives theta from the data; at generation
  time no future foot contacts exist).
- the prediction horizon of each step is one time step (T_pred = 1) and the network is rolled out
  autoregressively, as in QuaterNet and the curriculum of section 5.3.
With ``emotion_skip`` m is also concatenated to the GRU input and to FC_versors' input at every step.
The ablation without affective inputs and loss (section 5.6) drops FC_enc1 (``use_affective=False``).

Shapes: N batch, J joints, C emotions. Inputs are standardised by :class:`generation.gait.data.Normalizer`.
"""
from __future__ import annotations

import torch
from torch import nn

from .config import NUM_AFFECTIVE, NUM_ROOT_FEATURES, NUM_STEP_FEATURES, GaitModelConfig


def mlp(sizes: list[int], final_activation: bool = True) -> nn.Sequential:
    """Fully connected stack with ELU activations (section 5.3: ELU on all FC layers)."""
    layers: list[nn.Module] = []
    for i in range(len(sizes) - 1):
        layers.append(nn.Linear(sizes[i], sizes[i + 1]))
        if final_activation or i < len(sizes) - 2:
            layers.append(nn.ELU())
    return nn.Sequential(*layers)


class GaitNet(nn.Module):
    """Encoder + predictor; call :meth:`step` once per time step (or :meth:`forward` for many steps).

    ``config`` is the architecture (``GaitNetConfig.model``).
    """

    def __init__(self, config: GaitModelConfig):
        super().__init__()
        if not isinstance(config, GaitModelConfig):
            raise TypeError(f"GaitNet takes a GaitModelConfig (GaitNetConfig.model), got {type(config).__name__}")
        self.config = config
        C, J = config.num_emotions, config.num_joints
        if config.use_affective:
            self.fc_enc1 = mlp([NUM_AFFECTIVE + C, *config.enc1_sizes])
        else:
            self.fc_enc1 = None
        self.fc_enc2 = mlp([NUM_STEP_FEATURES + C, *config.enc2_sizes])
        gamma = config.h1 + config.h2
        skip = C if config.emotion_skip else 0
        self.gru_versors = nn.GRU(4 * J + gamma + skip, config.gru_hidden, num_layers=config.gru_layers,
                                  batch_first=True)
        self.fc_root = mlp([NUM_ROOT_FEATURES + gamma, config.root_hidden])
        self.fc_versors = mlp([config.gru_hidden + skip, config.versor_hidden, 4 * J], final_activation=False)
        self.fc_h = nn.Linear(config.root_hidden, 1)
        self.fc_s = nn.Linear(config.root_hidden, 1)
        self.fc_delta = nn.Linear(config.root_hidden, 1)
        self.fc_omega = nn.Linear(config.gru_hidden + config.root_hidden, 1)
        if config.residual:
            # Start as "hold the pose": the residual head begins near zero.
            nn.init.zeros_(self.fc_versors[-1].weight)
            nn.init.zeros_(self.fc_versors[-1].bias)

    def num_parameters(self) -> int:
        return sum(p.numel() for p in self.parameters())

    def forward(self, q, aff, step_feats, root_feats, emotion, hidden=None):
        """Run the network over L steps (teacher-forced inputs).

        Args:
            q: (N, L, J, 4) current rotations (unit quaternions; root relative to the path heading).
            aff: (N, L, 18) standardised affective features of the current pose.
            step_feats: (N, L, 5) [sin theta, cos theta, omega, s-bar, kappa] (last three standardised).
            root_feats: (N, L, 3) standardised [h, s, delta].
            emotion: (N, L, C) emotion vectors (l1-normalised).
            hidden: GRU state (layers, N, H3) or None.

        Returns:
            dict with ``q_raw`` (N, L, J, 4) unnormalised next rotations, ``q`` (N, L, J, 4) unit next
            rotations, ``root`` (N, L, 3) standardised next [h, s, delta], ``omega`` (N, L) standardised
            next phase increment, and ``hidden`` the new GRU state.
        """
        N, L, J, _ = q.shape
        parts = []
        if self.fc_enc1 is not None:
            parts.append(self.fc_enc1(torch.cat((aff, emotion), dim=-1)))
        parts.append(self.fc_enc2(torch.cat((step_feats, emotion), dim=-1)))
        gamma = torch.cat(parts, dim=-1)
        q_flat = q.reshape(N, L, 4 * J)
        skip = [emotion] if self.config.emotion_skip else []
        q_latent, hidden = self.gru_versors(torch.cat((q_flat, gamma, *skip), dim=-1), hidden)
        root_latent = self.fc_root(torch.cat((root_feats, gamma), dim=-1))
        q_out = self.fc_versors(torch.cat((q_latent, *skip), dim=-1))
        if self.config.residual:
            q_out = q_out + q_flat
        q_raw = q_out.reshape(N, L, J, 4)
        q_unit = q_raw / q_raw.norm(dim=-1, keepdim=True).clamp_min(1e-8)
        root = torch.cat((self.fc_h(root_latent), self.fc_s(root_latent), self.fc_delta(root_latent)), dim=-1)
        omega = self.fc_omega(torch.cat((q_latent, root_latent), dim=-1))[..., 0]
        return {"q_raw": q_raw, "q": q_unit, "root": root, "omega": omega, "hidden": hidden}

    def step(self, q, aff, step_feats, root_feats, emotion, hidden=None):
        """One time step: inputs without the L axis ((N, J, 4), (N, 18), ...); outputs likewise."""
        out = self.forward(q[:, None], aff[:, None], step_feats[:, None], root_feats[:, None], emotion[:, None],
                           hidden)
        return {k: (v[:, 0] if k != "hidden" else v) for k, v in out.items()}
