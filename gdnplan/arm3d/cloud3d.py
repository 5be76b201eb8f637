"""Point-cloud obstacles: a sensor's points as a coal octree of occupied voxels.

A cloud of k points p_i (m, in the obstacle's frame) becomes the union of the axis-aligned
cubes of edge ``resolution`` r of a grid aligned with that frame that hold a point
(``coal.makeOctree``). Every point lies in an occupied cube, so the octree is a superset of the
points: a distance to it is a lower bound of the distance to the points, within r√3 of it, and
a path certified against the octree is certified against the points (every certificate of
gdnplan is against the octree). A cloud samples surfaces: choose r at least the spacing of
neighbouring points, or the robot may pass between voxels where the real surface is closed.

coal's octree holds coordinates |x| < r · 2¹⁵ only and silently drops points beyond them, so
such clouds are refused (:data:`OCTREE_HALF_CELLS`), as are non-finite coordinates, more than
:data:`MAX_CLOUD_POINTS` points and a resolution outside [:data:`MIN_RESOLUTION`,
:data:`MAX_RESOLUTION`]. A distance to an octree costs about 0.5 µs per occupied voxel (coal
visits them all; a plan evaluates thousands of distances): clouds occupying more than
:data:`MAX_VOXELS` voxels are refused with a coarser resolution to use (2 million points of a
2 m × 1.2 m wall at 1 mm occupied 4.5 million voxels, 0.6 s per distance, and ``gdnplan plan``
ran for hours in its first certificate).

Files (``[[scene3d.obstacles]] type = "cloud"``, ``docs/problem_file_3d.md``): a NumPy ``.npy``
array (k, 3), or a text file of one point per line, ``x y z`` or ``x, y, z`` (``#`` comments).
"""

from __future__ import annotations

import io
import math
import warnings
from dataclasses import replace
from pathlib import Path

import coal
import numpy as np
from numpy.lib import format as fmt

from ..errors import InputError
from ..files import read_input
from ..limits import is_number
from .scene3d import Obstacle3D, obstacle
from .shapes import as_points, existing_file

MAX_CLOUD_POINTS = 2_000_000  # points of one cloud
MIN_RESOLUTION = 1e-3  # m: smallest voxel edge
MAX_RESOLUTION = 1.0  # m: largest voxel edge
OCTREE_HALF_CELLS = 2**15  # coal's octree (depth 16) spans |x| < resolution · 2¹⁵
DEFAULT_RESOLUTION = 0.02  # m
MAX_VOXELS = 50_000  # occupied voxels of one cloud (~0.025 s per distance)


def cloud_points(points, name: str) -> np.ndarray:
    """A finite float (k, 3) point array, 1 ≤ k ≤ MAX_CLOUD_POINTS, |x| ≤ MAX_COORDINATE m;
    else InputError (:func:`~gdnplan.arm3d.shapes.as_points`)."""
    return as_points(points, name, min_points=1, max_points=MAX_CLOUD_POINTS)


def cloud_resolution(value, name: str) -> float:
    """A voxel edge (m) in [MIN_RESOLUTION, MAX_RESOLUTION], else InputError."""
    if not is_number(value) or not MIN_RESOLUTION <= value <= MAX_RESOLUTION:
        shown = value.item() if isinstance(value, np.generic) else value
        raise InputError(
            f"{name}: expected a voxel edge in [{MIN_RESOLUTION:g}, {MAX_RESOLUTION:g}] m, "
            f"got {shown!r}"
        )
    return float(value)


def octree(points, resolution: float = DEFAULT_RESOLUTION, name: str = "cloud") -> coal.OcTree:
    """The coal octree of ``points`` (k, 3) at voxel edge ``resolution`` (m); see the module."""
    return _octree(cloud_points(points, f"{name}.points"), resolution, name)


