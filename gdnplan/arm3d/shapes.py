"""3-D collision shapes for coal: validated primitives, convex hulls of points and meshes, poses.

Every shape reaches coal only after its numbers are checked, because coal's convex hull crashes
the process (a segfault, no exception) on nearly flat point sets and huge coordinates:

* coordinates and sizes are finite numbers with ``|x| ≤ MAX_COORDINATE`` (m), primitive sizes
  (box sides, radii, lengths) at least ``MIN_SIZE`` (m): :mod:`gdnplan.arm3d.shape_numbers`;
* a point set's convex hull is computed first with scipy's Qhull (which raises instead of
  crashing) and must be thick: its thickness t = 2 V / A (hull volume V, surface area A; exact
  for a thin slab, 2 r / 3 for a ball of radius r) satisfies t ≥ MIN_SIZE and
  t ≥ ``REL_THICKNESS`` · diameter. Only the hull's vertices go to coal.

A mesh is always used as its convex hull. A mesh with a vertex deeper than ``CONVEX_TOLERANCE``
(relative to its diameter) inside that hull is not convex; it is still replaced by its hull
(a superset: distances to it are lower bounds of the mesh's), and a note is logged on the
``gdnplan.arm3d`` logger. Mesh files are read with coal's own loader (assimp: STL, OBJ, DAE, …).

Poses (a position and a quaternion or rotation matrix) are checked in :mod:`gdnplan.arm3d.poses`;
:func:`as_pose` and :func:`as_rotation` are re-exported here.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

import coal
import numpy as np
from scipy.spatial import ConvexHull, QhullError

from ..errors import InputError, UnknownNameError
from ..limits import is_number
from ..urdf_robot.meshes import mesh_vertices
from .poses import ORTHONORMAL_ROUNDING as ORTHONORMAL_ROUNDING
from .poses import ROTATION_TOLERANCE as ROTATION_TOLERANCE
from .poses import as_pose as as_pose
from .poses import as_rotation as as_rotation
from .shape_numbers import MAX_COORDINATE as MAX_COORDINATE
from .shape_numbers import MAX_HULL_POINTS as MAX_HULL_POINTS
from .shape_numbers import MIN_SIZE as MIN_SIZE
from .shape_numbers import as_points as as_points
from .shape_numbers import as_size as as_size
from .shape_numbers import as_vector as as_vector

REL_THICKNESS = 1e-4  # hull thickness / diameter floor (coal's hull crashed near 1e-8)
CONVEX_TOLERANCE = 1e-6  # a mesh vertex deeper than this · diameter inside its hull: non-convex
DEPTH_BLOCK = 4_000_000  # (facet, point) entries per block of the convexity check (32 MB)

log = logging.getLogger("gdnplan.arm3d")


# -------------------------------------------------------------------- shapes
def box(size, name: str = "box") -> coal.Box:
    """A box of full side lengths (sx, sy, sz) in metres, centred on its frame."""
    sides = [as_size(s, f"{name}.size") for s in as_vector(size, 3, f"{name}.size")]
    return coal.Box(*sides)


def sphere(radius, name: str = "sphere") -> coal.Sphere:
    """A sphere of ``radius`` (m) centred on its frame."""
    return coal.Sphere(as_size(radius, f"{name}.radius"))


def cylinder(radius, length, name: str = "cylinder") -> coal.Cylinder:
    """A cylinder along the frame's z axis: ``radius``, full ``length`` (m), centred."""
    return coal.Cylinder(as_size(radius, f"{name}.radius"), as_size(length, f"{name}.length"))


def capsule(radius, length, name: str = "capsule") -> coal.Capsule:
    """A capsule along z: a segment of full ``length`` (m) swept by a ball of ``radius``."""
    return coal.Capsule(as_size(radius, f"{name}.radius"), as_size(length, f"{name}.length"))


