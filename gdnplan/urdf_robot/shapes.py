"""Collision shapes → link polygons: points whose hull contains each coal shape, and the
projected hull, simplified to an enclosing polygon: a link polygon always contains the
projection of its link's geometry (the certificate's distances are then lower bounds)."""

from __future__ import annotations

from functools import cache

import numpy as np
from scipy.spatial import QhullError

from ..errors import InputError
from ..geometry import check_part, enclosing_convex


def _projected_polygon(uv: np.ndarray, max_vertices: int, name: str, source: str) -> np.ndarray:
    """Simplified convex hull of projected points (k, 2); InputError when it is flat."""
    flat = InputError(
        f"geometry {name!r} of {source} projects to a segment or a point on the plane; "
        "give it thickness across the plane, skip it or give a link polygon instead"
    )
    try:
        poly = enclosing_convex(uv, max_vertices)
    except (QhullError, ValueError) as e:
        raise flat from e
    try:
        check_part(poly, f"geometry {name!r}")
    except InputError as e:
        raise flat from e
    return poly


def geometry_points(geometry, samples: int = 24) -> np.ndarray:
    """Points (k, 3) of a coal collision geometry's frame whose convex hull contains it.

    Boxes give their corners, meshes their vertices; cylinders and capsules the corners of
    regular ``samples``-gons circumscribing their end circles, spheres (and capsule ends) the
    vertices of a polyhedron circumscribing the ball (so every projection of the hull contains
    the shape's projection, not a polygon inscribed in it).
    """
    import coal

    ang = np.linspace(0, 2 * np.pi, samples, endpoint=False)
    ring = np.stack([np.cos(ang), np.sin(ang), np.zeros_like(ang)], 1) / np.cos(np.pi / samples)
    if isinstance(geometry, coal.Box):
        h = np.asarray(geometry.halfSide)
        corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
        return corners * h
    if isinstance(geometry, coal.Sphere):
        return geometry.radius * _ball_cover()
    if isinstance(geometry, (coal.Cylinder, coal.Capsule)):
        r, h = geometry.radius, geometry.halfLength
        pts = [ring * r + [0, 0, z] for z in (-h, h)]
        if isinstance(geometry, coal.Capsule):
            pts += [r * _ball_cover() + np.array([0.0, 0.0, z]) for z in (-h, h)]
        return np.concatenate(pts)
    if hasattr(geometry, "vertices"):  # BVH meshes and convex hulls
        return np.asarray(geometry.vertices())
    if hasattr(geometry, "points"):
        return np.asarray(geometry.points())
    raise InputError(f"geometry: unsupported collision shape {type(geometry).__name__}")


@cache
def _ball_cover(n: int = 642) -> np.ndarray:
    """(n, 3) vertices of a convex polyhedron containing the unit ball: n Fibonacci points on
    the unit sphere, scaled by 1/ρ with ρ the smallest distance from the centre to a face of
    their hull (its inradius)."""
    from scipy.spatial import ConvexHull

    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5.0**0.5) * k
    pts = np.stack([np.sqrt(1 - z**2) * np.cos(phi), np.sqrt(1 - z**2) * np.sin(phi), z], 1)
    rho = float(np.min(-ConvexHull(pts).equations[:, 3]))  # unit normals: −offset = distance
    return pts / rho
