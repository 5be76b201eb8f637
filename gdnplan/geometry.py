"""2-D polygons: validation, squares, α-shapes, densification, convex decomposition,
zero-padded batches of polygon lists (:func:`pad_polygons`); convex hulls (simplified or
enclosing) are in :mod:`gdnplan.convex_hulls` and re-exported here.

Convention: a polygon is an ``(m, 2)`` float64 array of vertices in metres, counter-clockwise,
without a repeated closing vertex.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.spatial import Delaunay
from shapely.geometry import MultiPolygon, Polygon

from .convex_hulls import MEET_REACH as MEET_REACH
from .convex_hulls import convex_hull as convex_hull
from .convex_hulls import drop_collinear
from .convex_hulls import enclosing_convex as enclosing_convex
from .convex_hulls import simplify_convex as simplify_convex
from .errors import InputError


def signed_area(poly: np.ndarray) -> float:
    """Shoelace area (m²): positive for counter-clockwise vertex order."""
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


MAX_VERTICES = 2000  # vertices of one polygon
MIN_THICKNESS = 1e-6  # m: floor of the width of every convex part (and of every edge length)
REL_THICKNESS = 1e-6  # ... relative to the part's extent (coal's hull crashed below ~5e-9)


def as_polygon(vertices, name: str = "polygon") -> np.ndarray:
    """Validate vertices and return them as a CCW (m, 2) float64 polygon.

    Raises InputError naming ``name`` for a wrong shape, NaN or infinite coordinates, fewer
    than 3 or more than ``MAX_VERTICES`` vertices, repeated vertices (edges shorter than
    ``MIN_THICKNESS``), zero area (collinear vertices, checked first: a flat polygon
    is also invalid to shapely) or self-intersection. Booleans and strings are no numbers.
    """
    poly = _float_array(vertices, name)
    if poly.ndim != 2 or poly.shape[1] != 2:
        raise InputError(f"{name}: expected vertices of shape (m, 2), got {poly.shape}")
    if not np.all(np.isfinite(poly)):
        raise InputError(f"{name}: contains NaN or infinite coordinates")
    if len(poly) > 1 and np.allclose(poly[0], poly[-1]):
        poly = poly[:-1]
    if len(poly) < 3:
        raise InputError(f"{name}: needs at least 3 vertices, got {len(poly)}")
    if len(poly) > MAX_VERTICES:
        raise InputError(
            f"{name}: {len(poly)} vertices, the limit is {MAX_VERTICES}; simplify the polygon"
        )
    if np.max(np.abs(poly)) > 1e12:
        raise InputError(f"{name}: coordinates beyond 1e12 m; use metres near the robot")
    edges = np.linalg.norm(np.roll(poly, -1, 0) - poly, axis=1)
    if np.min(edges) < MIN_THICKNESS:
        k = int(np.argmin(edges))
        raise InputError(
            f"{name}: vertices {k} and {(k + 1) % len(poly)} are repeated or closer than "
            f"{MIN_THICKNESS} m; remove one"
        )
    if _collinear(poly):
        raise InputError(f"{name}: the polygon has zero area (collinear vertices)")
    if not Polygon(poly).is_valid:
        raise InputError(f"{name}: the polygon intersects itself; list its vertices in order")
    area = signed_area(poly)
    if abs(area) < 1e-12:
        raise InputError(f"{name}: the polygon has zero area")
    return poly if area > 0 else poly[::-1].copy()


def _collinear(poly: np.ndarray, rel: float = 1e-12) -> bool:
    """True when every vertex lies within rel · max(1 m, extent) of one line (the principal
    axis of the vertices): a flat polygon, which shapely also calls invalid."""
    centred = poly - poly.mean(0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]  # unit direction of the line
    off = np.abs(centred @ np.array([-axis[1], axis[0]]))  # distances from it (m)
    return float(np.max(off)) <= rel * max(1.0, float(np.max(np.ptp(poly, axis=0))))


def _float_array(vertices, name: str) -> np.ndarray:
    """Nested numbers -> float array; booleans, strings and other objects are rejected."""
    if isinstance(vertices, np.ndarray):
        if vertices.dtype.kind not in "iuf":
            raise InputError(f"{name}: expected numbers, got an array of {vertices.dtype}")
        return np.array(vertices, dtype=float)
    if not isinstance(vertices, (list, tuple)) or not all(
        isinstance(v, (list, tuple, np.ndarray)) for v in vertices
    ):
        raise InputError(f"{name}: expected a list of [x, y] vertices")
    for v in vertices:
        for x in v:
            if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
                raise InputError(f"{name}: expected numbers as coordinates, got {x!r}")
    try:
        return np.array(vertices, dtype=float)
    except (TypeError, ValueError, OverflowError) as e:
        raise InputError(f"{name}: expected a list of [x, y] vertices") from e


def min_width(poly: np.ndarray) -> float:
    """Width (m) of a convex polygon: the smallest extent over its edge normals."""
    edges = np.roll(poly, -1, 0) - poly
    normals = np.c_[-edges[:, 1], edges[:, 0]] / np.linalg.norm(edges, axis=1)[:, None]
    extent = (poly - poly.mean(0)) @ normals.T  # (m vertices, m normals)
    return float(np.min(extent.max(0) - extent.min(0)))


def check_part(part: np.ndarray, name: str, floor: float | None = None) -> None:
    """InputError unless the convex part is at least ``floor`` thick (default
    max(MIN_THICKNESS, REL_THICKNESS · max(extent, 2 m))): thinner slivers crash coal's
    convex hull (a 0.3 m × 1e-8 m rectangle segfaulted)."""
    size = float(np.max(np.ptp(part, axis=0)))
    floor = max(MIN_THICKNESS, REL_THICKNESS * max(size, 2.0)) if floor is None else floor
    width = min_width(part)
    if width < floor:
        raise InputError(
            f"{name}: a convex part is only {width:.3g} m thick, the floor is {floor:.3g} m; "
            "make the obstacle thicker or remove it"
        )


def is_convex(poly: np.ndarray, tol: float = 1e-12) -> bool:
    """True when every turn of the CCW polygon is a left turn (collinear allowed)."""
    edges = np.roll(poly, -1, 0) - poly
    turns = edges[:, 0] * np.roll(edges, -1, 0)[:, 1] - edges[:, 1] * np.roll(edges, -1, 0)[:, 0]
    return bool(np.all(turns >= -tol))


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
    """Split a simple CCW polygon into convex CCW parts whose union is the polygon.

    Constrained Delaunay triangulation (shapely, O(n log n)), then Hertel–Mehlhorn: drop
    each diagonal whose removal keeps both its ends convex (O(1) per diagonal on a half-edge
    structure), at most 4× the fewest convex parts. A convex input is its only part.
    (``MAX_VERTICES`` is sized by its cost: docs/decisions.md#vertex-limit.)
    """
    if is_convex(poly):
        return [poly]
    index = {tuple(p): i for i, p in enumerate(poly.tolist())}
    tris = shapely.constrained_delaunay_triangles(Polygon(poly))
    succ: dict[tuple[int, int], int] = {}  # half-edge (u, v) -> w: the next one is (v, w)
    pred: dict[tuple[int, int], int] = {}  # half-edge (u, v) -> t: the previous one is (t, u)
    for t in tris.geoms:
        ring = [index[tuple(c)] for c in np.asarray(t.exterior.coords)[:-1].tolist()]
        if signed_area(poly[ring]) < 0:
            ring = ring[::-1]
        for k in range(3):
            a, b, c = ring[k], ring[(k + 1) % 3], ring[(k + 2) % 3]
            succ[(a, b)], pred[(b, c)] = c, a
    for a, b in [e for e in succ if e[0] < e[1] and (e[1], e[0]) in succ]:
        p, q = pred[(a, b)], succ[(b, a)]  # around a: (p, a) then (a, q)
        r, s = pred[(b, a)], succ[(a, b)]  # around b: (r, b) then (b, s)
        if _left(poly[p], poly[a], poly[q]) and _left(poly[r], poly[b], poly[s]):
            for e in ((a, b), (b, a)):
                del succ[e], pred[e]
            succ[(p, a)], pred[(a, q)] = q, p
            succ[(r, b)], pred[(b, s)] = s, r
    return [drop_collinear(poly[ring]) for ring in _cycles(succ)]


def _left(p: np.ndarray, a: np.ndarray, q: np.ndarray) -> bool:
    """p -> a -> q turns left or goes straight (relative tolerance 1e-12)."""
    u, v = a - p, q - a
    return u[0] * v[1] - u[1] * v[0] >= -1e-12 * np.linalg.norm(u) * np.linalg.norm(v)


def _cycles(succ: dict[tuple[int, int], int]) -> list[list[int]]:
    """The vertex cycles of the half-edge structure (one per part)."""
    seen: set[tuple[int, int]] = set()
    out = []
    for start in succ:
        if start in seen:
            continue
        ring, e = [], start
        while e not in seen:
            seen.add(e)
            ring.append(e[0])
            e = (e[1], succ[e])
        out.append(ring)
    return out


def polygon_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Euclidean distance between two polygons (0 when they overlap), via shapely."""
    return float(Polygon(a).distance(Polygon(b)))


def pad_polygons(polys: list[list[np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """Stack per-sample polygon lists into (n, P, V, 2) zero-padded arrays and (n, P) sizes."""
    n_poly = max(len(ps) for ps in polys)
    n_vert = max(len(p) for ps in polys for p in ps)
    out = np.zeros((len(polys), n_poly, n_vert, 2))
    sizes = np.zeros((len(polys), n_poly), np.int32)
    for i, ps in enumerate(polys):
        for j, p in enumerate(ps):
            out[i, j, : len(p)] = p
            sizes[i, j] = len(p)
    return out, sizes
