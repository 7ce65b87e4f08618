"""The offscreen PyVista scenes: mannequin (default), stick figure or point-lights; ground grid, chair, camera.

Built once per clip; each frame only moves actors (``user_matrix``) and re-renders, as PyVista
0.49 returns stale images otherwise (REFERENCE.md section 8): one ``screenshot()`` during setup,
then ``render()`` + ``screenshot(return_img=True)`` per frame.
"""
from __future__ import annotations

import numpy as np

from generation.core.skeleton import Skeleton

from .body import MANNEQUIN_COLOUR, PartPoser, mannequin_parts, part_mesh
from .camera import CameraPose, project

LEFT_COLOUR = (0.16, 0.42, 0.85)    # blue
RIGHT_COLOUR = (0.90, 0.35, 0.12)   # orange
MID_COLOUR = (0.55, 0.55, 0.58)     # grey
CHAIR_COLOUR = (0.46, 0.52, 0.60)   # blue-grey (contrasts with the clay mannequin)
BACKGROUND = (0.93, 0.95, 0.98)
GROUND_COLOUR = (0.80, 0.80, 0.79)
GRID_COLOUR = (0.58, 0.58, 0.58)
SHADOW_COLOUR = (0.62, 0.62, 0.63)
GROUND_TILE_M = 0.5
GROUND_MARGIN_M = 25.0  # the floor reaches this far beyond the root's path: its edge stays out of view
#: Grid lines reach this far beyond the root's path; the floor beyond is plain. Far grid lines are denser than the
#: pixels and shimmer (moire) in a moving camera's frames, which also doubles the H.264 bitrate.
GRID_MARGIN_M = 8.0


SHADOW_RIM_POINTS = 12
"""Points on the floor shadow's rim that framing keeps in view."""


def _side_colour(name: str) -> tuple[float, float, float]:
    if name.startswith("left_"):
        return LEFT_COLOUR
    if name.startswith("right_"):
        return RIGHT_COLOUR
    return MID_COLOUR


