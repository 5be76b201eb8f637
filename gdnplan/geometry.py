"""2-D polygons: validation, convex hulls, squares, α-shapes, densification, convex decomposition.

Convention: a polygon is an ``(m, 2)`` float64 array of vertices in metres, counter-clockwise,
without a repeated closing vertex.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.spatial import ConvexHull, Delaunay
from shapely.geometry import MultiPolygon, Polygon

from .errors import InputError


def signed_area(poly: np.ndarray) -> float:
    """Shoelace area (m²): positive for counter-clockwise vertex order."""
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def as_polygon(vertices, name: str = "polygon") -> np.ndarray:
    """Validate vertices and return them as a CCW (m, 2) float64 polygon.

    Raises InputError naming ``name`` for a wrong shape, NaN, fewer than 3 distinct vertices,
    zero area or self-intersection.
    """
    try:
        poly = np.array(vertices, dtype=float)
    except (TypeError, ValueError) as e:
        raise InputError(f"{name}: expected a list of [x, y] vertices") from e
    if poly.ndim != 2 or poly.shape[1] != 2:
        raise InputError(f"{name}: expected vertices of shape (m, 2), got {poly.shape}")
    if not np.all(np.isfinite(poly)):
        raise InputError(f"{name}: contains NaN or infinite coordinates")
    if len(poly) > 1 and np.allclose(poly[0], poly[-1]):
        poly = poly[:-1]
    if len(poly) < 3:
        raise InputError(f"{name}: needs at least 3 vertices, got {len(poly)}")
    if not Polygon(poly).is_valid:
        raise InputError(f"{name}: the polygon intersects itself; list its vertices in order")
    area = signed_area(poly)
    if abs(area) < 1e-12:
        raise InputError(f"{name}: the polygon has zero area")
    return poly if area > 0 else poly[::-1].copy()


def is_convex(poly: np.ndarray, tol: float = 1e-12) -> bool:
    """True when every turn of the CCW polygon is a left turn (collinear allowed)."""
    edges = np.roll(poly, -1, 0) - poly
    turns = edges[:, 0] * np.roll(edges, -1, 0)[:, 1] - edges[:, 1] * np.roll(edges, -1, 0)[:, 0]
    return bool(np.all(turns >= -tol))


def convex_hull(points: np.ndarray) -> np.ndarray:
    """CCW convex hull (m, 2) of points (k, 2)."""
    points = np.asarray(points, dtype=float)
    return points[ConvexHull(points).vertices]  # scipy lists 2-D hull vertices CCW


def simplify_convex(poly: np.ndarray, max_vertices: int) -> np.ndarray:
    """Drop vertices of a convex polygon, least area lost first, until ``max_vertices`` remain."""
    poly = np.asarray(poly, dtype=float)
    while len(poly) > max_vertices:
        prev, nxt = np.roll(poly, 1, 0), np.roll(poly, -1, 0)
        a, b = poly - prev, nxt - prev
        lost = np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
        poly = np.delete(poly, int(np.argmin(lost)), axis=0)
    return poly


def rectangle(center, size, angle: float = 0.0) -> np.ndarray:
    """CCW rectangle with ``size = (width, height)`` rotated by ``angle`` about its center."""
    w, h = 0.5 * np.asarray(size, dtype=float)
    local = np.array([[-w, -h], [w, -h], [w, h], [-w, h]])
    c, s = np.cos(angle), np.sin(angle)
    return local @ np.array([[c, s], [-s, c]]) + np.asarray(center, dtype=float)


def square(center, side: float, angle: float = 0.0) -> np.ndarray:
    """CCW square of side ``side`` (m) rotated by ``angle`` (rad) about its center."""
    return rectangle(center, (side, side), angle)


def densify(poly: np.ndarray, max_edge: float) -> np.ndarray:
    """Insert evenly spaced vertices so that no edge is longer than ``max_edge`` (m)."""
    out = []
    for a, b in zip(poly, np.roll(poly, -1, 0), strict=True):
        pieces = max(1, int(np.ceil(np.linalg.norm(b - a) / max_edge)))
        t = np.arange(pieces)[:, None] / pieces
        out.append(a + t * (b - a))
    return np.concatenate(out)


def alpha_shape(points: np.ndarray, alpha: float) -> np.ndarray:
    """Largest polygon of the α-shape of ``points`` (k, 2): the union of the Delaunay
    triangles whose circumradius is at most ``alpha``, without holes. Returns a CCW polygon.

    Raises InputError when no triangle survives (α too small for the point spacing).
    """
    tri = Delaunay(points)
    a, b, c = (points[tri.simplices[:, i]] for i in range(3))
    la, lb, lc = (np.linalg.norm(u - v, axis=1) for u, v in ((b, c), (a, c), (a, b)))
    area2 = np.abs((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    with np.errstate(divide="ignore"):
        radius = la * lb * lc / (2.0 * area2)
    keep = tri.simplices[radius <= alpha]
    if len(keep) == 0:
        raise InputError(f"alpha: no Delaunay triangle has circumradius ≤ {alpha}")
    union = shapely.union_all([Polygon(points[s]) for s in keep])
    parts = list(union.geoms) if isinstance(union, MultiPolygon) else [union]
    largest = max(parts, key=lambda p: p.area)
    ring = np.asarray(largest.exterior.coords)[:-1]
    return as_polygon(ring)


def limit_vertices(poly: np.ndarray, max_vertices: int) -> np.ndarray:
    """Simplify a (possibly non-convex) polygon to at most ``max_vertices`` vertices, keeping it
    simple: Douglas–Peucker with a growing tolerance."""
    shape = Polygon(poly)
    tol = 1e-4
    while len(shape.exterior.coords) - 1 > max_vertices:
        shape = Polygon(poly).simplify(tol, preserve_topology=True)
        tol *= 1.5
    return as_polygon(np.asarray(shape.exterior.coords)[:-1])


def convex_decomposition(poly: np.ndarray) -> list[np.ndarray]:
    """Split a simple polygon into convex CCW parts whose union is the polygon.

    Constrained Delaunay triangulation (shapely), then Hertel–Mehlhorn: merge neighbouring
    pieces across a shared edge whenever the union stays convex. A convex input is returned as
    the only part.
    """
    if is_convex(poly):
        return [poly]
    tris = shapely.constrained_delaunay_triangles(Polygon(poly))
    pieces = [as_polygon(np.asarray(t.exterior.coords)[:-1]) for t in tris.geoms]
    merged = True
    while merged:
        merged = False
        for i in range(len(pieces)):
            for j in range(i + 1, len(pieces)):
                joined = _merge_convex(pieces[i], pieces[j])
                if joined is not None:
                    pieces[i] = joined
                    del pieces[j]
                    merged = True
                    break
            if merged:
                break
    return pieces


def _merge_convex(p: np.ndarray, r: np.ndarray) -> np.ndarray | None:
    """Union of two convex polygons sharing an edge, if it is convex; else None."""
    union = Polygon(p).union(Polygon(r))
    if not isinstance(union, Polygon) or union.area < Polygon(p).area + Polygon(r).area - 1e-12:
        return None
    shared = Polygon(p).intersection(Polygon(r))
    if shared.length < 1e-9:  # touching at a point only
        return None
    ring = np.asarray(union.simplify(0.0).exterior.coords)[:-1]
    ring = ring if signed_area(ring) > 0 else ring[::-1]
    return ring if is_convex(ring, tol=1e-10) else None


def polygon_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Euclidean distance between two polygons (0 when they overlap), via shapely."""
    return float(Polygon(a).distance(Polygon(b)))
