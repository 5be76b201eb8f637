"""Graph nodes and edges of 3-D geometry: surface points of coal shapes, polytope and kNN edges,
padded neighbourhoods (the building blocks of :mod:`gdnplan.graph3d`).

A convex shape's nodes (:func:`shape_points`, in its own frame, m) are a box's 8 corners,
``rim`` points on each rim circle of a cylinder (a capsule: the rims of its cylinder and the
tips of its caps), a Fibonacci sample of ``rim²/2`` points on a sphere (:func:`fibonacci_sphere`)
and at most ``hull_points`` hull vertices of a mesh hull (:func:`farthest_points`). Its edges
are the edges of the convex polytope of its nodes (:func:`hull_edges`: the edges of scipy's
Qhull triangulation between facets that are not coplanar); a point cloud's are the symmetrised
k-nearest-neighbour graph (:func:`knn_edges`). Node degrees differ, so :func:`neighbourhoods`
pads them to the largest degree D: ``nbr`` (N, D) node indices (padded slots point to the node
itself) and ``nbr_mask`` (N, D).
"""

from __future__ import annotations

import coal
import numpy as np
from scipy.spatial import ConvexHull, QhullError, cKDTree

from .arm3d.shapes import bvh_vertices
from .errors import InputError

RIM = 8  # points per cylinder rim (docs/decisions.md#graphdistnet-3d-robot-graph-nodes)
HULL_POINTS = 24  # most vertices kept of a mesh hull
COPLANAR = 1e-10  # facets with 1 − n₁·n₂ below this (unit normals) are one face


def fibonacci_sphere(n: int) -> np.ndarray:
    """(n, 3) nearly uniform unit vectors (golden-angle spiral)."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = np.pi * (1 + 5**0.5) * k
    r = np.sqrt(1 - z * z)
    return np.c_[r * np.cos(phi), r * np.sin(phi), z]


def farthest_points(points: np.ndarray, n: int) -> np.ndarray:
    """Indices of n of ``points`` (k, 3), farthest-point sampling from the first (all if k ≤ n)."""
    if len(points) <= n:
        return np.arange(len(points))
    chosen = [0]
    d = np.linalg.norm(points - points[0], axis=1)
    for _ in range(n - 1):
        chosen.append(int(np.argmax(d)))
        d = np.minimum(d, np.linalg.norm(points - points[chosen[-1]], axis=1))
    return np.array(chosen)


def shape_points(shape, rim: int = RIM, hull_points: int = HULL_POINTS) -> np.ndarray:
    """(k, 3) surface points of a coal shape in its own frame (m), module docstring."""
    if isinstance(shape, coal.Box):
        h = np.asarray(shape.halfSide)
        return np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * h
    if isinstance(shape, coal.Sphere):
        return shape.radius * fibonacci_sphere(max(rim * rim // 2, 4))
    if isinstance(shape, (coal.Cylinder, coal.Capsule)):
        t = 2 * np.pi * np.arange(rim) / rim
        circle = shape.radius * np.c_[np.cos(t), np.sin(t)]
        h = shape.halfLength
        pts = [np.c_[circle, np.full(rim, z)] for z in (-h, h)]
        if isinstance(shape, coal.Capsule):
            pts.append(np.array([[0.0, 0.0, -h - shape.radius], [0.0, 0.0, h + shape.radius]]))
        return np.concatenate(pts)
    if hasattr(shape, "points") or hasattr(shape, "vertices"):
        v = bvh_vertices(shape)
        return v[farthest_points(v, hull_points)]
    raise InputError(f"shape: no graph nodes for coal {type(shape).__name__}")


def hull_edges(points: np.ndarray) -> np.ndarray:
    """(E, 2) edges of the convex polytope of ``points`` (k, 3), k ≥ 4 and not flat: the edges
    shared by two hull facets that are not coplanar (module docstring)."""
    try:
        hull = ConvexHull(points)
    except (QhullError, ValueError) as e:
        raise InputError("points: their convex hull is flat or degenerate") from e
    normals = hull.equations[:, :3]
    faces: dict[tuple[int, int], list[int]] = {}
    for f, tri in enumerate(hull.simplices):
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            faces.setdefault((min(a, b), max(a, b)), []).append(f)
    edges = [e for e, fs in faces.items() if 1 - normals[fs[0]] @ normals[fs[-1]] > COPLANAR]
    return np.array(sorted(edges), dtype=int).reshape(-1, 2)


def knn_edges(points: np.ndarray, k: int) -> np.ndarray:
    """(E, 2) symmetrised k-nearest-neighbour edges (i < j) of a point cloud (n, 3)."""
    k = min(k, len(points) - 1)
    if k < 1:
        return np.zeros((0, 2), dtype=int)
    _, idx = cKDTree(points).query(points, k + 1)
    rows = np.repeat(np.arange(len(points)), k)
    pairs = np.sort(np.c_[rows, idx[:, 1:].ravel()], axis=1)
    return np.unique(pairs, axis=0)


def neighbourhoods(n: int, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Padded neighbourhoods of an undirected graph: nbr (n, D) and nbr_mask (n, D), D the
    largest degree (at least 1); padded slots point to the node itself."""
    edges = np.asarray(edges, dtype=int).reshape(-1, 2)
    both = np.concatenate([edges, edges[:, ::-1]])
    degree = np.bincount(both[:, 0], minlength=n)
    width = max(int(degree.max(initial=0)), 1)
    nbr = np.repeat(np.arange(n)[:, None], width, 1)
    mask = np.zeros((n, width), bool)
    order = np.argsort(both[:, 0], kind="stable")
    src, dst = both[order, 0], both[order, 1]
    slot = np.arange(len(src)) - np.searchsorted(src, src)
    nbr[src, slot], mask[src, slot] = dst, True
    return nbr, mask


__all__ = [
    "COPLANAR",
    "HULL_POINTS",
    "RIM",
    "farthest_points",
    "fibonacci_sphere",
    "hull_edges",
    "knn_edges",
    "neighbourhoods",
    "shape_points",
]
