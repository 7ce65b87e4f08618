"""A low-poly humanoid mannequin built from a skeleton's own bone lengths.

Every body part is a rigid mesh attached to one bone: a tapered capsule (spherical caps centred on the
two joints, so elbows, knees, hips and shoulders show no gap at any bend) with an elliptic cross-section
for the trunk, hands and feet, plus an ellipsoid head without a face. Meshes are built once per clip at
the skeleton's rest bone lengths; each frame only computes one rigid 4x4 transform per part
(:func:`part_matrices`), so the body follows the motion without re-meshing.

Widths scale with the body height (``skeleton.height / 1.75``) and the build: a female build gets a
narrower chest and shoulders, wider hips and a deeper chest; a male build the reverse (the skeleton's
own shoulder and hip offsets already differ by build, see :data:`generation.core.skeleton.BUILDS`).
Pure numpy apart from :func:`part_mesh` (PyVista).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generation.core.skeleton import Skeleton

#: Matte neutral clay colour of the mannequin (warm, so it reads against the grey floor and the bluish
#: white background; no left/right colour coding).
MANNEQUIN_COLOUR = (0.80, 0.66, 0.52)

# Trunk half-widths (x) and depth ratios (z / x) at fractions of the root->neck height, for 1.75 m.
_TRUNK = {
    "male": {"h": (0.0, 0.40, 0.80, 1.0), "w": (0.150, 0.125, 0.170, 0.120), "d": (0.62, 0.62, 0.64, 0.70)},
    "female": {"h": (0.0, 0.40, 0.80, 1.0), "w": (0.165, 0.112, 0.148, 0.105), "d": (0.60, 0.66, 0.78, 0.72)},
}
# Limb radii (start, end) for 1.75 m, by build.
_LIMBS = {
    "male": {"thigh": (0.078, 0.052), "shin": (0.050, 0.036), "foot": (0.038, 0.030), "girdle": (0.055, 0.055),
             "upper_arm": (0.050, 0.040), "forearm": (0.039, 0.028), "hand": (0.034, 0.028), "neck": (0.048, 0.045)},
    "female": {"thigh": (0.082, 0.050), "shin": (0.046, 0.033), "foot": (0.034, 0.027), "girdle": (0.048, 0.048),
               "upper_arm": (0.044, 0.035), "forearm": (0.034, 0.025), "hand": (0.030, 0.025),
               "neck": (0.040, 0.038)},
}
HEAD_RADII = {"male": (0.085, 0.115, 0.100), "female": (0.080, 0.110, 0.095)}  # x, y (up), z; 1.75 m


@dataclass(frozen=True)
class Part:
    """One rigid body part on the bone ``a -> b`` (joint indices).

    The part's frame: origin at joint ``a``, +y along the bone, +x towards the body's left (from the
    ``side`` joint pair), +z = x cross y. The mesh spans y in [y0 - k*r0, y1 + k*r1].

    Attributes:
        name: e.g. "left_thigh".
        a, b: joint indices of the bone.
        r0, r1: radii at y0 and y1, metres.
        y0, y1: where along the bone the part starts and ends (metres from ``a``).
        sx, sz: scale of the cross-section along x and z (1 = round).
        cap: cap height as a fraction of its radius (1 = hemisphere).
        side: "hips" or "shoulders": which pair of joints gives the part's left direction.
        ellipsoid: (rx, ry, rz) for an ellipsoid centred at (0, y1, 0) instead of a capsule (the head).
    """

    name: str
    a: int
    b: int
    r0: float
    r1: float
    y0: float
    y1: float
    sx: float = 1.0
    sz: float = 1.0
    cap: float = 1.0
    side: str = "hips"
    ellipsoid: tuple[float, float, float] | None = None


def _first(skeleton: Skeleton, *names: str) -> int | None:
    for n in names:
        if n in skeleton.joints:
            return skeleton.joints.index(n)
    return None


def _trunk_profile(build: str, h: float, s: float) -> tuple[float, float]:
    t = _TRUNK[build]
    return float(np.interp(h, t["h"], t["w"])) * s, float(np.interp(h, t["h"], t["d"]))


def _trunk_parts(skeleton: Skeleton, build: str, s: float, neck: int | None) -> list[Part]:
    """The trunk's elliptic capsules (see the comment inside) for a skeleton scaled by ``s`` = height / 1.75."""
    parents = skeleton.parents
    rest = skeleton.rest_positions()
    parts: list[Part] = []
    # Trunk: the chain from the root up to the neck in at most three elliptic capsules (pelvis/abdomen,
    # waist/chest, upper chest) between the chain joints nearest 0, 40 %, 75 % and 100 % of its height; a
    # part may span several spine bones (the gesture skeleton has five), which keeps the trunk from looking
    # like a stack of rings; the parts overlap at their ends, so a bending spine opens no gap.
    chain = []
    j = neck
    while j is not None and j > 0:
        chain.append(j)
        j = parents[j]
    chain = [0] + chain[::-1]  # root .. neck
    if len(chain) > 1:
        y_root, y_neck = rest[0, 1], rest[neck, 1]
        span = max(y_neck - y_root, 1e-6)
        frac = {jj: (rest[jj, 1] - y_root) / span for jj in chain}
        keys = [0]
        for target in (0.40, 0.75):
            inner = [jj for jj in chain[1:-1] if frac[jj] > frac[keys[-1]]]
            if inner:
                best = min(inner, key=lambda jj, t=target: abs(frac[jj] - t))
                if abs(frac[best] - target) < 0.25:
                    keys.append(best)
        keys.append(neck)
        for k, (ja, jb) in enumerate(zip(keys, keys[1:])):
            wa, da = _trunk_profile(build, frac[ja], s)
            wb, db = _trunk_profile(build, frac[jb], s)
            length = float(np.linalg.norm(rest[jb] - rest[ja]))
            parts.append(Part(f"trunk_{k}", ja, jb, wa, wb, 0.0, length, sz=(da + db) / 2,
                              cap=0.65 if k == 0 else 0.25, side="hips" if frac[jb] < 0.5 else "shoulders"))
    return parts


