"""Batched forward kinematics in torch (differentiable) and numpy.

Convention (QuaterNet): ``rotations[..., j, :]`` is joint j's local rotation relative to its
parent; the global rotation of j is ``R_global[parent(j)] * R_local[j]``; the position of j is
``X[parent(j)] + R_global[parent(j)] · offset[j]``; the root's local rotation is its global
orientation and its position is given by ``root_positions``. torch is imported when a function first runs, not
with this module.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .quaternion import qmul, qrot
from .skeleton import Skeleton

if TYPE_CHECKING:
    import torch


def forward_kinematics(
    rotations: torch.Tensor,
    root_positions: torch.Tensor,
    offsets: torch.Tensor,
    parents: tuple[int, ...] | list[int],
    return_global_rotations: bool = False,
):
    """Joint positions from local rotations.

    Args:
        rotations: (..., J, 4) unit quaternions (w, x, y, z), e.g. (N, T, J, 4).
        root_positions: (..., 3) metres.
        offsets: (J, 3) or (..., J, 3) rest offsets in metres.
        parents: J parent indices, -1 for the root; parents precede children.
        return_global_rotations: also return (..., J, 4) global rotations.

    Returns:
        (..., J, 3) positions in metres (and global rotations when asked).
    """
    import torch  # heavy: only the torch variants load torch
    positions: list[torch.Tensor] = []
    global_rot: list[torch.Tensor] = []
    offsets = offsets.to(rotations.dtype)
    for j, p in enumerate(parents):
        if p < 0:
            positions.append(root_positions)
            global_rot.append(rotations[..., j, :])
        else:
            positions.append(positions[p] + qrot(global_rot[p], offsets[..., j, :].expand_as(root_positions)))
            global_rot.append(qmul(global_rot[p], rotations[..., j, :]))
    pos = torch.stack(positions, dim=-2)
    if return_global_rotations:
        return pos, torch.stack(global_rot, dim=-2)
    return pos


def fk_skeleton(rotations: torch.Tensor, root_positions: torch.Tensor, skeleton: Skeleton) -> torch.Tensor:
    """Torch forward kinematics on a :class:`Skeleton`; shapes as in :func:`forward_kinematics`."""
    import torch  # heavy: only the torch variants load torch
    offsets = torch.tensor(skeleton.offsets, dtype=rotations.dtype, device=rotations.device)
    return forward_kinematics(rotations, root_positions, offsets, skeleton.parents)


def np_forward_kinematics(rotations: np.ndarray, root_positions: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """numpy forward kinematics: (..., J, 4), (..., 3) -> (..., J, 3) metres, float64."""
    import torch  # heavy: only the torch variants load torch
    with torch.no_grad():
        pos = fk_skeleton(torch.as_tensor(np.asarray(rotations, dtype=np.float64)),
                          torch.as_tensor(np.asarray(root_positions, dtype=np.float64)), skeleton)
    return pos.numpy()
