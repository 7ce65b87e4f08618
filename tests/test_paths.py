"""Ground paths: arc length, heading convention, factories, corner rounding."""
import numpy as np
import pytest

from generation.core import paths
from generation.core.paths import GroundPath


def test_straight_length_points_and_heading():
    p = paths.straight(10.0)
    assert p.length == pytest.approx(10.0)
    np.testing.assert_allclose(p.point_at(4.0), [0.0, 4.0])
    assert p.heading_at(3.0) == pytest.approx(0.0)
    # heading pi/2 walks toward +x
    q = paths.straight(5.0, heading=np.pi / 2)
    np.testing.assert_allclose(q.point_at(5.0), [5.0, 0.0], atol=1e-12)
    assert q.heading_at(1.0) == pytest.approx(np.pi / 2)


def test_point_at_is_vectorised_and_extends_past_the_ends():
    p = paths.straight(2.0)
    pts = p.point_at(np.array([[-1.0, 0.5], [2.0, 3.0]]))
    assert pts.shape == (2, 2, 2)
    np.testing.assert_allclose(pts[0, 0], [0.0, -1.0])
    np.testing.assert_allclose(pts[1, 1], [0.0, 3.0])


def test_curved_arc_geometry_and_turn_direction():
    r, ang = 3.0, np.pi / 2
    p = paths.curved(r, ang)
    assert p.length == pytest.approx(r * ang, rel=1e-3)
    end = p.point_at(p.length)
    np.testing.assert_allclose(end, [r, r], atol=1e-6)          # quarter circle turning toward +x
    assert p.heading_at(p.length - 1e-3) == pytest.approx(ang, abs=0.01)
    left = paths.curved(r, -ang, length_m=10.0)
    assert left.length == pytest.approx(10.0, rel=1e-3)
    assert left.point_at(left.length)[0] < 0                    # negative angle turns toward -x
    assert left.heading_at(left.length) == pytest.approx(-ang, abs=0.01)


def test_sharp_turn_corner():
    p = paths.sharp_turn(np.radians(90), 10.0, at_fraction=0.3)
    np.testing.assert_allclose(p.point_at(3.0), [0.0, 3.0])
    assert p.heading_at(2.0) == pytest.approx(0.0)
    assert p.heading_at(5.0) == pytest.approx(np.pi / 2)
    np.testing.assert_allclose(p.point_at(10.0), [7.0, 3.0], atol=1e-9)


def test_smoothed_keeps_straight_and_rounds_corners():
    s = paths.straight(6.0).smoothed(0.3)
    np.testing.assert_allclose(s.points[:, 0], 0.0, atol=1e-12)
    assert s.length == pytest.approx(6.0, abs=0.02)
    turn = paths.sharp_turn(np.radians(90), 8.0).smoothed(0.3)
    h = turn.heading_at(np.arange(0.0, turn.length, 0.01))
    assert np.abs(np.diff(np.unwrap(h))).max() < 0.1            # no 90 degree jump: the corner is rounded
    assert h[-1] == pytest.approx(np.pi / 2, abs=0.01)


def test_random_path_is_deterministic_and_covers_kinds():
    a = paths.random_path(np.random.default_rng(3), 12.0)
    b = paths.random_path(np.random.default_rng(3), 12.0)
    np.testing.assert_array_equal(a.points, b.points)
    kinds = {paths.random_path(np.random.default_rng(i), 12.0).kind for i in range(40)}
    assert kinds == set(paths.PATH_KINDS)
    for kind in paths.PATH_KINDS:
        p = paths.random_path(np.random.default_rng(0), 12.0, kind=kind)
        assert p.kind == kind
        assert p.length == pytest.approx(12.0, rel=0.01)


@pytest.mark.parametrize("points, message", [
    (np.zeros((3, 3)), "(N, 2)"),
    ([[0.0, 0.0]], "two distinct"),
    ([[0.0, 0.0], [0.0, 0.0]], "two distinct"),
    ([[0.0, 0.0], [np.nan, 1.0]], "NaN"),
])
def test_bad_points_are_rejected(points, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        GroundPath.from_points(points)


def test_bad_factory_arguments():
    with pytest.raises(ValueError, match="radius"):
        paths.curved(0.0, 1.0)
    with pytest.raises(ValueError, match="at_fraction"):
        paths.sharp_turn(1.0, 10.0, at_fraction=1.0)
    with pytest.raises(ValueError, match="length"):
        paths.straight(-1.0)
    with pytest.raises(ValueError, match="kind"):
        paths.random_path(np.random.default_rng(0), 5.0, kind="zigzag")
