import numpy as np
import pytest
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon

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


@pytest.mark.parametrize(
    ("vertices", "message"),
    [
        ([[0, 0], [1, 0], [1, 0], [0, 1]], "repeated"),
        ([[0, 0], [1, 0], [1, 1e-9], [0, 1]], "repeated"),
        ([[0, 0], [1e300, 0], [1e300, 1e300]], "1e12"),
        ([[0, 0], [1, 0], [1, True]], "numbers"),
        ([[0, 0], [1, 0], [1, "1"]], "numbers"),
        ([[0, 0], [1, 0], [1, np.inf]], "infinite"),
        ("abc", "list"),
        (np.array([["0", "0"], ["1", "0"], ["1", "1"]]), "numbers"),
    ],
)
def test_as_polygon_rejects_degenerate_and_non_numeric_vertices(vertices, message):
    with pytest.raises(gp.InputError, match=message):
        geo.as_polygon(vertices, "obstacles[0]")


def test_as_polygon_limits_the_vertex_count():
    t = np.linspace(0, 2 * np.pi, geo.MAX_VERTICES + 1, endpoint=False)
    with pytest.raises(gp.InputError, match=f"limit is {geo.MAX_VERTICES}"):
        geo.as_polygon(np.c_[np.cos(t), np.sin(t)], "obstacles[0]")


@pytest.mark.parametrize("thickness", [1e-7, 1e-8, 1e-12])
def test_check_part_rejects_slivers_that_crash_coal(thickness):
    sliver = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, thickness]])
    with pytest.raises(gp.InputError, match="thick"):
        geo.check_part(sliver, "obstacles[3]")
    geo.check_part(np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 1e-5]]), "fine")


def _star(n: int, seed: int = 0) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 1 + 0.3 * np.sin(7 * t) + 0.05 * np.random.default_rng(seed).uniform(size=n)
    return geo.as_polygon(np.c_[r * np.cos(t), r * np.sin(t)])


@pytest.mark.parametrize("n", [5, 40, 300])
def test_convex_decomposition_of_star_polygons_is_an_exact_convex_partition(n):
    poly = _star(n, seed=n)
    parts = geo.convex_decomposition(poly)
    assert all(geo.is_convex(p) and geo.signed_area(p) > 0 for p in parts)
    assert sum(Polygon(p).area for p in parts) == pytest.approx(Polygon(poly).area, rel=1e-9)
    assert shapely.union_all([Polygon(p) for p in parts]).symmetric_difference(
        Polygon(poly)
    ).area == pytest.approx(0.0, abs=1e-9)
    reflex = len(poly) - sum(
        geo.is_convex(poly[[i - 1, i, (i + 1) % len(poly)]]) for i in range(len(poly))
    )
    assert len(parts) <= 2 * max(reflex, 1) + 1  # Hertel–Mehlhorn: at most 2 r + 1 parts


def test_convex_decomposition_is_exact_at_the_vertex_limit():
    poly = _star(geo.MAX_VERTICES)  # the old O(n³) merge took 162 s at 400 vertices
    parts = geo.convex_decomposition(poly)
    assert sum(Polygon(p).area for p in parts) == pytest.approx(Polygon(poly).area, rel=1e-9)


@settings(max_examples=60, deadline=None)
@given(
    tilt=st.floats(-0.05, 0.05),
    size=st.tuples(st.floats(0.05, 2.0), st.floats(0.05, 2.0)),
    arcs=st.integers(3, 20),
    bulge=st.floats(0.0, 0.1),
    most=st.integers(3, 6),
)
@example(tilt=0.001, size=(0.5, 0.5), arcs=17, bulge=0.02, most=3)  # was a 57 m triangle
def test_an_enclosing_polygon_of_a_near_rectangle_stays_near_it(tilt, size, arcs, bulge, most):
    """A slightly tilted rectangle with elliptic ends (a cylinder seen from its side) has
    neighbouring hull edges that are nearly parallel: their meeting point lies far away, and
    the enclosing polygon must not go there (a link of a user's URDF failed its thickness
    check as "flat": a 1 m link got a triangle 2.6e6 m long)."""
    w, h = size
    a = np.linspace(-np.pi / 2, np.pi / 2, arcs)
    end = np.c_[w / 2 + bulge * w * np.cos(a), h / 2 * np.sin(a)]
    side = np.linspace(-w / 2, w / 2, arcs)
    pts = np.vstack(
        [end, end * [-1, 1], np.c_[side, side * 0 + h / 2], np.c_[side, side * 0 - h / 2]]
    )
    c, s = np.cos(tilt), np.sin(tilt)
    pts = (pts + np.array([0.5, 0.0])) @ np.array([[c, s], [-s, c]])
    poly = geo.enclosing_convex(pts, most)
    assert 3 <= len(poly) <= most and geo.is_convex(poly)
    assert np.ptp(poly, axis=0).max() <= 6 * np.ptp(pts, axis=0).max()  # near the points
    geo.check_part(poly, "near rectangle")  # thick: not the far-away sliver
    shape = Polygon(poly)
    outside = [shape.exterior.distance(Point(p)) for p in pts if not shape.contains(Point(p))]
    assert max(outside, default=0.0) <= 1e-9 * (1 + np.abs(pts).max())


@settings(max_examples=60, deadline=None)
@given(
    st.integers(0, 2**31),
    st.integers(3, 80),
    st.integers(3, 14),
    st.sampled_from(["cloud", "circle", "thin"]),
)
def test_an_enclosing_polygon_contains_every_point_within_its_vertex_limit(seed, n, most, kind):
    """Link polygons must contain their geometry's projection: the simplified polygon keeps at
    most ``most`` vertices, stays convex and CCW, and leaves no point outside it."""
    rng = np.random.default_rng(seed)
    if kind == "circle":
        a = np.linspace(0.0, 2 * np.pi, n, endpoint=False) + rng.uniform(0, 1)
        pts = np.c_[np.cos(a), np.sin(a)] * rng.uniform(0.01, 1.0) + rng.uniform(-2, 2, 2)
    else:
        scale = [1.0, 1e-3] if kind == "thin" else rng.uniform(0.01, 2.0, 2)
        pts = rng.normal(size=(n, 2)) * scale
    poly = geo.enclosing_convex(pts, most)
    assert 3 <= len(poly) <= most and geo.is_convex(poly) and geo.signed_area(poly) > 0
    shape = Polygon(poly)
    outside = [shape.exterior.distance(Point(p)) for p in pts if not shape.contains(Point(p))]
    assert max(outside, default=0.0) <= 1e-9 * (1 + np.abs(pts).max())