def _octree(pts: np.ndarray, resolution, name: str) -> coal.OcTree:
    """:func:`octree` of points already checked by :func:`cloud_points`."""
    r = cloud_resolution(resolution, f"{name}.resolution")
    reach = float(np.max(np.abs(pts)))
    if reach >= 0.999 * r * OCTREE_HALF_CELLS:
        raise InputError(
            f"{name}: a point {reach:.4g} m from the cloud's origin is beyond what an octree of "
            f"{r:g} m voxels holds ({r * OCTREE_HALF_CELLS:.4g} m); give the points relative "
            "to a position near them, or a coarser resolution"
        )
    voxels = _voxel_count(pts, r)
    if voxels > MAX_VOXELS:
        coarser = r  # the first of r · 1.5ᵏ (in mm, rounded up) whose voxels fit
        while _voxel_count(pts, coarser) > MAX_VOXELS and coarser < MAX_RESOLUTION:
            coarser = min(math.ceil(1500 * coarser) / 1000, MAX_RESOLUTION)
        fits = _voxel_count(pts, coarser) <= MAX_VOXELS
        fix = f"give resolution = {coarser:g} m or more, or" if fits else "give"
        raise InputError(
            f"{name}: its points occupy {voxels} voxels of {r:g} m, more than {MAX_VOXELS}: "
            f"each distance to it would take about {voxels * 5e-7:.2g} s and a plan needs "
            f"thousands; {fix} fewer points"
        )
    return coal.makeOctree(np.ascontiguousarray(pts), r)


def _voxel_count(pts: np.ndarray, r: float) -> int:
    """Occupied voxels of edge r (m) of points (k, 3) within r · 2¹⁵ of the origin."""
    keys = np.floor(pts / r).astype(np.int64) + OCTREE_HALF_CELLS  # each in [0, 2¹⁶]
    return len(np.unique((keys[:, 0] << 34) | (keys[:, 1] << 17) | keys[:, 2]))


def cloud_obstacle(
    points,
    resolution: float = DEFAULT_RESOLUTION,
    position=(0.0, 0.0, 0.0),
    rotation=None,
    name: str = "cloud",
) -> Obstacle3D:
    """A point cloud (k, 3) in the obstacle's frame (m) as an octree obstacle of voxel edge
    ``resolution`` (m), posed by ``position`` and ``rotation``; it keeps its points."""
    pts = cloud_points(points, f"{name}.points")
    return replace(obstacle(_octree(pts, resolution, name), position, rotation, name), points=pts)


def _load_npy(data: bytes) -> np.ndarray:
    """The array of a ``.npy`` file's bytes, after checking that its header claims no more
    data than the file holds (``np.load`` allocates the claimed size first: a 100-byte file
    whose header claims 10¹¹ points asked for 2 TiB); ValueError naming what is wrong."""
    buf = io.BytesIO(data)
    version = np.lib.format.read_magic(buf)
    readers = {(1, 0): fmt.read_array_header_1_0, (2, 0): fmt.read_array_header_2_0}
    if version not in readers:  # 3.0: UTF-8 field names, never a point array
        raise ValueError(f".npy format version {version[0]}.{version[1]}")
    shape, _, dtype = readers[version](buf)
    claimed, held = math.prod(shape) * dtype.itemsize, len(data) - buf.tell()
    if claimed > held:
        raise ValueError(
            f"its header claims shape {shape}, {claimed:,} bytes, the file holds {held:,}: "
            "truncated or damaged"
        )
    return np.load(io.BytesIO(data), allow_pickle=False)


def read_cloud(path: Path | str, name: str = "cloud") -> np.ndarray:
    """The (k, 3) points of a ``.npy`` file or a text file of ``x y z`` / ``x, y, z`` lines (m);
    UnknownNameError for a missing file, InputError for one that holds no such points."""
    path = existing_file(path, f"{name}: point file")
    data = read_input(path, f"{name}: point file")  # a regular file of at most 256 MiB
    try:
        if path.suffix.lower() == ".npy":
            pts = _load_npy(data)
        else:
            text = data.decode("utf-8-sig").replace(",", " ")  # a BOM some editors write
            with warnings.catch_warnings():  # no data: refused below, with the shape
                warnings.simplefilter("ignore", UserWarning)
                pts = np.loadtxt(text.splitlines(), dtype=float, comments="#", ndmin=2)
    except (OSError, ValueError, UnicodeDecodeError) as e:
        first = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise InputError(f"{name}: {path.name} is not a point file ({first})") from e
    return cloud_points(pts, f"{name} ({path.name})")


__all__ = [
    "DEFAULT_RESOLUTION",
    "MAX_CLOUD_POINTS",
    "MAX_RESOLUTION",
    "MAX_VOXELS",
    "MIN_RESOLUTION",
    "cloud_obstacle",
    "cloud_points",
    "cloud_resolution",
    "octree",
    "read_cloud",
]
