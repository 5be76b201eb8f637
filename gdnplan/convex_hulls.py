"""Convex hulls of 2-D points: the hull, simplified with few vertices by cutting corners
(:func:`simplify_convex`, inside the hull) or by extending edges (:func:`enclosing_convex`,
containing every point).

Convention (:mod:`gdnplan.geometry`): a polygon is an ``(m, 2)`` float64 array of vertices in
metres, counter-clockwise, without a repeated closing vertex.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import ConvexHull


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


MEET_REACH = 2.0  # hull extents: how far a dropped edge's neighbours may meet


def enclosing_convex(points: np.ndarray, max_vertices: int) -> np.ndarray:
    """A CCW convex polygon of at most ``max_vertices`` (≥ 3) vertices containing ``points``.

    :func:`simplify_convex` drops hull vertices and so cuts corners off; here edges of the hull
    are dropped instead, least area added first: the two neighbouring edges are extended to
    meet (possible where they converge), so the polygon only grows. Where no edge can go (a
    rectangle's parallel sides, or neighbours so close to parallel that they would meet more
    than ``MEET_REACH`` hull extents away: a rectangle tilted by 1e-3 rad made a triangle
    10⁶ m long), the simplified hull's edges are pushed out until every point is on their
    inner side (:func:`_push_out`).
    """
    hull = convex_hull(points)
    reach = MEET_REACH * float(np.ptp(hull, axis=0).max())
    poly = hull
    while len(poly) > max_vertices:
        a, b = poly, np.roll(poly, -1, 0)  # edge i: a[i] → b[i]
        d1, d2 = a - np.roll(poly, 1, 0), np.roll(poly, -2, 0) - b  # its neighbours' directions
        turn = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]  # > 0: the neighbours converge
        gap = b - a
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (gap[:, 0] * d2[:, 1] - gap[:, 1] * d2[:, 0]) / turn
            meet = a + t[:, None] * d1
        added = 0.5 * np.abs((meet - a)[:, 0] * gap[:, 1] - (meet - a)[:, 1] * gap[:, 0])
        ok = (turn > 1e-12 * np.linalg.norm(d1, axis=1) * np.linalg.norm(d2, axis=1)) & (t >= 0)
        ok &= np.linalg.norm(meet - a, axis=1) <= reach  # NaN (parallel) is not ≤: refused
        if not ok.any():
            return _push_out(hull, simplify_convex(poly, max_vertices))
        i = int(np.argmin(np.where(ok, added, np.inf)))
        if i < len(poly) - 1:  # vertices i, i + 1 → their edge's replacement corner
            poly = np.vstack([poly[:i], meet[i][None], poly[i + 2 :]])
        else:  # the closing edge: vertices n − 1 and 0
            poly = np.vstack([poly[1:i], meet[i][None]])
    return poly


def _push_out(hull: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """The convex polygon poly with every edge pushed out along its normal to the support of
    ``hull``: the intersection of those half-planes, which contains the hull."""
    edge = np.roll(poly, -1, 0) - poly
    normal = np.stack([edge[:, 1], -edge[:, 0]], 1) / np.linalg.norm(edge, axis=1)[:, None]
    offset = np.max(hull @ normal.T, axis=0)  # support of the hull along each outward normal
    span = float(np.max(np.abs(hull))) + float(np.ptp(hull, axis=0).max()) + 1.0
    out = np.array([[-span, -span], [span, -span], [span, span], [-span, span]])
    for n, c in zip(normal, offset, strict=True):  # Sutherland–Hodgman: clip by n · x ≤ c
        inside = out @ n <= c
        rows = []
        for a, b, ia, ib in zip(out, np.roll(out, -1, 0), inside, np.roll(inside, -1), strict=True):
            if ia:
                rows.append(a)
            if ia != ib:
                rows.append(a + (c - a @ n) / ((b - a) @ n) * (b - a))
        out = np.array(rows)
    return drop_collinear(out)


def drop_collinear(part: np.ndarray) -> np.ndarray:
    """Remove vertices where a convex part goes straight on."""
    prev, nxt = np.roll(part, 1, 0), np.roll(part, -1, 0)
    u, v = part - prev, nxt - part
    cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    keep = np.abs(cross) > 1e-12 * np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1)
    return part[keep] if keep.sum() >= 3 else part