def bone_matrices(start: np.ndarray, end: np.ndarray, radius: float | np.ndarray) -> np.ndarray:
    """(B, 4, 4) transforms mapping a unit cylinder (radius 1, y from 0 to 1) onto bones start->end.

    Args:
        start, end: (B, 3) metres.
        radius: scalar or (B,) metres.
    """
    vec = end - start
    length = np.linalg.norm(vec, axis=1)
    axis = vec / np.maximum(length, 1e-9)[:, None]
    # A helper vector not parallel to the bone gives the two perpendicular axes.
    helper = np.where(np.abs(axis[:, [0]]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 0, 1.0]]))
    e1 = np.cross(axis, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(e1, axis)
    r = np.broadcast_to(np.asarray(radius, dtype=float), length.shape)
    m = np.zeros((len(start), 4, 4))
    m[:, :3, 0] = e1 * r[:, None]
    m[:, :3, 1] = axis * length[:, None]
    m[:, :3, 2] = e2 * r[:, None]
    m[:, :3, 3] = start
    m[:, 3, 3] = 1.0
    return m


def chair_boxes(positions: np.ndarray, skeleton: Skeleton, facing: np.ndarray, ground_y: float,
                seat: tuple[float, float] | None = None) -> list[tuple]:
    """Boxes (centre (3,), half-sizes (3,) in the chair frame, yaw rotation) of a simple chair under a seated body.

    The seat top sits just under the lowest hip position over the clip, the backrest behind the
    pelvis, four legs down to the ground. Metres. ``seat``: (seat top height, backrest distance behind the
    root) fitted to a body's mesh instead (:func:`generation.render.human.seat_fit`).
    """
    s = skeleton.height / 1.75
    hips = [j for j, n in enumerate(skeleton.joints) if n.endswith("_hip")]
    hip_y = positions[:, hips, 1].min()
    root = positions[0, 0]
    seat_top = hip_y - 0.07 * s if seat is None else seat[0]
    seat_th = 0.04 * s
    right = np.cross(facing, np.array([0.0, 1.0, 0.0]))  # body's right
    # The backrest sits just behind the pelvis (a seated back touches it), the seat reaches toward the knees.
    half_w, depth_back, depth_front = 0.23 * s, (0.13 * s if seat is None else seat[1] + 0.005), 0.30 * s
    centre_z = (depth_front - depth_back) / 2
    boxes = []

    def add(local_centre, half):
        x, y, z = local_centre
        world = root * np.array([1, 0, 1]) + right * x + facing * z + np.array([0, y, 0])
        boxes.append((world, np.asarray(half, dtype=float)))

    add((0.0, seat_top - seat_th / 2, centre_z), (half_w, seat_th / 2, (depth_back + depth_front) / 2))
    back_h = 0.50 * s
    add((0.0, seat_top + back_h / 2, -depth_back - 0.02 * s), (half_w, back_h / 2, 0.02 * s))
    leg_h = max(seat_top - seat_th - ground_y, 0.0)
    for sx in (-1, 1):
        for sz in (-1, 1):
            z = centre_z + sz * ((depth_back + depth_front) / 2 - 0.03 * s)
            add((sx * (half_w - 0.03 * s), ground_y + leg_h / 2, z), (0.02 * s, leg_h / 2, 0.02 * s))
    yaw = np.arctan2(facing[0], facing[2])
    return [(c, h, yaw) for c, h in boxes]


class StickFigureScene:
    """An offscreen scene for one skeleton: tubes for bones, spheres for joints, ground grid, chair.

    Args:
        skeleton: the hierarchy (joint names tell left from right).
        width, height: pixels.
        anti_aliasing: "none", "fxaa", "ssaa2" or "msaa".
        ground_extent: (xmin, xmax, zmin, zmax) metres of the ground plane.
        ground_y: height of the ground, metres.
        chair: boxes from :func:`chair_boxes`, or None.
    """

    background = BACKGROUND
    show_ground = True  # floor, grid and chair

    def __init__(self, skeleton: Skeleton, width: int, height: int, anti_aliasing: str,
                 ground_extent: tuple[float, float, float, float], ground_y: float = 0.0,
                 chair: list[tuple] | None = None):
        import pyvista as pv  # heavy: VTK, loaded only when a scene is built

        self.skeleton = skeleton
        self.width, self.height = width, height
        self.ssaa = 2 if anti_aliasing == "ssaa2" else 1
        self.plotter = pv.Plotter(off_screen=True, window_size=[width * self.ssaa, height * self.ssaa])
        self.plotter.disable_anti_aliasing()
        if anti_aliasing == "fxaa":
            # VTK's own FXAA pass; PyVista's enable_anti_aliasing("fxaa") swaps in its costly SSAA on EGL builds.
            self.plotter.renderer.SetUseFXAA(True)
        elif anti_aliasing == "msaa":
            self.plotter.enable_anti_aliasing("msaa", multi_samples=4)
        self.plotter.set_background(self.background)
        s = skeleton.height / 1.75
        if self.show_ground:
            self._add_ground(pv, ground_extent, ground_y)
        if chair and self.show_ground:
            for centre, half, yaw in chair:
                box = pv.Box(bounds=(-half[0], half[0], -half[1], half[1], -half[2], half[2]))
                actor = self.plotter.add_mesh(box, color=CHAIR_COLOUR, smooth_shading=False)
                c, sn = np.cos(yaw), np.sin(yaw)
                m = np.array([[c, 0, sn, centre[0]], [0, 1, 0, centre[1]], [-sn, 0, c, centre[2]], [0, 0, 0, 1]])
                actor.user_matrix = m
        self.ground_y = ground_y
        self._build_figure(pv, s)
        self._primed = False

    def _build_figure(self, pv, s: float) -> None:
        """Tubes for bones, spheres for joints, an opaque shadow disc."""
        skeleton = self.skeleton
        # Bones: every joint with a parent and a non-zero offset.
        lengths = skeleton.bone_lengths()
        self.bones = [j for j, p in enumerate(skeleton.parents) if p >= 0 and lengths[j] > 1e-6]
        unit_cyl = pv.Cylinder(center=(0, 0.5, 0), direction=(0, 1, 0), radius=1.0, height=1.0, resolution=14,
                               capping=False)
        unit_sphere = pv.Sphere(radius=1.0, theta_resolution=16, phi_resolution=12)
        self.bone_actors = []
        for j in self.bones:
            actor = self.plotter.add_mesh(unit_cyl, color=_side_colour(skeleton.joints[j]), smooth_shading=True,
                                          specular=0.2)
            self.bone_actors.append(actor)
        self.bone_radius = np.array([0.022 * s] * len(self.bones))
        self.joint_radius = np.full(skeleton.num_joints, 0.03 * s)
        self.head = skeleton.joints.index("head") if "head" in skeleton.joints else None
        self.neck = skeleton.joints.index("neck") if "neck" in skeleton.joints else None
        if self.head is not None:
            self.joint_radius[self.head] = 0.10 * s
        self.joint_actors = []
        for name in skeleton.joints:
            actor = self.plotter.add_mesh(unit_sphere, color=_side_colour(name), smooth_shading=True, specular=0.2)
            self.joint_actors.append(actor)
        # A soft shadow disc under the pelvis helps read where the body is over the ground.
        # Opaque (a translucent one costs an extra blending pass in software GL).
        disc = pv.Disc(center=(0, 0, 0), inner=0.0, outer=1.0, normal=(0, 1, 0), c_res=32)
        self.shadow = self.plotter.add_mesh(disc, color=SHADOW_COLOUR, lighting=False)
        self.shadow_radius = 0.28 * s
        self._head_lift = max(0.02, 0.20 * s - (lengths[self.head] if self.head is not None else 0.0))

    def figure_actors(self) -> tuple:
        """The actors that move with the body (hidden for the background of patch rendering)."""
        return (*self.bone_actors, *self.joint_actors, self.shadow)

    def _add_ground(self, pv, extent, ground_y):
        """Unlit floor with grid lines every GROUND_TILE_M metres.

        Flat colour and line geometry instead of a lit, mipmapped texture: in software GL (llvmpipe)
        per-pixel lighting and trilinear texture sampling over the whole floor cost more than the figure.
        """
        xmin, xmax, zmin, zmax = extent
        # Snap the plane to whole tiles so the grid lines sit on round coordinates.
        xmin, zmin = np.floor(xmin / GROUND_TILE_M) * GROUND_TILE_M, np.floor(zmin / GROUND_TILE_M) * GROUND_TILE_M
        xmax, zmax = np.ceil(xmax / GROUND_TILE_M) * GROUND_TILE_M, np.ceil(zmax / GROUND_TILE_M) * GROUND_TILE_M
        plane = pv.Plane(center=((xmin + xmax) / 2, ground_y - 0.002, (zmin + zmax) / 2), direction=(0, 1, 0),
                         i_size=xmax - xmin, j_size=zmax - zmin, i_resolution=1, j_resolution=1)
        self.plotter.add_mesh(plane, color=GROUND_COLOUR, lighting=False)
        shrink = max(0.0, GROUND_MARGIN_M - GRID_MARGIN_M)
        xmin, xmax = (np.floor((xmin + shrink) / GROUND_TILE_M) * GROUND_TILE_M,
                      np.ceil((xmax - shrink) / GROUND_TILE_M) * GROUND_TILE_M)
        zmin, zmax = (np.floor((zmin + shrink) / GROUND_TILE_M) * GROUND_TILE_M,
                      np.ceil((zmax - shrink) / GROUND_TILE_M) * GROUND_TILE_M)
        xs = np.arange(xmin, xmax + 1e-6, GROUND_TILE_M)
        zs = np.arange(zmin, zmax + 1e-6, GROUND_TILE_M)
        pts = np.concatenate([
            np.stack([np.repeat(xs, 2), np.full(2 * len(xs), ground_y), np.tile([zmin, zmax], len(xs))], axis=1),
            np.stack([np.tile([xmin, xmax], len(zs)), np.full(2 * len(zs), ground_y), np.repeat(zs, 2)], axis=1),
        ])
        n = len(pts) // 2
        cells = np.column_stack([np.full(n, 2), 2 * np.arange(n), 2 * np.arange(n) + 1]).ravel()
        grid = pv.PolyData(pts, lines=cells)
        self.plotter.add_mesh(grid, color=GRID_COLOUR, line_width=1.5, lighting=False)

    def set_camera(self, pose: CameraPose) -> None:
        cam = self.plotter.camera
        cam.position = tuple(pose.position)
        cam.focal_point = tuple(pose.focal_point)
        cam.up = tuple(pose.view_up)
        cam.view_angle = pose.view_angle
        # Near/far planes from the scene, not from VTK's automatic reset (which lags moving cameras).
        self.plotter.renderer.ResetCameraClippingRange()

    def set_pose(self, positions: np.ndarray) -> None:
        """Move the figure to joint positions (J, 3) metres."""
        parents = self.skeleton.parents
        start = positions[[parents[j] for j in self.bones]]
        end = positions[self.bones]
        mats = bone_matrices(start, end, self.bone_radius)
        for actor, m in zip(self.bone_actors, mats):
            actor.user_matrix = m
        centres = positions.copy()
        if self.head is not None and self.neck is not None:
            d = positions[self.head] - positions[self.neck]
            centres[self.head] = positions[self.head] + d / max(np.linalg.norm(d), 1e-9) * self._head_lift
        for actor, c, r in zip(self.joint_actors, centres, self.joint_radius):
            actor.user_matrix = np.array([[r, 0, 0, c[0]], [0, r, 0, c[1]], [0, 0, r, c[2]], [0, 0, 0, 1.0]])
        rs, root = self.shadow_radius, positions[0]
        self.shadow.user_matrix = np.array([[rs, 0, 0, root[0]], [0, 1, 0, self.ground_y + 0.001],
                                            [0, 0, rs, root[2]], [0, 0, 0, 1.0]])

    def set_frame(self, t: int, positions: np.ndarray) -> None:
        """Move the figure to frame ``t`` of the clip, whose joint positions are ``positions`` (J, 3) metres (a
        figure posed ahead of time, the human body, uses ``t``; the others the positions)."""
        self.set_pose(positions)

    def frame(self) -> np.ndarray:
        """Render and return the current image, (height, width, 3) uint8."""
        if not self._primed:
            # The first screenshot initialises the offscreen buffers (REFERENCE.md section 8).
            self.plotter.screenshot(return_img=True)
            self._primed = True
        self.plotter.renderer.ResetCameraClippingRange()
        self.plotter.render()
        img = np.asarray(self.plotter.screenshot(return_img=True))[..., :3]
        return self._downsample(img)

    def _downsample(self, img: np.ndarray) -> np.ndarray:
        """Average ssaa x ssaa pixel blocks (integer arithmetic, rounded)."""
        if self.ssaa > 1:
            k = self.ssaa
            blocks = img.reshape(self.height, k, self.width, k, 3).sum(axis=(1, 3), dtype=np.uint16)
            img = ((blocks + (k * k) // 2) // (k * k)).astype(np.uint8)
        return np.ascontiguousarray(img)

    # ---- patch rendering for a fixed camera ----------------------------------------------------
    def _body_spheres(self, positions: np.ndarray, joints: np.ndarray, shadow: bool
                      ) -> tuple[np.ndarray, np.ndarray]:
        """Bounding spheres (centres (T, K, 3), radii (K,)) of the selected joints (J,) bool, the head if
        selected, and the shadow disc if ``shadow``."""
        centres = [positions[:, joints]]
        radii = [np.maximum(self.joint_radius[joints], self.bone_radius.max()) + 0.01]
        if self.head is not None and self.neck is not None and joints[self.head]:
            d = positions[:, self.head] - positions[:, self.neck]
            head = positions[:, self.head] + d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9) * \
                self._head_lift
            centres.append(head[:, None])
            radii.append(np.array([self.joint_radius[self.head] + 0.01]))
        if shadow:
            centres.append(self._shadow_rim(positions))
            radii.append(np.full(SHADOW_RIM_POINTS, 0.01))
        return np.concatenate(centres, axis=1), np.concatenate(radii)

    def _shadow_rim(self, positions: np.ndarray) -> np.ndarray:
        """(T, SHADOW_RIM_POINTS, 3) points on the rim of the floor shadow under the root of ``positions`` (T, J, 3)."""
        angles = np.linspace(0, 2 * np.pi, SHADOW_RIM_POINTS, endpoint=False)
        ring = np.stack([np.cos(angles), np.zeros_like(angles), np.sin(angles)], 1) * self.shadow_radius
        return positions[:, :1] * np.array([1, 0, 1]) + np.array([0, self.ground_y, 0]) + ring[None]

    def _screen_boxes(self, centres: np.ndarray, radii: np.ndarray, pose: CameraPose, W: int, H: int):
        """Per-frame pixel boxes (lo (T, 2), hi (T, 2)) around spheres, or None if one is behind the camera."""
        T, K = centres.shape[:2]
        if K == 0:
            return np.full((T, 2), W / 2), np.full((T, 2), W / 2)
        px, depth, f = project(centres.reshape(-1, 3), pose, W, H)
        if (depth <= 0.05).any():
            return None
        rpx = (np.tile(radii, T) * f / depth)[:, None]
        return (px - rpx).reshape(T, K, 2).min(1), (px + rpx).reshape(T, K, 2).max(1)

    def plan_patches(self, positions: np.ndarray, pose: CameraPose, margin_px: int = 6,
                     max_fraction: float = 0.8) -> bool:
        """Prepare to render only the changing part of each frame (fixed camera only).

        A background is rendered once; each frame then renders a window just big enough for what moves,
        with the same projection as that region of the full frame (off-axis camera: ``SetWindowCenter``
        and a narrower view angle), and pastes it in, so per-pixel work (anti-aliasing above all) only
        runs over the patch. Two cases:

        - the body travels (a walk): the background is the scene without the figure and its shadow, and
          the patch covers the whole figure and shadow;
        - the root stays put (a seated gesture): the background holds the figure in its first pose, and
          the patch covers the joints that move (and the bones touching them) in the first pose and now.

        Returns False (and renders whole frames) when the patch would cover more than ``max_fraction`` of
        the frame, where it would not save time.

        Args:
            positions: (T, J, 3) joint positions of the whole clip.
            pose: the fixed camera.
        """
        W, H = self.width * self.ssaa, self.height * self.ssaa
        travels = float(np.ptp(positions[:, 0], axis=0).max()) > 0.01
        if travels:
            joints = np.ones(self.skeleton.num_joints, dtype=bool)
        else:
            moving = np.linalg.norm(positions - positions[:1], axis=-1).max(0) > 0.002
            joints = moving.copy()
            for j, p in enumerate(self.skeleton.parents):
                if p >= 0 and (moving[j] or moving[p]):
                    joints[j] = joints[p] = True
        centres, radii = self._body_spheres(positions, joints, shadow=travels)
        boxes = self._screen_boxes(centres, radii, pose, W, H)
        if boxes is None:
            return False
        lo, hi = boxes
        if not travels:  # the first pose must be erased from the background too
            lo, hi = np.minimum(lo, lo[:1]), np.maximum(hi, hi[:1])
        lo, hi = lo - margin_px * self.ssaa, hi + margin_px * self.ssaa
        size = np.maximum(np.ceil((hi - lo).max(0)).astype(int), 16)
        size += size % 2
        if size[0] * size[1] > max_fraction * W * H or size[0] >= W or size[1] >= H:
            return False
        self._patch_size = (int(size[0]), int(size[1]))
        centre = (lo + hi) / 2
        x0 = np.clip(np.round(centre[:, 0] - size[0] / 2), 0, W - size[0]).astype(int)
        y0 = np.clip(np.round(centre[:, 1] - size[1] / 2), 0, H - size[1]).astype(int)
        self._patch_origin = np.stack([x0, y0], 1)
        self._patch_pose = pose
        self.set_camera(pose)
        figure = self.figure_actors()
        if travels:
            for actor in figure:
                actor.visibility = False
            self._background = self._render_full()
            for actor in figure:
                actor.visibility = True
        else:
            self.set_frame(0, positions[0])
            self._background = self._render_full()
        self.plotter.render_window.SetSize(*self._patch_size)
        return True

    def _render_full(self) -> np.ndarray:
        if not self._primed:
            # The first screenshot initialises the offscreen buffers (REFERENCE.md section 8).
            self.plotter.screenshot(return_img=True)
            self._primed = True
        self.plotter.renderer.ResetCameraClippingRange()
        self.plotter.render()
        return np.asarray(self.plotter.screenshot(return_img=True))[..., :3]

    def frame_patch(self, t: int) -> np.ndarray:
        """Frame ``t`` of a clip prepared by :meth:`plan_patches` (after :meth:`set_pose`)."""
        W, H = self.width * self.ssaa, self.height * self.ssaa
        w, h = self._patch_size
        x0, y0 = self._patch_origin[t]
        cam = self.plotter.camera
        pose = self._patch_pose
        # Off-axis projection of the patch: same pixel scale as the full frame, centre shifted.
        cam.view_angle = float(np.degrees(2 * np.arctan(np.tan(np.radians(pose.view_angle) / 2) * h / H)))
        dx = (x0 + w / 2) - W / 2
        dy = H / 2 - (y0 + h / 2)
        cam.SetWindowCenter(dx / (w / 2), dy / (h / 2))
        self.plotter.renderer.ResetCameraClippingRange()
        self.plotter.render()
        patch = np.asarray(self.plotter.screenshot(return_img=True))[..., :3]
        img = self._background.copy()
        m = 2 * self.ssaa  # screen-space AA sees the patch edge; keep the background's border pixels
        img[y0 + m:y0 + h - m, x0 + m:x0 + w - m] = patch[m:h - m, m:w - m]
        return self._downsample(img)

    def close(self) -> None:
        self.plotter.close()


#: The mannequin's ground shadow: the floor colour darkened as a 28 % black overlay would, drawn opaque between the
#: floor and the grid lines (a translucent disc costs a blending pass over the frame in software GL).
SHADOW_OVERLAY = 0.28
MANNEQUIN_SHADOW_COLOUR = tuple((1.0 - SHADOW_OVERLAY) * c for c in GROUND_COLOUR)


class MannequinScene(StickFigureScene):
    """The default look: a low-poly humanoid mannequin (:mod:`generation.render.body`), matte clay colour,
    a soft dark ellipse as its ground shadow, on the same floor grid (and chair) as the sticks.

    The part meshes are built once from the skeleton's bone lengths and merged into one mesh (one actor, one
    draw call); each frame computes one rigid transform per part and rewrites the merged mesh's points and
    normals in place (no actors or buffers are rebuilt).
    """

    def _build_figure(self, pv, s: float) -> None:
        self.parts = mannequin_parts(self.skeleton)
        self.poser = PartPoser(self.skeleton, self.parts)
        meshes = [part_mesh(part) for part in self.parts]
        self._base_points = np.concatenate([np.asarray(m.points, dtype=float) for m in meshes])   # (N, 3)
        self._base_normals = np.concatenate([np.asarray(m.point_data["Normals"], dtype=float) for m in meshes])
        self._point_part = np.repeat(np.arange(len(meshes)), [m.n_points for m in meshes])          # (N,)
        body = pv.merge(meshes, merge_points=False)
        body.point_data["Normals"] = self._base_normals.copy()  # VTK would share (and we overwrite) the array
        body.point_data.active_normals_name = "Normals"
        actor = self.plotter.add_mesh(body, color=MANNEQUIN_COLOUR, smooth_shading=True, specular=0.0, diffuse=0.85,
                                      ambient=0.22)
        self.body_mesh = actor.mapper.dataset
        self.part_actors = [actor]
        disc = pv.Disc(center=(0, 0, 0), inner=0.0, outer=1.0, normal=(0, 1, 0), c_res=32)
        self.shadow = self.plotter.add_mesh(disc, color=MANNEQUIN_SHADOW_COLOUR, lighting=False)
        self.shadow_radius = 0.32 * s
        j = self.skeleton.joints
        self._hips = (j.index("left_hip"), j.index("right_hip")) if "left_hip" in j else None
        # Bounding radius around every joint for patch planning: each mesh point counts for the nearer end of its
        # part's bone, so the boxes of these spheres hold every part (hands beyond the wrist, the head's top).
        self.joint_radius = self._joint_radii(meshes) + 0.02 * s
        self.bone_radius = np.array([0.03 * s])
        self.head = self.neck = None
        self.bones, self.bone_actors, self.joint_actors = [], [], []

    def _joint_radii(self, meshes) -> np.ndarray:
        """(J,) metres: per joint, the farthest mesh point of the parts on its bones that is nearer to it than to the
        bone's other end (part frames: joint ``a`` at the origin, ``b`` on +y at the rest distance)."""
        rest = self.skeleton.rest_positions()
        radius = np.zeros(self.skeleton.num_joints)
        for part, mesh in zip(self.parts, meshes):
            pts = np.asarray(mesh.points)
            end = np.array([0.0, np.linalg.norm(rest[part.b] - rest[part.a]), 0.0])
            da, db = np.linalg.norm(pts, axis=1), np.linalg.norm(pts - end, axis=1)
            near_a = da <= db
            radius[part.a] = max(radius[part.a], da[near_a].max(initial=0.0))
            radius[part.b] = max(radius[part.b], db[~near_a].max(initial=0.0))
        return radius

    def figure_actors(self) -> tuple:
        return (*self.part_actors, self.shadow)

    def set_pose(self, positions: np.ndarray) -> None:
        mats = self.poser.matrices(positions)[self._point_part]                     # (N, 4, 4)
        rot = mats[:, :3, :3]
        points = np.einsum("nij,nj->ni", rot, self._base_points) + mats[:, :3, 3]
        normals = np.einsum("nij,nj->ni", rot, self._base_normals)
        mesh = self.body_mesh
        mesh.points[:] = points                     # in place: the mapper re-uploads the same buffers
        mesh.point_data["Normals"][:] = normals
        mesh.GetPoints().Modified()
        mesh.GetPointData().GetNormals().Modified()
        mesh.Modified()
        root = positions[0]
        side = positions[self._hips[0]] - positions[self._hips[1]] if self._hips else np.array([1.0, 0, 0])
        side = np.array([side[0], 0.0, side[2]])
        side = side / max(np.linalg.norm(side), 1e-9) if np.linalg.norm(side) > 1e-6 else np.array([1.0, 0, 0])
        fwd = np.cross(side, [0.0, 1.0, 0.0])
        rs = self.shadow_radius
        m = np.eye(4)
        m[:3, 0], m[:3, 2] = side * rs, fwd * rs * 0.72
        m[:3, 3] = (root[0], self.ground_y - 0.001, root[2])   # above the floor, under the grid lines
        self.shadow.user_matrix = m


POINT_COLOUR = (1.0, 1.0, 1.0)


class PointLightScene(StickFigureScene):
    """A point-light display (Johansson 1973): white dots at the joints on black, no floor, grid or chair."""

    background = (0.0, 0.0, 0.0)
    show_ground = False

    def _build_figure(self, pv, s: float) -> None:
        dot = pv.Sphere(radius=1.0, theta_resolution=12, phi_resolution=8)
        self.dot_radius = 0.03 * s
        self.joint_actors = [self.plotter.add_mesh(dot, color=POINT_COLOUR, lighting=False)
                             for _ in self.skeleton.joints]
        self.bone_radius = np.array([self.dot_radius])
        self.joint_radius = np.full(self.skeleton.num_joints, self.dot_radius)
        self.shadow_radius = 0.0
        self.head = self.neck = None
        self.bones, self.bone_actors = [], []

    def figure_actors(self) -> tuple:
        return tuple(self.joint_actors)

    def set_pose(self, positions: np.ndarray) -> None:
        r = self.dot_radius
        for actor, c in zip(self.joint_actors, positions):
            actor.user_matrix = np.array([[r, 0, 0, c[0]], [0, r, 0, c[1]], [0, 0, r, c[2]], [0, 0, 0, 1.0]])


SCENES = {"mannequin": MannequinScene, "stick": StickFigureScene, "points": PointLightScene}
