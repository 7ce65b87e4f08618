"""Linear blend skinning of an exported body (numpy + scipy.sparse).

Posing follows anny's ``world-orient`` parameterisation: each bone is given its world orientation ``D_c`` (3x3) and
its head follows its parent, so bone lengths stay the body's own. With the rest pose ``[R_c | h_c]``, the bone's
transform is ``T_c = [G_c | T_p(h_c) - G_c h_c]`` with ``G_c = D_c R_c^T`` (the root: ``T_0 = [G_0 | d_0 - G_0
h_0]`` for its head's world position ``d_0``), and a vertex moves to ``sum_k w_k T_{b_k} v``.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .store import Body


def bone_transforms(body: Body, orientations: np.ndarray, root_head: np.ndarray) -> np.ndarray:
    """(T, B, 3, 4) bone transforms from world orientations (T, B, 3, 3) and the root head's positions (T, 3)."""
    G = orientations @ np.swapaxes(body.bone_rest, -1, -2)[None]          # (T, B, 3, 3)
    h = body.bone_heads
    t = np.empty(G.shape[:2] + (3,))
    t[:, 0] = root_head - G[:, 0] @ h[0]
    for c in range(1, body.num_bones):
        p = body.bone_parents[c]
        t[:, c] = G[:, p] @ h[c] + t[:, p] - G[:, c] @ h[c]
    return np.concatenate([G, t[..., None]], axis=-1)


def vertex_normals(points: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(V, 3) unit vertex normals: the area-weighted sum of the faces' normals around each vertex."""
    tri = points[faces]
    fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n = np.zeros_like(points, dtype=float)
    for k in range(3):
        np.add.at(n, faces[:, k], fn)
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)


def posed_heads(body: Body, transforms: np.ndarray) -> np.ndarray:
    """(T, B, 3) bone head positions under ``transforms`` (T, B, 3, 4)."""
    return np.einsum("tbij,bj->tbi", transforms[..., :3], body.bone_heads) + transforms[..., 3]


class Skinner:
    """Skins one body, frame by frame: ``points, normals = skinner(transforms_of_one_frame)``.

    The weights are kept as a sparse (V, B) matrix, so blending the 12 coefficients of every bone's transform per
    vertex is one sparse product; the normals turn with the blended 3x3 part (renormalised).
    """

    def __init__(self, body: Body, rest_points: np.ndarray | None = None, rest_normals: np.ndarray | None = None):
        V, K = body.weights.shape
        rows = np.repeat(np.arange(V), K)
        self.W = sp.csr_matrix((body.weights.ravel(), (rows, body.weight_bones.ravel())),
                               shape=(V, body.num_bones))
        self.points = np.array(body.vertices if rest_points is None else rest_points, dtype=float)
        self.normals = None if rest_normals is None else np.array(rest_normals, dtype=float)

    def blend(self, transforms: np.ndarray) -> np.ndarray:
        """(V, 3, 4) per-vertex blended transforms for one frame's (B, 3, 4)."""
        return np.asarray(self.W @ transforms.reshape(len(transforms), 12)).reshape(-1, 3, 4)

    def __call__(self, transforms: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """(V, 3) points and (V, 3) unit normals (or None without rest normals) for one frame."""
        M = self.blend(transforms)
        pts = np.einsum("vij,vj->vi", M[:, :, :3], self.points) + M[:, :, 3]
        if self.normals is None:
            return pts, None
        n = np.einsum("vij,vj->vi", M[:, :, :3], self.normals)
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
        return pts, n

    def pose_many(self, transforms: np.ndarray, index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(T, N, 3) posed points and (T, N, 3) unit normals of the rows ``index`` (needs rest normals)."""
        T = len(transforms)
        coeffs = transforms.reshape(T, -1, 12).transpose(1, 0, 2).reshape(-1, T * 12)
        M = np.asarray(self.W[index] @ coeffs).reshape(len(index), T, 3, 4)
        pts = np.einsum("ntij,nj->tni", M[..., :3], self.points[index]) + M[..., 3].transpose(1, 0, 2)
        n = np.einsum("ntij,nj->tni", M[..., :3], self.normals[index])
        return pts, n / np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-12)

    def points_many(self, transforms: np.ndarray, index: np.ndarray | None = None) -> np.ndarray:
        """(T, N, 3) posed points (all, or the rows ``index``) for transforms (T, B, 3, 4)."""
        W = self.W if index is None else self.W[index]
        P = self.points if index is None else self.points[index]
        T = len(transforms)
        coeffs = transforms.reshape(T, -1, 12).transpose(1, 0, 2).reshape(-1, T * 12)      # (B, T * 12)
        M = np.asarray(W @ coeffs).reshape(len(P), T, 3, 4)
        return np.einsum("ntij,nj->tni", M[..., :3], P) + M[..., 3].transpose(1, 0, 2)