def hull_vertices(points, name: str) -> tuple[np.ndarray, ConvexHull]:
    """Vertices (h, 3) of the convex hull of ``points`` after the checks of the module."""
    pts = as_points(points, name)
    diameter = float(np.linalg.norm(pts.max(0) - pts.min(0)))
    flat = f"{name}: the points are (nearly) flat or a line; give the shape thickness"
    if diameter < MIN_SIZE:
        raise InputError(f"{name}: the points span less than {MIN_SIZE:g} m")
    try:
        hull = ConvexHull(pts)
    except (QhullError, ValueError) as e:
        raise InputError(flat) from e
    thickness = 2.0 * hull.volume / hull.area
    if thickness < max(MIN_SIZE, REL_THICKNESS * diameter):
        raise InputError(
            f"{flat} (thickness 2·volume/area = {thickness:.3g} m < {REL_THICKNESS:g} · "
            f"diameter {diameter:.3g} m)"
        )
    return pts[hull.vertices], hull


def convex(points, name: str = "convex") -> coal.ConvexBase:
    """The convex hull of ``points`` (k, 3) in metres as a coal convex shape."""
    vertices, _ = hull_vertices(points, name)
    return _coal_hull(vertices)


def check_shape(shape, name: str, octree: bool = False):
    """``shape`` when it is a coal shape the builders of this module could have made: sizes in
    [``MIN_SIZE``, ``MAX_COORDINATE``] m, a convex hull's points checked as :func:`convex`'s, an
    ``OcTree`` (a point cloud) only with ``octree``. InputError naming ``name`` otherwise: a
    raw ``coal.Box(nan, 1, 1)`` or ``coal.Sphere(-1)`` was never hit by any distance."""
    if isinstance(shape, coal.Box):
        box(2 * np.asarray(shape.halfSide), name)
    elif isinstance(shape, coal.Sphere):
        sphere(shape.radius, name)
    elif isinstance(shape, (coal.Capsule, coal.Cylinder)):
        as_size(shape.radius, f"{name}.radius")
        as_size(2 * shape.halfLength, f"{name}.length")
    elif isinstance(shape, coal.ConvexBase):
        hull_vertices(np.array([shape.point(i) for i in range(shape.num_points)]), name)
    elif not (octree and isinstance(shape, coal.OcTree)):
        kinds = "Box, Sphere, Cylinder, Capsule or ConvexBase" + (" or OcTree" if octree else "")
        raise InputError(
            f"{name}: expected a coal {kinds} (build it with gdnplan.arm3d.shapes), got "
            f"{type(shape).__name__}"
        )
    return shape


def _coal_hull(vertices: np.ndarray) -> coal.ConvexBase:
    cloud = coal.StdVec_Vec3s()
    for p in vertices:
        cloud.append(p)
    return coal.ConvexBase.convexHull(cloud, False, "")


def mesh_hull(vertices, name: str) -> coal.ConvexBase:
    """The convex hull of a mesh's vertices (k, 3); logs a note when the mesh is not convex."""
    count = len(vertices) if isinstance(vertices, (np.ndarray, list, tuple)) else 0
    if count > MAX_HULL_POINTS:  # as_points' "expected (k, 3) points with …" named no fix
        raise InputError(
            f"{name}: the mesh has {count} vertices, more than {MAX_HULL_POINTS}; only its "
            "convex hull is used: simplify (decimate) the mesh or give its hull"
        )
    pts = as_points(vertices, name)
    hull_pts, hull = hull_vertices(pts, name)
    depth = _deepest_inside(pts, hull, _convex_tolerance(pts))
    if depth > _convex_tolerance(pts):
        log.info(
            "%s: the mesh is not convex (a vertex lies %.3g m inside its hull); using its "
            "convex hull",
            name,
            depth,
        )
    return _coal_hull(hull_pts)


def is_convex_mesh(vertices) -> bool:
    """True when no vertex lies deeper than CONVEX_TOLERANCE · diameter inside the hull."""
    pts = as_points(vertices, "mesh")
    _, hull = hull_vertices(pts, "mesh")
    return _deepest_inside(pts, hull, _convex_tolerance(pts)) <= _convex_tolerance(pts)