def mannequin_parts(skeleton: Skeleton) -> list[Part]:
    """The parts of a mannequin for ``skeleton`` (the 21-joint gait or 23-joint gesture skeleton, or any
    skeleton with the same joint-name conventions: hips, knees, heels/ankles, toes, shoulders, elbows,
    hands/wrists, neck, head)."""
    s = skeleton.height / 1.75
    build = skeleton.build if skeleton.build in _TRUNK else "male"
    limb = {k: (v[0] * s, v[1] * s) for k, v in _LIMBS[build].items()}
    lengths = skeleton.bone_lengths()
    parents = skeleton.parents
    rest = skeleton.rest_positions()
    parts: list[Part] = []
    neck = _first(skeleton, "neck")
    head = _first(skeleton, "head")
    parts += _trunk_parts(skeleton, build, s, neck)
    if neck is not None and head is not None:
        L = float(lengths[head])
        rx, ry, rz = (r * s for r in HEAD_RADII[build])
        # The head's top touches the body height in the rest pose.
        lift = skeleton.height - (rest[head, 1] + skeleton.root_height()) - ry
        # The neck reaches into the head ellipsoid (its top 0.6 ry above the head's lowest point), so no gap opens
        # between them on skeletons with a long neck->head bone or a lifted head.
        neck_top = max(0.55 * L, L + lift - 0.4 * ry)
        parts.append(Part("neck", neck, head, limb["neck"][0], limb["neck"][1], 0.0, neck_top, side="shoulders"))
        parts.append(Part("head", neck, head, 0.0, 0.0, 0.0, L + lift, side="shoulders", ellipsoid=(rx, ry, rz)))
    for side in ("left", "right"):
        def idx(*cands, side=side):
            return _first(skeleton, *(f"{side}_{c}" for c in cands))

        hip, knee, heel, toe = idx("hip"), idx("knee"), idx("heel", "ankle"), idx("toe")
        collar, shoulder, elbow, hand, index = idx("collar"), idx("shoulder"), idx("elbow"), idx("hand", "wrist"), \
            idx("hand_index")
        if hip is not None and knee is not None:
            parts.append(Part(f"{side}_thigh", hip, knee, *limb["thigh"], 0.0, float(lengths[knee])))
        if knee is not None and heel is not None:
            parts.append(Part(f"{side}_shin", knee, heel, *limb["shin"], 0.0, float(lengths[heel])))
        if heel is not None and toe is not None:
            parts.append(Part(f"{side}_foot", heel, toe, *limb["foot"], 0.0, float(lengths[toe]), sx=1.25, sz=0.75))
        if collar is not None:
            parts.append(Part(f"{side}_collar", parents[collar], collar, *limb["girdle"], 0.0,
                              float(lengths[collar]), side="shoulders"))
        if shoulder is not None and parents[shoulder] >= 0:
            parts.append(Part(f"{side}_girdle", parents[shoulder], shoulder, *limb["girdle"], 0.0,
                              float(lengths[shoulder]), side="shoulders"))
        if shoulder is not None and elbow is not None:
            parts.append(Part(f"{side}_upper_arm", shoulder, elbow, *limb["upper_arm"], 0.0, float(lengths[elbow]),
                              side="shoulders"))
        if elbow is not None and hand is not None:
            parts.append(Part(f"{side}_forearm", elbow, hand, *limb["forearm"], 0.0, float(lengths[hand]),
                              side="shoulders"))
            r0, r1 = limb["hand"]
            if index is not None:  # a hand bone: the hand spans it
                parts.append(Part(f"{side}_hand", hand, index, r0, r1, 0.02 * s, float(lengths[index]), sx=0.5,
                                  side="shoulders"))
            else:  # no hand bone (the gesture skeleton ends at the wrist): extend the forearm's frame
                L = float(lengths[hand])
                parts.append(Part(f"{side}_hand", elbow, hand, r0, r1, L + 0.035 * s, L + 0.10 * s, sx=0.5,
                                  side="shoulders"))
    return parts


