"""Collision shapes → link polygons: surface points of coal shapes, their projected hull."""

from __future__ import annotations

import numpy as np
from scipy.spatial import QhullError

from ..errors import InputError
from ..geometry import check_part, convex_hull, simplify_convex


def _projected_polygon(uv: np.ndarray, max_vertices: int, name: str, source: str) -> np.ndarray:
    """Simplified convex hull of projected points (k, 2); InputError when it is flat."""
    flat = InputError(
        f"geometry {name!r} of {source} projects to a segment or a point on the plane; "
        "give it thickness across the plane, skip it or give a link polygon instead"
    )
    try:
        poly = simplify_convex(convex_hull(uv), max_vertices)
    except (QhullError, ValueError) as e:
        raise flat from e
    try:
        check_part(poly, f"geometry {name!r}")
    except InputError as e:
        raise flat from e
    return poly


def geometry_points(geometry, samples: int = 24) -> np.ndarray:
    """Surface points (k, 3) of a coal collision geometry in its own frame.

    Boxes give their corners, cylinders/capsules/spheres rings of ``samples`` points, meshes
    their vertices.
    """
    import coal

    ang = np.linspace(0, 2 * np.pi, samples, endpoint=False)
    ring = np.stack([np.cos(ang), np.sin(ang), np.zeros_like(ang)], 1)
    if isinstance(geometry, coal.Box):
        h = np.asarray(geometry.halfSide)
        corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
        return corners * h
    if isinstance(geometry, coal.Sphere):
        return _sphere_points(geometry.radius, ang)
    if isinstance(geometry, (coal.Cylinder, coal.Capsule)):
        r, h = geometry.radius, geometry.halfLength
        pts = [ring * r + [0, 0, z] for z in (-h, h)]
        if isinstance(geometry, coal.Capsule):
            pts += [_sphere_points(r, ang) + np.array([0.0, 0.0, z]) for z in (-h, h)]
        return np.concatenate(pts)
    if hasattr(geometry, "vertices"):  # BVH meshes and convex hulls
        return np.asarray(geometry.vertices())
    if hasattr(geometry, "points"):
        return np.asarray(geometry.points())
    raise InputError(f"geometry: unsupported collision shape {type(geometry).__name__}")


def _sphere_points(radius: float, ang: np.ndarray) -> np.ndarray:
    """Points on three great circles of a sphere: enough for the hull of any projection."""
    c, s, z = np.cos(ang), np.sin(ang), np.zeros_like(ang)
    return radius * np.concatenate(
        [np.stack([c, s, z], 1), np.stack([c, z, s], 1), np.stack([z, c, s], 1)]
    )