def _convex_tolerance(pts: np.ndarray) -> float:
    """CONVEX_TOLERANCE · the diameter (m) of points (k, 3)."""
    return CONVEX_TOLERANCE * float(np.linalg.norm(pts.max(0) - pts.min(0)))


def _deepest_inside(pts: np.ndarray, hull: ConvexHull, enough: float) -> float:
    """Depth (m) inside the hull of the deepest point, min over facets of −(n·p + b) (n unit),
    or of the first point found deeper than ``enough``. Only points that are not hull
    vertices are measured, nearest the centre first, in blocks of at most DEPTH_BLOCK
    (facet, point) entries: one (facets, k) array of a 20 000-vertex sphere took 6 GB."""
    inner = np.setdiff1d(np.arange(len(pts)), hull.vertices)
    centre = pts[hull.vertices].mean(axis=0)
    inner = inner[np.argsort(np.linalg.norm(pts[inner] - centre, axis=1))]
    normals, offsets = hull.equations[:, :3], hull.equations[:, 3]
    step, deepest = max(1, DEPTH_BLOCK // len(normals)), 0.0
    for start in range(0, len(inner), step):
        block = pts[inner[start : start + step]] @ normals.T + offsets  # (b, facets) ≤ 0 inside
        deepest = max(deepest, float(np.max(-np.max(block, axis=1))))
        if deepest > enough:
            break
    return deepest


def existing_file(path, what: str) -> Path:
    """``path`` as a Path, UnknownNameError "<what> <path> does not exist" unless it is a file
    (InputError when it is no str or path-like: Path(3) raised TypeError)."""
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(f"{what}: expected a file path, got {type(path).__name__}")
    path = Path(path)
    try:
        found = path.is_file()
    except (OSError, ValueError):  # a name too long, a NUL byte
        found = False
    if not found:
        raise UnknownNameError(f"{what} {path} does not exist (or is not a file)")
    return path


def load_mesh(path, scale=(1.0, 1.0, 1.0), name: str = "mesh") -> coal.ConvexBase:
    """The convex hull of the mesh file ``path`` (STL, OBJ, DAE, … via coal's assimp loader).

    ``scale``: per-axis factors applied to the file's coordinates (a file in millimetres
    needs 1e-3). UnknownNameError for a missing file, InputError for one that is not a mesh.
    """
    path = existing_file(path, f"{name}: mesh file")
    items = np.asarray(scale, dtype=object)
    ok = items.shape == (3,) and all(is_number(x) for x in items)
    factors = items.astype(float) if ok else np.zeros(3)
    if not ok or not np.all(np.isfinite(factors)) or np.any(factors <= 0):
        raise InputError(f"{name}.scale: expected three positive numbers, got {scale!r}")
    # read and checked (finite, bounded) before anything computes with them: coal's own
    # loader prints "eigen: too many iterations" for a NaN vertex
    vertices = mesh_vertices(path, factors, f"{name}: mesh file {path.name}")
    return mesh_hull(vertices, f"{name} ({path.name})")


def bvh_vertices(geometry) -> np.ndarray:
    """Vertices (k, 3) of a coal BVH mesh (or the points of a convex shape)."""
    if hasattr(geometry, "vertices"):
        return np.asarray(geometry.vertices(), dtype=float)
    return np.asarray(geometry.points(), dtype=float)


def bounding_sphere(shape) -> tuple[np.ndarray, float]:
    """Centre (3,) in the shape's frame and radius (m) of a sphere enclosing the shape: coal's
    local AABB centre and the radius of the sphere around that box."""
    shape.computeLocalAABB()
    return np.array(shape.aabb_center, dtype=float), float(shape.aabb_radius)


__all__ = [
    "MAX_COORDINATE",
    "MIN_SIZE",
    "REL_THICKNESS",
    "as_pose",
    "as_rotation",
    "bounding_sphere",
    "box",
    "capsule",
    "check_shape",
    "convex",
    "cylinder",
    "is_convex_mesh",
    "load_mesh",
    "mesh_hull",
    "sphere",
]