def _ring_profile(r0: float, r1: float, y0: float, y1: float, cap: float, n_cap: int = 4
                  ) -> tuple[np.ndarray, np.ndarray]:
    """(rho, y) of the rings of a tapered capsule, bottom pole to top pole (poles have rho 0)."""
    a = np.linspace(-np.pi / 2, 0, n_cap + 1)
    bottom = np.stack([r0 * np.cos(a), y0 + cap * r0 * np.sin(a)], 1)
    top = np.stack([r1 * np.cos(a[::-1]), y1 - cap * r1 * np.sin(a[::-1])], 1)
    mid = []
    if y1 - y0 > 0.12:  # one middle ring on long parts keeps the taper straight under smooth shading
        mid = [[(r0 + r1) / 2, (y0 + y1) / 2]]
    prof = np.concatenate([bottom, np.asarray(mid).reshape(-1, 2), top])
    return prof[:, 0], prof[:, 1]


def part_mesh(part: Part, n_around: int = 12):
    """The PyVista mesh of a part in its own frame (metres), with point normals for smooth shading."""
    import pyvista as pv  # heavy: VTK, loaded only when a frame is drawn

    if part.ellipsoid is not None:
        rx, ry, rz = part.ellipsoid
        sphere = pv.Sphere(radius=1.0, theta_resolution=14, phi_resolution=10)
        pts = np.asarray(sphere.points) * np.array([rx, ry, rz]) + np.array([0.0, part.y1, 0.0])
        sphere.points = pts
        return sphere.compute_normals(auto_orient_normals=True)
    rho, y = _ring_profile(part.r0, part.r1, part.y0, part.y1, part.cap)
    ang = np.linspace(0, 2 * np.pi, n_around, endpoint=False)
    rings = []
    for r, yy in zip(rho, y):
        rings.append(np.stack([r * np.cos(ang) * part.sx, np.full(n_around, yy), r * np.sin(ang) * part.sz], 1))
    pts = np.concatenate(rings)
    faces = []
    n_r = len(rings)
    for i in range(n_r - 1):
        for k in range(n_around):
            a, b = i * n_around + k, i * n_around + (k + 1) % n_around
            faces.append([4, a, a + n_around, b + n_around, b])
    mesh = pv.PolyData(pts, np.asarray(faces).ravel()).clean(tolerance=1e-9)
    return mesh.compute_normals(auto_orient_normals=True, consistent_normals=True)


def _unit_rows(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-9)


class PartPoser:
    """Per-frame rigid transforms of a list of parts (precomputed index arrays; numpy only)."""

    def __init__(self, skeleton: Skeleton, parts: list[Part]):
        self.a = np.array([p.a for p in parts])
        self.b = np.array([p.b for p in parts])
        self.use_shoulders = np.array([p.side == "shoulders" for p in parts])
        j = skeleton.joints
        self.hips = (j.index("left_hip"), j.index("right_hip")) if "left_hip" in j else None
        self.shoulders = (j.index("left_shoulder"), j.index("right_shoulder")) if "left_shoulder" in j else None

    def matrices(self, positions: np.ndarray) -> np.ndarray:
        """(P, 4, 4) transforms for joint positions (J, 3)."""
        axis = _unit_rows(positions[self.b] - positions[self.a])
        hip_side = positions[self.hips[0]] - positions[self.hips[1]] if self.hips else np.array([1.0, 0, 0])
        sh_side = positions[self.shoulders[0]] - positions[self.shoulders[1]] if self.shoulders else hip_side
        side = np.where(self.use_shoulders[:, None], sh_side[None], hip_side[None])
        e1 = side - (side * axis).sum(1, keepdims=True) * axis
        bad = np.linalg.norm(e1, axis=1) < 1e-6
        if bad.any():  # bone parallel to the side direction: any perpendicular will do
            alt = np.where(np.abs(axis[bad, 1:2]) < 0.9, np.array([[0.0, 1, 0]]), np.array([[0.0, 0, 1]]))
            e1[bad] = np.cross(axis[bad], alt)
        e1 = _unit_rows(e1)
        e2 = np.cross(e1, axis)
        m = np.zeros((len(self.a), 4, 4))
        m[:, :3, 0], m[:, :3, 1], m[:, :3, 2] = e1, axis, e2
        m[:, :3, 3] = positions[self.a]
        m[:, 3, 3] = 1.0
        return m


def head_top(skeleton: Skeleton, positions: np.ndarray) -> np.ndarray | None:
    """(T, 3) top of the mannequin's head (the head ellipsoid's pole along the neck->head bone), or None."""
    parts = [p for p in mannequin_parts(skeleton) if p.name == "head"]
    if not parts:
        return None
    p = parts[0]
    d = _unit_rows(positions[:, p.b] - positions[:, p.a])
    return positions[:, p.a] + d * (p.y1 + p.ellipsoid[1])
