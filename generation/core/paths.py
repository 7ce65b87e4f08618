"""Walking paths on the ground plane.

A :class:`GroundPath` is a polyline on the x-z ground plane (y-up world, metres), parametrised by
arc length ``s`` (metres from the first point). Points are given as ``(x, z)`` pairs.

Heading convention: ``heading`` is the walking direction as an angle in radians about the +y
axis, measured from +z; 0 walks along +z and a positive heading turns toward +x (the body's
left side for an agent facing +z). A direction ``(dx, dz)`` has heading ``atan2(dx, dz)``, and the
root orientation of an agent walking with heading h is the rotation by h about +y, which maps
+z onto ``(sin h, 0, cos h)``.

Outside ``[0, length]`` the path continues straight along its first / last segment, so a walker
may start before the first point or run past the last one.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class GroundPath:
    """Arc-length-parametrised polyline on the ground.

    Attributes:
        points: (N, 2) float64 ``(x, z)`` vertices in metres, N >= 2, consecutive points distinct.
        kind: free-form label ("straight", "curved", "sharp_turn", "random", "custom").
    """

    points: np.ndarray = field(repr=False)
    kind: str = "custom"

    def __post_init__(self):
        pts = np.asarray(self.points, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise ValueError(f"GroundPath points must be (N, 2) (x, z) metres, got shape {pts.shape}")
        if not np.isfinite(pts).all():
            raise ValueError("GroundPath points contain NaN or infinite values")
        # Drop repeated vertices (zero-length segments have no direction).
        keep = np.ones(len(pts), dtype=bool)
        keep[1:] = np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-9
        pts = pts[keep]
        if len(pts) < 2:
            raise ValueError("GroundPath needs at least two distinct points")
        pts.setflags(write=False)
        object.__setattr__(self, "points", pts)
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        cum = np.concatenate(([0.0], np.cumsum(seg)))
        cum.setflags(write=False)
        object.__setattr__(self, "_cum", cum)

    # ---- construction ---------------------------------------------------------------------
    @classmethod
    def from_points(cls, points, kind: str = "custom") -> GroundPath:
        """Path through ``points`` (N, 2) ``(x, z)`` metres."""
        return cls(np.asarray(points, dtype=np.float64), kind)

    # ---- queries ---------------------------------------------------------------------------
    @property
    def length(self) -> float:
        """Arc length in metres."""
        return float(self._cum[-1])

    def _locate(self, s):
        s = np.asarray(s, dtype=np.float64)
        seg = np.clip(np.searchsorted(self._cum, s, side="right") - 1, 0, len(self.points) - 2)
        return s, seg

    def point_at(self, s) -> np.ndarray:
        """Ground point(s) at arc length ``s`` (scalar or array, metres) -> (..., 2) ``(x, z)``.

        Beyond either end the path is extended straight along the end segment.
        """
        s, seg = self._locate(s)
        p0 = self.points[seg]
        p1 = self.points[seg + 1]
        span = (self._cum[seg + 1] - self._cum[seg])[..., None]
        frac = (s - self._cum[seg])[..., None] / span
        return p0 + frac * (p1 - p0)

    def direction_at(self, s) -> np.ndarray:
        """Unit tangent(s) ``(dx, dz)`` at arc length ``s`` -> (..., 2)."""
        _, seg = self._locate(s)
        d = self.points[seg + 1] - self.points[seg]
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    def heading_at(self, s) -> np.ndarray:
        """Heading(s) in radians at arc length ``s`` (0 = +z, positive toward +x), shape of ``s``.

        Piecewise constant on a polyline: a sharp corner is a jump; :meth:`smoothed` rounds it.
        """
        d = self.direction_at(s)
        return np.arctan2(d[..., 0], d[..., 1])

    def resampled(self, spacing: float = 0.01, start: float = 0.0, stop: float | None = None) -> GroundPath:
        """Path through points every ``spacing`` metres from ``start`` to ``stop`` (may extend the ends)."""
        stop = self.length if stop is None else stop
        if not stop > start or not spacing > 0:
            raise ValueError(f"resampled needs stop > start and spacing > 0 (got {start}, {stop}, {spacing})")
        n = max(2, int(np.ceil((stop - start) / spacing)) + 1)
        return GroundPath(self.point_at(np.linspace(start, stop, n)), self.kind)

    def smoothed(self, sigma_m: float = 0.3, start: float | None = None, stop: float | None = None,
                 spacing: float = 0.01) -> GroundPath:
        """Corner-rounded copy: Gaussian blur of the points along arc length (sigma in metres).

        The straight extensions beyond the ends are included in the blur, so straight paths stay
        unchanged. The returned path starts at arc length ``start`` of this one (default 0) and
        its arc length restarts at 0 there.
        """
        start = 0.0 if start is None else start
        stop = self.length if stop is None else stop
        if sigma_m <= 0:
            return self.resampled(spacing, start, stop)
        pad = 4.0 * sigma_m
        s = np.arange(start - pad, stop + pad + spacing, spacing)
        pts = self.point_at(s)
        radius = int(np.ceil(pad / spacing))
        k = np.exp(-0.5 * (np.arange(-radius, radius + 1) * spacing / sigma_m) ** 2)
        k /= k.sum()
        blurred = np.stack([np.convolve(pts[:, i], k, mode="valid") for i in range(2)], axis=1)
        # 'valid' drops `radius` samples at each end, which is what the padding added.
        return GroundPath(blurred, self.kind)

    def __len__(self) -> int:  # pragma: no cover - convenience
        return len(self.points)


def _check_length(length_m: float) -> float:
    length_m = float(length_m)
    if not length_m > 0:
        raise ValueError(f"path length must be positive, got {length_m}")
    return length_m


def straight(length_m: float = 10.0, heading: float = 0.0) -> GroundPath:
    """Straight path from the origin, ``length_m`` metres long, along ``heading`` (0 = +z)."""
    length_m = _check_length(length_m)
    d = np.array([np.sin(heading), np.cos(heading)])
    return GroundPath(np.stack([np.zeros(2), length_m * d]), "straight")


def curved(radius_m: float, angle_rad: float, length_m: float | None = None) -> GroundPath:
    """Circular arc from the origin, starting along +z.

    Args:
        radius_m: arc radius in metres (> 0).
        angle_rad: total turn in radians; positive turns toward +x, negative toward -x.
        length_m: total path length; the arc (``radius_m * |angle_rad|`` metres) is followed by a
            straight run if ``length_m`` is longer; if shorter, the arc is cut at ``length_m``.
    """
    if not radius_m > 0:
        raise ValueError(f"curved: radius_m must be positive, got {radius_m}")
    arc = radius_m * abs(angle_rad)
    length_m = arc if length_m is None else _check_length(length_m)
    arc_used = min(arc, length_m)
    n = max(8, int(np.ceil(arc_used / 0.02)))
    sign = 1.0 if angle_rad >= 0 else -1.0
    theta = np.linspace(0.0, arc_used / radius_m, n)
    # Centre at (sign * r, 0): heading theta*sign at each point.
    pts = np.stack([sign * radius_m * (1.0 - np.cos(theta)), radius_m * np.sin(theta)], axis=1)
    if length_m > arc_used + 1e-9:
        h = sign * theta[-1]
        end = pts[-1] + (length_m - arc_used) * np.array([np.sin(h), np.cos(h)])
        pts = np.vstack([pts, end])
    return GroundPath(pts, "curved")


def sharp_turn(angle_rad: float, length_m: float = 10.0, at_fraction: float = 0.5) -> GroundPath:
    """Two straight legs joined by a corner of ``angle_rad`` (positive toward +x) at ``at_fraction``."""
    length_m = _check_length(length_m)
    if not 0.0 < at_fraction < 1.0:
        raise ValueError(f"sharp_turn: at_fraction must be in (0, 1), got {at_fraction}")
    if not abs(angle_rad) < np.pi:
        raise ValueError(f"sharp_turn: |angle_rad| must be below pi, got {angle_rad}")
    corner = np.array([0.0, at_fraction * length_m])
    end = corner + (1.0 - at_fraction) * length_m * np.array([np.sin(angle_rad), np.cos(angle_rad)])
    return GroundPath(np.stack([np.zeros(2), corner, end]), "sharp_turn")


PATH_KINDS = ("straight", "curved", "sharp_turn")


def path_from_spec(spec) -> GroundPath:
    """A GroundPath from a plan's trajectory mapping: ``kind`` (straight | curved | sharp_turn), ``length_m``;
    curves ``radius_m`` and ``angle_deg`` (swept, degrees); sharp turns ``angle_deg`` and ``at_fraction``."""
    kind, length = spec["kind"], spec["length_m"]
    if kind == "straight":
        return straight(length)
    if kind == "curved":
        return curved(spec["radius_m"], float(np.radians(spec["angle_deg"])), length)
    if kind == "sharp_turn":
        return sharp_turn(float(np.radians(spec["angle_deg"])), length, spec["at_fraction"])
    raise ValueError(f"unknown trajectory kind {kind!r} (straight, curved, sharp_turn)")


def random_path(rng: np.random.Generator, length_m: float = 10.0, kind: str | None = None) -> GroundPath:
    """A random straight, curved or sharp-turn path of ``length_m`` metres starting along +z.

    ``kind`` picks the family (one of :data:`PATH_KINDS`); by default it is drawn with
    probabilities 0.4 / 0.35 / 0.25. Curves have radius 2-8 m and turn 30-150 degrees either way;
    sharp turns 30-120 degrees either way at 30-70 % of the length.
    """
    length_m = _check_length(length_m)
    if kind is None:
        kind = str(rng.choice(PATH_KINDS, p=[0.4, 0.35, 0.25]))
    sign = 1.0 if rng.random() < 0.5 else -1.0
    if kind == "straight":
        return straight(length_m)
    if kind == "curved":
        radius = rng.uniform(2.0, 8.0)
        angle = sign * np.radians(rng.uniform(30.0, 150.0))
        arc = radius * abs(angle)
        # Start the arc after a random straight lead-in when there is room.
        lead = rng.uniform(0.0, max(0.0, length_m - arc) * 0.5)
        arc_path = curved(radius, angle, length_m - lead)
        pts = np.vstack([[0.0, 0.0], arc_path.points + [0.0, lead]]) if lead > 1e-3 else arc_path.points
        return GroundPath(pts, "curved")
    if kind == "sharp_turn":
        return sharp_turn(sign * np.radians(rng.uniform(30.0, 120.0)), length_m, rng.uniform(0.3, 0.7))
    raise ValueError(f"random_path: kind must be one of {PATH_KINDS}, got {kind!r}")
