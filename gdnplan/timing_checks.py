"""Input checks of the time parametrisation (:mod:`gdnplan.timing`): velocity and
acceleration limits, waypoints, and a robot's URDF velocity limits.

Limits are finite and within :data:`LIMIT_RANGE`, waypoints finite and within
:data:`MAX_ANGLE`, so a path's times and their squares stay finite in float64; anything else is
an :class:`~gdnplan.errors.InputError` naming the argument.
"""

from __future__ import annotations

import numpy as np

from .arm3d.robot3d import Robot3D
from .errors import InputError
from .limits import is_number, shown
from .robot import Robot

LIMIT_RANGE = (1e-6, 1e9)  # max_velocity (rad/s) and max_acceleration (rad/s²) allowed
MAX_ANGLE = 1e6  # rad, |q| of a waypoint: beyond it the times' squares could overflow


def limit_vector(value, dof: int, name: str, unit: str) -> np.ndarray:
    """(dof,) limits from one number or dof numbers, each in :data:`LIMIT_RANGE` (10⁻⁶ … 10⁹
    ``unit``; beyond it a path's times or their squares leave float64), else InputError."""
    if is_number(value):
        value = [value] * dof
    listed = isinstance(value, (list, tuple)) or (isinstance(value, np.ndarray) and value.ndim == 1)
    items = list(value) if listed else None  # a 0-d or 2-d array is neither (list() fails)
    if items is None or len(items) != dof or not all(is_number(x) for x in items):
        raise InputError(f"{name}: expected a number or {dof} numbers ({unit}), got {shown(value)}")
    out = np.asarray(items, float)
    if not np.all(np.isfinite(out) & (out > 0)):
        raise InputError(f"{name}: expected finite limits > 0 ({unit}), got {out.tolist()}")
    low, high = LIMIT_RANGE
    if not np.all((out >= low) & (out <= high)):
        raise InputError(
            f"{name}: expected limits in [{low:g}, {high:g}] {unit}, got {out.tolist()}"
        )
    return out


def check_waypoints(q) -> np.ndarray:
    """q as float64 (T, dof) waypoints, T ≥ 1, dof ≥ 1, real and finite with |q| ≤
    :data:`MAX_ANGLE` rad, else InputError naming ``q``."""
    try:
        arr = np.asarray(q)
    except (TypeError, ValueError) as e:
        raise InputError(f"q: expected (T, dof) waypoints (rad), got {type(q).__name__}") from e
    if arr.dtype.kind not in "iuf":
        raise InputError(f"q: expected real numbers (rad), got an array of {arr.dtype}")
    if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise InputError(f"q: expected (T, dof) waypoints with T, dof ≥ 1, got shape {arr.shape}")
    arr = arr.astype(float)
    if not np.all(np.isfinite(arr)):
        raise InputError(f"q: expected finite (T, dof) waypoints (rad), got shape {arr.shape}")
    if np.max(np.abs(arr)) > MAX_ANGLE:
        raise InputError(f"q: waypoints beyond ±{MAX_ANGLE:g} rad are no joint angles")
    return arr


def urdf_velocity(robot: Robot | Robot3D) -> np.ndarray:
    """(dof,) velocity limits of the robot's URDF (rad/s); InputError naming the first joint
    whose limit is missing (URDF velocity="0"; a continuous joint without <limit> gives inf)."""
    v = np.asarray(robot.model.velocityLimit, float)
    bad = np.flatnonzero(~(np.isfinite(v) & (v > 0)))
    if len(bad):
        j = int(bad[0])
        raise InputError(
            f"max_velocity: joint {robot.joint_names[j]!r} of robot {robot.name!r} has velocity "
            f"limit {v[j]:g} in its URDF; set <limit velocity=...> (rad/s) there or pass "
            "max_velocity"
        )
    return v


def check_scene_dof(scene, dof: int) -> None:
    """InputError unless ``scene`` is a scene whose robot has ``dof`` joints (the path's
    columns)."""
    robot = getattr(scene, "robot", None)
    joints = getattr(robot, "dof", None)
    if joints is None:
        raise InputError(f"scene: expected a Scene or Scene3D, got {type(scene).__name__}")
    if joints != dof:
        raise InputError(f"scene: its robot has {joints} joints, q has {dof} columns")


__all__ = [
    "LIMIT_RANGE",
    "MAX_ANGLE",
    "check_scene_dof",
    "check_waypoints",
    "limit_vector",
    "urdf_velocity",
]
