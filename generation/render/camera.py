"""Camera placement: a fixed camera that frames a whole motion, or one that tracks the root.

All positions are metres, y-up. A camera is (position, focal_point, view_up) plus VTK's vertical
view angle in degrees. Pure numpy: no VTK here, so it is quick to test.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

UP = np.array([0.0, 1.0, 0.0])
SHORT_PATH_M = 6.0


@dataclass(frozen=True)
class CameraPose:
    position: np.ndarray   # (3,) metres
    focal_point: np.ndarray  # (3,) metres
    view_up: tuple = (0.0, 1.0, 0.0)
    view_angle: float = 30.0  # vertical field of view, degrees


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v)
    return v / n if n > 1e-12 else v


def facing_direction(root_rotation: np.ndarray) -> np.ndarray:
    """Horizontal unit vector the body faces (+z rotated by the root quaternion w,x,y,z)."""
    w, x, y, z = root_rotation
    # Third column of the rotation matrix = R·(0,0,1).
    fwd = np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])
    fwd[1] = 0.0
    if np.linalg.norm(fwd) < 1e-6:
        return np.array([0.0, 0.0, 1.0])
    return _unit(fwd)


def travel_direction(root_xz: np.ndarray) -> np.ndarray | None:
    """Principal horizontal direction of a root path (T, 2) oriented start->end, or None if it stays put."""
    if root_xz.shape[0] < 2:
        return None
    span = root_xz.max(0) - root_xz.min(0)
    if np.linalg.norm(span) < 0.5:
        return None
    centred = root_xz - root_xz.mean(0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    axis = vt[0]
    if np.dot(root_xz[-1] - root_xz[0], axis) < 0:
        axis = -axis
    return _unit(np.array([axis[0], 0.0, axis[1]]))


def view_offset(forward: np.ndarray, azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """Unit vector from the focal point to the camera.

    ``azimuth_deg`` is measured from the side (perpendicular to ``forward``, on the body's left)
    towards ``forward``: 0 looks at the left side, 90 looks at the front.
    """
    side = _unit(np.cross(UP, forward))  # body's left when forward is +z (left = +x)
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    horiz = np.cos(az) * side + np.sin(az) * forward
    return _unit(np.cos(el) * horiz + np.sin(el) * UP)


def fit_distance(points: np.ndarray, focal: np.ndarray, offset: np.ndarray, view_angle_deg: float,
                 aspect: float, margin: float = 1.08) -> float:
    """Smallest camera distance along ``offset`` from ``focal`` that keeps all ``points`` (N, 3) in view.

    For a point p relative to the focal point, with view direction d = -offset, right r and up u:
    depth = dist + (p-f)·d; it is inside when |(p-f)·r| <= depth·tan(hfov/2) and likewise for u.
    """
    d = -offset
    r = _unit(np.cross(d, UP))
    u = np.cross(r, d)
    rel = points - focal
    tv = np.tan(np.radians(view_angle_deg) / 2) / margin
    th = tv * aspect
    need = np.maximum(np.abs(rel @ r) / th, np.abs(rel @ u) / tv) - rel @ d
    return float(max(need.max(), 0.5))


def fixed_camera(positions: np.ndarray, root_rotation0: np.ndarray, aspect: float, azimuth_deg: float | None = None,
                 elevation_deg: float = 8.0, view_angle: float = 30.0, extra_points: np.ndarray | None = None
                 ) -> CameraPose:
    """One camera for the whole clip that keeps every joint of every frame in view.

    Args:
        positions: (T, J, 3) joint positions, metres.
        root_rotation0: (4,) root quaternion of the first frame (decides the side for in-place motion).
        aspect: width / height of the video.
        azimuth_deg: angle from the side view towards the front; by default a walk shorter than
            SHORT_PATH_M gets 30 (three-quarter side view), a longer one the angle in 40..60 that shows
            the body largest while the whole path is in view, and in-place motion 65 (front-left).
        extra_points: (N, 3) more points to keep in view (a chair).
    """
    pts = positions.reshape(-1, 3)
    # Joints are centres: pad for the head sphere above and the limbs' thickness around.
    pad = np.array([[0.0, 0.2, 0.0], [0.08, 0.0, 0.0], [-0.08, 0.0, 0.0], [0.0, 0.0, 0.08], [0.0, 0.0, -0.08],
                    [0.0, -0.05, 0.0]])
    pts = (pts[:, None, :] + pad[None]).reshape(-1, 3)
    if extra_points is not None:
        pts = np.concatenate([pts, extra_points.reshape(-1, 3)])
    focal = (pts.min(0) + pts.max(0)) / 2
    travel = travel_direction(positions[:, 0, [0, 2]])
    if travel is None:
        forward = facing_direction(root_rotation0)
        offset = view_offset(forward, 65.0 if azimuth_deg is None else azimuth_deg, elevation_deg)
        focal, dist = _centred_fit(pts, focal, offset, view_angle, aspect)
        return CameraPose(focal + offset * dist, focal, view_angle=view_angle)
    # A walk: from ahead of the path. A short path (a few walk cycles) is seen three-quarter from the side,
    # where stride and arm swing read best; on a long path, the azimuth that shows the body largest on
    # average while the whole path stays in view (a long path seen side-on leaves a tiny figure).
    extent = float(np.linalg.norm(np.ptp(positions[:, 0, [0, 2]], axis=0)))
    if azimuth_deg is not None:
        candidates = [azimuth_deg]
    elif extent < SHORT_PATH_M:
        candidates = [30.0]
    else:
        candidates = list(range(40, 61, 5))
    body = positions[:, 0]
    best = None
    for az in candidates:
        offset = view_offset(travel, az, elevation_deg)
        f, dist = _centred_fit(pts, focal, offset, view_angle, aspect)
        depth = (body - (f + offset * dist)) @ (-offset)
        size = float(np.mean(1.0 / np.maximum(depth, 1e-3)))
        if best is None or size > best[0]:
            best = (size, f, offset, dist)
    _, focal, offset, dist = best
    return CameraPose(focal + offset * dist, focal, view_angle=view_angle)


def _centred_fit(points: np.ndarray, focal: np.ndarray, offset: np.ndarray, view_angle: float, aspect: float,
                 iterations: int = 4) -> tuple[np.ndarray, float]:
    """Focal point and distance that frame ``points`` with their projection centred in the image.

    The bounding-box centre is not the centre of the projected points under perspective (near parts
    look bigger), so the focal point is moved across the view until the projected extents are
    symmetric, refitting the distance each time.
    """
    d = -offset
    r = _unit(np.cross(d, UP))
    u = np.cross(r, d)
    tv = np.tan(np.radians(view_angle) / 2)
    dist = fit_distance(points, focal, offset, view_angle, aspect)
    for _ in range(iterations):
        cam = focal + offset * dist
        rel = points - cam
        depth = np.maximum(rel @ d, 1e-3)
        x, y = (rel @ r) / depth, (rel @ u) / depth        # tangent-plane coordinates
        cx, cy = (x.max() + x.min()) / 2, (y.max() + y.min()) / 2
        if abs(cx) < 0.002 * tv and abs(cy) < 0.002 * tv:
            break
        focal = focal + dist * (cx * r + cy * u)
        dist = fit_distance(points, focal, offset, view_angle, aspect)
    return focal, dist


def project(points: np.ndarray, pose: CameraPose, width: int, height: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Pixel coordinates of points (N, 3) seen by ``pose`` in a width x height image.

    Returns (N, 2) pixel positions (x to the right, y down, pixel centres at +0.5), (N,) depths in metres
    along the view direction, and the focal length in pixels.
    """
    d = _unit(np.asarray(pose.focal_point, float) - np.asarray(pose.position, float))
    r = _unit(np.cross(d, np.asarray(pose.view_up, float)))
    u = np.cross(r, d)
    rel = points - np.asarray(pose.position, float)
    depth = rel @ d
    f = (height / 2) / np.tan(np.radians(pose.view_angle) / 2)
    safe = np.maximum(depth, 1e-6)
    px = np.stack([width / 2 + f * (rel @ r) / safe, height / 2 - f * (rel @ u) / safe], axis=1)
    return px, depth, float(f)


#: Smallest figure height as a fraction of the frame height, in every frame.
MIN_FIGURE_FRACTION = {"walk": 0.50, "seated": 0.60}
#: What the follow camera aims for (the whole body stays in frame first).
FOLLOW_TARGET_FRACTION = {"walk": 0.70, "seated": 0.78}


def figure_fractions(points: np.ndarray, poses: list[CameraPose], width: int, height: int
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame projected figure height / frame height, and per-frame pixel boxes (T, 4) x0, y0, x1, y1.

    Args:
        points: (T, K, 3) points of the body's outline (joints padded by the body's thickness, head top).
        poses: T camera poses (or one repeated).
    """
    T = points.shape[0]
    boxes = np.zeros((T, 4))
    for t in range(T):
        px, _, _ = project(points[t], poses[t if len(poses) > 1 else 0], width, height)
        boxes[t] = (px[:, 0].min(), px[:, 1].min(), px[:, 0].max(), px[:, 1].max())
    return (boxes[:, 3] - boxes[:, 1]) / height, boxes


def critically_damped(x: np.ndarray, fps: float, omega: float) -> np.ndarray:
    """Zero-phase critically damped smoothing of a (T, D) signal.

    A second-order critically damped follower (x'' = w^2 (target - x) - 2 w x') run forward and then
    backward over the forward result: no overshoot, no jitter, no lag (the backward pass undoes the
    forward pass's delay).
    """
    def run(sig):
        dt = 1.0 / fps
        out = np.empty_like(sig)
        pos = sig[0].copy()
        vel = (sig[min(1, len(sig) - 1)] - sig[0]) / dt
        for t in range(len(sig)):
            acc = omega * omega * (sig[t] - pos) - 2 * omega * vel
            vel = vel + acc * dt
            pos = pos + vel * dt
            out[t] = pos
        return out

    x = np.asarray(x, dtype=float)
    if len(x) < 2:
        return x.copy()
    # Extend both ends along the local velocity (over half a second) by several time constants, so the
    # follower has settled onto the motion when the clip starts and ends.
    n_pad = int(np.ceil(8.0 / omega * fps))
    k = max(1, min(len(x) - 1, int(round(0.5 * fps))))
    v0, v1 = (x[k] - x[0]) / k, (x[-1] - x[-1 - k]) / k
    steps = np.arange(1, n_pad + 1)[:, None]
    padded = np.concatenate([x[0] - v0 * steps[::-1], x, x[-1] + v1 * steps])
    return run(run(padded)[::-1])[::-1][n_pad:n_pad + len(x)]


def follow_cameras(positions: np.ndarray, outline: np.ndarray, fps: float, width: int, height: int,
                   kind: str = "walk", azimuth_deg: float = 35.0, elevation_deg: float = 12.0,
                   view_angle: float = 30.0, omega: float = 2.5, facing: np.ndarray | None = None
                   ) -> list[CameraPose]:
    """A camera per frame that follows the body at a fixed world-space offset and distance.

    The look-at point is the root's ground track smoothed by :func:`critically_damped` (zero phase),
    at a constant height; the view direction comes from the clip's travel direction (or the body's
    facing for in-place motion), ``azimuth_deg`` from the side towards the front, ``elevation_deg``
    above the horizon so the floor grid shows the motion over the ground. The distance is the
    closest that keeps the whole outline in frame (with a margin) in every frame, starting from the
    one that makes the figure FOLLOW_TARGET_FRACTION of the frame height.

    Args:
        positions: (T, J, 3) joints; outline: (T, K, 3) body outline points (see :func:`figure_fractions`).
    """
    T = positions.shape[0]
    root = positions[:, 0]
    travel = travel_direction(root[:, [0, 2]])
    if travel is None:
        # In place: from the body's front-left, as the fixed camera does.
        forward = facing if facing is not None else np.array([0.0, 0.0, 1.0])
        azimuth_deg = 65.0
    else:
        forward = travel
    offset = view_offset(forward, azimuth_deg, elevation_deg)
    lo_y, hi_y = outline[..., 1].min(), outline[..., 1].max()
    track = critically_damped(root[:, [0, 2]], fps, omega)
    focal = np.stack([track[:, 0], np.full(T, (lo_y + hi_y) / 2), track[:, 1]], 1)
    body_h = float(np.median(np.ptp(outline[..., 1], axis=1)))
    tv = np.tan(np.radians(view_angle) / 2)
    dist = body_h / (2 * tv * FOLLOW_TARGET_FRACTION[kind])
    margin = 0.04  # of the frame, on every side
    for _ in range(40):
        poses = [CameraPose(focal[t] + offset * dist, focal[t], view_angle=view_angle) for t in range(T)]
        _, boxes = figure_fractions(outline, poses, width, height)
        inside = (boxes[:, 0] >= margin * width).all() and (boxes[:, 2] <= (1 - margin) * width).all() and \
            (boxes[:, 1] >= margin * height).all() and (boxes[:, 3] <= (1 - margin) * height).all()
        if inside:
            break
        dist *= 1.05
    return poses


def body_outline(positions: np.ndarray, head_top: np.ndarray | None, thickness: float) -> np.ndarray:
    """(T, K, 3) points around the body: every joint padded up/down/sideways by ``thickness`` metres,
    plus the head top when given."""
    pad = np.array([[0, 0, 0], [0, 1, 0], [0, -1, 0], [1, 0, 0], [-1, 0, 0], [0, 0, 1], [0, 0, -1]],
                   dtype=float) * thickness
    pts = (positions[:, :, None, :] + pad[None, None]).reshape(positions.shape[0], -1, 3)
    if head_top is not None:
        pts = np.concatenate([pts, head_top[:, None]], axis=1)
    return pts


def choose_cameras(positions: np.ndarray, root_rotation0: np.ndarray, outline: np.ndarray, fps: float,
                   width: int, height: int, mode: str = "auto", seated: bool = False,
                   extra_points: np.ndarray | None = None) -> tuple[list[CameraPose], dict]:
    """The clip's cameras and the rule that chose them.

    ``mode`` "auto": the fixed camera fitted to the whole clip (:func:`fixed_camera`) when the figure is at
    least MIN_FIGURE_FRACTION (+ 0.03 to spare) of the frame height in every frame, else the follow camera
    (:func:`follow_cameras`). "fixed" and "tracking" force one. Returns (T poses, info) where info holds
    ``rule`` ("fixed" or "follow"), ``min_figure_fraction`` and ``max_figure_fraction`` (projected).
    """
    T = positions.shape[0]
    kind = "seated" if seated else "walk"
    need = MIN_FIGURE_FRACTION[kind]
    cams = None
    rule = "follow"
    if mode in ("auto", "fixed"):
        pts = outline.reshape(-1, 3)
        if extra_points is not None:
            pts = np.concatenate([pts, extra_points.reshape(-1, 3)])
        cam = fixed_camera(positions, root_rotation0, width / height, extra_points=pts)
        frac, _ = figure_fractions(outline, [cam], width, height)
        if mode == "fixed" or frac.min() >= need + 0.03:
            cams, rule = [cam] * T, "fixed"
    if cams is None:
        cams = follow_cameras(positions, outline, fps, width, height, kind,
                              facing=facing_direction(root_rotation0))
    frac, _ = figure_fractions(outline, cams, width, height)
    return cams, {"rule": rule, "min_figure_fraction": round(float(frac.min()), 3),
                  "max_figure_fraction": round(float(frac.max()), 3), "required_fraction": need}
