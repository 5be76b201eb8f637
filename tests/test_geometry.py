import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon

import gdnplan as gp
from gdnplan import geometry as geo


def test_as_polygon_orients_ccw_and_drops_closing_vertex():
    cw = [[0, 0], [0, 1], [1, 1], [1, 0], [0, 0]]
    poly = geo.as_polygon(cw)
    assert poly.shape == (4, 2)
    assert geo.signed_area(poly) == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("vertices", "message"),
    [
        ([[0, 0], [1, 0]], "at least 3"),
        ([[0, 0], [1, 1], [1, 0], [0, 1]], "intersects"),
        ([[0, 0], [1, np.nan], [1, 1]], "NaN"),
        ([[0, 0, 0], [1, 0, 0], [1, 1, 0]], "shape"),
    ],
)
def test_as_polygon_rejects_bad_input(vertices, message):
    with pytest.raises(gp.InputError, match=message):
        geo.as_polygon(vertices, "obstacles[0]")


def test_square_has_side_and_rotation():
    sq = geo.square((1.0, 2.0), 0.2, np.pi / 4)
    assert geo.signed_area(sq) == pytest.approx(0.04)
    np.testing.assert_allclose(sq.mean(0), [1.0, 2.0])
    assert np.linalg.norm(sq[0] - sq[1]) == pytest.approx(0.2)


def test_densify_bounds_edges_and_keeps_shape():
    sq = geo.square((0, 0), 1.0)
    dense = geo.densify(sq, 0.3)
    edges = np.linalg.norm(np.roll(dense, -1, 0) - dense, axis=1)
    assert edges.max() <= 0.3 + 1e-12
    assert len(dense) == 16
    assert Polygon(dense).equals(Polygon(sq))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000))
def test_convex_decomposition_covers_alpha_shapes(seed):
    poly = gp.scene.random_alpha_shape(np.random.default_rng(seed))
    parts = geo.convex_decomposition(poly)
    assert all(geo.is_convex(p, tol=1e-10) for p in parts)
    assert sum(Polygon(p).area for p in parts) == pytest.approx(Polygon(poly).area, rel=1e-9)
    union = Polygon(parts[0]).union(Polygon(parts[0]))
    for p in parts[1:]:
        union = union.union(Polygon(p))
    assert union.symmetric_difference(Polygon(poly)).area < 1e-9


def test_alpha_shape_limits_vertices_and_is_simple():
    rng = np.random.default_rng(0)
    for _ in range(20):
        poly = gp.scene.random_alpha_shape(rng)
        assert 3 <= len(poly) <= 15
        assert Polygon(poly).is_valid
        assert geo.signed_area(poly) > 0


def test_convex_hull_and_simplify():
    rng = np.random.default_rng(1)
    pts = rng.normal(size=(200, 2))
    hull = geo.convex_hull(pts)
    assert geo.is_convex(hull) and geo.signed_area(hull) > 0
    small = geo.simplify_convex(hull, 6)
    assert len(small) == 6 and geo.is_convex(small)
    assert Polygon(hull).contains(Polygon(small).buffer(-1e-9))
