"""Posed shapes in 3-D problem files: one table gives a shape (``type`` and its sizes) and its
pose (``position`` and a rotation), as ``[[scene3d.obstacles]]`` and ``[robot.held]`` do.

A rotation is one of ``quaternion = [x, y, z, w]`` (normalised), ``rpy = [roll, pitch, yaw]``
(rad, URDF's convention R = R_z(yaw) R_y(pitch) R_x(roll)) or ``matrix = [[…], […], […]]``
(rows, orthonormal with determinant +1); none: the identity. ``docs/problem_file_3d.md`` is the
schema; every bad value is a one-line :class:`~gdnplan.errors.ProblemFileError` naming it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..errors import GdnplanError, InputError, ProblemFileError
from ..limits import is_number
from ..scene import no_unknown_keys
from .cloud3d import DEFAULT_RESOLUTION, cloud_obstacle, read_cloud
from .scene3d import (
    Obstacle3D,
    box_obstacle,
    capsule_obstacle,
    convex_obstacle,
    cylinder_obstacle,
    mesh_obstacle,
    sphere_obstacle,
)

ROTATION_KEYS = ("quaternion", "rpy", "matrix")
MAX_RPY = 1e3  # rad: largest |angle| of an rpy (as a URDF origin's, xml_checks.MAX_ANGLE)
POSE_KEYS = frozenset({"type", "name", "position", *ROTATION_KEYS})
OBSTACLE3D_KEYS = {  # type -> its own keys besides POSE_KEYS
    "box": frozenset({"size"}),
    "sphere": frozenset({"radius"}),
    "cylinder": frozenset({"radius", "length"}),
    "capsule": frozenset({"radius", "length"}),
    "convex": frozenset({"points"}),
    "mesh": frozenset({"file", "scale"}),
    "cloud": frozenset({"points", "file", "resolution"}),
}
OPTIONAL3D_KEYS = {"mesh": frozenset({"scale"}), "cloud": OBSTACLE3D_KEYS["cloud"]}


def rpy_matrix(rpy) -> np.ndarray:
    """R = R_z(yaw) R_y(pitch) R_x(roll) (URDF's fixed-axis roll-pitch-yaw), rpy in rad:
    three finite numbers within ±MAX_RPY rad, else InputError."""
    items = np.asarray(rpy, dtype=object)
    if items.shape != (3,) or not all(is_number(x) for x in items):
        raise InputError(f"rpy: expected 3 numbers (rad), got {rpy!r}")
    r, p, y = items.astype(float)
    if not all(math.isfinite(a) and abs(a) <= MAX_RPY for a in (r, p, y)):
        raise InputError(  # as_vector's "values beyond 1000 m; use metres" named no angle
            f"rpy: expected finite angles within ±{MAX_RPY:g} rad, got {rpy!r}"
        )
    cr, sr, cp, sp, cy, sy = (f(a) for a in (r, p, y) for f in (math.cos, math.sin))
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def file_path(value, base_dir: Path, where: str) -> Path:
    """``value`` (a non-empty string) as a path relative to ``base_dir``."""
    if not isinstance(value, str) or not value:
        raise ProblemFileError(f"{where}: expected a file path, got {value!r}")
    return base_dir / value


MAX_QUATERNION = 1e3  # largest |component| of a quaternion (it is normalised; 1 is usual)


def check_quaternion(value: list, where: str) -> None:
    """ProblemFileError naming ``where`` quaternion unless ``value`` (4 items) is 4 finite
    numbers, none beyond :data:`MAX_QUATERNION`, of nonzero length (computed without
    overflow); the length is normalised away, so give a unit quaternion."""
    if not all(is_number(x) for x in value):
        return  # as_rotation names a non-number
    quat = np.asarray(value, float)
    if not np.all(np.isfinite(quat)):
        raise ProblemFileError(
            f"{where} quaternion: {value!r} is not finite; give a unit quaternion [x, y, z, w]"
        )
    big = float(np.max(np.abs(quat)))
    length = big * float(np.linalg.norm(quat / big)) if big > 0 else 0.0  # no overflow
    if big > MAX_QUATERNION or length < 1e-9:
        raise ProblemFileError(
            f"{where} quaternion: {value!r} has length {length:.3g}, not near 1; give a unit "
            "quaternion [x, y, z, w] (a rotation, not a position; zero length is refused)"
        )


def rotation_of(table: dict, where: str):
    """The rotation a table gives (quaternion, rpy or matrix; None: identity)."""
    given = [k for k in ROTATION_KEYS if k in table]
    if len(given) > 1:
        raise ProblemFileError(f"{where}: give at most one of {', '.join(given)}")
    if not given:
        return None
    key = given[0]
    value = table[key]
    if key == "rpy":
        return rpy_matrix_checked(value, f"{where} rpy")
    if key == "quaternion" and not (isinstance(value, list) and len(value) == 4):
        raise ProblemFileError(f"{where} quaternion: expected [x, y, z, w], got {value!r}")
    if key == "quaternion":
        check_quaternion(value, where)
    if key == "matrix" and not (
        isinstance(value, list) and len(value) == 3 and all(isinstance(r, list) for r in value)
    ):
        raise ProblemFileError(f"{where} matrix: expected 3 rows of 3 numbers, got {value!r}")
    return value


def rpy_matrix_checked(value, where: str) -> np.ndarray:
    try:
        return rpy_matrix(value)
    except GdnplanError as e:
        raise ProblemFileError(f"{where}: expected [roll, pitch, yaw] in rad ({e})") from e


def posed_shape(
    table, where: str, base_dir: Path, default_name: str, extra=frozenset(), solid: bool = False
) -> Obstacle3D:
    """The shape and pose a table gives, as an :class:`Obstacle3D` (its pose in whatever frame
    the table's place in the file means); ``extra``: further keys the caller reads itself;
    ``solid``: refuse a point cloud (a part of the robot must be a solid shape)."""
    if not isinstance(table, dict):
        raise ProblemFileError(f"{where}: expected a table with type = ...")
    kinds = [k for k in OBSTACLE3D_KEYS if not (solid and k == "cloud")]
    kind = table.get("type")
    if not isinstance(kind, str) or kind not in kinds:
        raise ProblemFileError(f"{where} type: expected one of {kinds}, got {kind!r}")
    no_unknown_keys(table, POSE_KEYS | OBSTACLE3D_KEYS[kind] | extra, where)
    missing = sorted(OBSTACLE3D_KEYS[kind] - OPTIONAL3D_KEYS.get(kind, frozenset()) - set(table))
    if missing:
        raise ProblemFileError(f"{where} {missing[0]}: missing for a {kind}")
    name = table.get("name", default_name)
    if not isinstance(name, str):
        raise ProblemFileError(f"{where} name: expected a string, got {name!r}")
    position = table.get("position", [0.0, 0.0, 0.0])
    rotation = rotation_of(table, where)
    try:
        if kind == "box":
            return box_obstacle(table["size"], position, rotation, name)
        if kind == "sphere":
            return sphere_obstacle(table["radius"], position, name)
        if kind in ("cylinder", "capsule"):
            make = cylinder_obstacle if kind == "cylinder" else capsule_obstacle
            return make(table["radius"], table["length"], position, rotation, name)
        if kind == "convex":
            return convex_obstacle(table["points"], position, rotation, name)
        if kind == "cloud":
            return _cloud(table, where, base_dir, position, rotation, name)
        path = file_path(table["file"], base_dir, f"{where} file")
        return mesh_obstacle(path, position, rotation, table.get("scale", [1, 1, 1]), name)
    except ProblemFileError:
        raise
    except GdnplanError as e:
        raise ProblemFileError(f"{where} ({name}): {e}") from e


def _cloud(table: dict, where: str, base_dir: Path, position, rotation, name) -> Obstacle3D:
    """A ``type = "cloud"`` table: exactly one of ``points`` / ``file``, ``resolution`` (m)."""
    given = [k for k in ("points", "file") if k in table]
    if len(given) != 1:
        raise ProblemFileError(
            f"{where}: a cloud takes exactly one of points = [[x, y, z], ...] or file = "
            f'"cloud.npy", got {" and ".join(given) or "neither"}'
        )
    if "file" in table:
        points = read_cloud(file_path(table["file"], base_dir, f"{where} file"), name)
    else:
        points = table["points"]
    resolution = table.get("resolution", DEFAULT_RESOLUTION)
    return cloud_obstacle(points, resolution, position, rotation, name)


def obstacle_from_table(table, k: int, base_dir: Path) -> Obstacle3D:
    """``[[scene3d.obstacles]]`` entry k as an :class:`Obstacle3D` (world pose)."""
    kind = table.get("type") if isinstance(table, dict) else None
    default = f"{kind}{k}" if isinstance(kind, str) else f"obstacle{k}"
    return posed_shape(table, f"[[scene3d.obstacles]] {k}", base_dir, default)


__all__ = [
    "OBSTACLE3D_KEYS",
    "OPTIONAL3D_KEYS",
    "POSE_KEYS",
    "ROTATION_KEYS",
    "file_path",
    "obstacle_from_table",
    "posed_shape",
    "rotation_of",
    "rpy_matrix",
]
