"""Input checks of planar scenes (:mod:`gdnplan.scene`): the robot, the obstacles, and the
problem-file tables they come from.

A :class:`~gdnplan.scene.Scene` holds a planar :class:`~gdnplan.robot.Robot` and at most
:data:`MAX_OBSTACLES` simple polygons within :func:`coordinate_bound` of joint 1, with at most
:data:`MAX_PARTS` convex parts in all, each thick enough for coal
(:func:`gdnplan.geometry.check_part`); anything else is an :class:`~gdnplan.errors.InputError`
naming it. A problem-file table with unknown keys, or whose values its factory refuses, is a
:class:`~gdnplan.errors.ProblemFileError` naming the table.
"""

from __future__ import annotations

from collections.abc import Callable, Set

import numpy as np

from .errors import InputError, ProblemFileError, UnknownNameError, did_you_mean
from .geometry import as_polygon, check_part, convex_decomposition
from .robot import Robot

MAX_OBSTACLES = 1000  # obstacle polygons of one scene
MAX_PARTS = 500  # convex parts of all obstacles (coal's cost grows with them)
# vertices of all obstacles: a distance call's cost grows with them (coal's support function
# scans a part's vertices): 500 polygons of 2 000 took 14 s per configuration, 10 of 2 000
# 0.16 s (docs/decisions.md#scene-vertex-limit)
MAX_SCENE_VERTICES = 20_000


def coordinate_bound(robot: Robot) -> float:
    """Largest |x|, |y| offset (m) of an obstacle vertex from joint 1: max(100 m, 100 × reach).
    Farther obstacles can never touch the arm, and huge coordinates (1e300) crashed coal."""
    return max(100.0, 100.0 * robot.reach)


def describe(value) -> str:
    """A value's type for messages, with the value itself when it is short (``str 'b'``)."""
    text = repr(value)
    return type(value).__name__ + (f" {text}" if len(text) <= 40 else "")


def check_robot(robot) -> None:
    """InputError unless ``robot`` is a planar :class:`Robot` (a Robot3D belongs in a Scene3D)."""
    if isinstance(robot, Robot):
        return
    from .arm3d.robot3d import Robot3D  # on demand: arm3d imports this module

    if isinstance(robot, Robot3D):
        raise InputError("robot: a 3-D robot (Robot3D): use gdnplan.arm3d.Scene3D")
    raise InputError(f"robot: expected a Robot (gdnplan.load_robot), got {describe(robot)}")


def check_obstacles(obstacles, robot: Robot) -> tuple[np.ndarray, ...]:
    """``obstacles`` as a tuple of checked CCW polygons (:func:`gdnplan.geometry.as_polygon`):
    at most :data:`MAX_OBSTACLES` of them, every vertex within :func:`coordinate_bound` of the
    robot's joint 1, every convex part passing :func:`gdnplan.geometry.check_part`, at most
    :data:`MAX_PARTS` parts and :data:`MAX_SCENE_VERTICES` vertices in all; else InputError
    naming the obstacle (checked one obstacle at a time: the first past a limit stops)."""
    if not isinstance(obstacles, (list, tuple, np.ndarray)):
        got = describe(obstacles)
        raise InputError(f"obstacles: expected a list of (m, 2) polygons, got {got}")
    if len(obstacles) > MAX_OBSTACLES:
        raise InputError(f"obstacles: {len(obstacles)} polygons, the limit is {MAX_OBSTACLES}")
    bound = coordinate_bound(robot)
    base = robot.chain.joint_origins[0]
    checked, parts, vertices = [], 0, 0
    for i, raw in enumerate(obstacles):  # one at a time: the first past a limit stops the work
        poly = as_polygon(raw, f"obstacles[{i}]")
        vertices += len(poly)
        if vertices > MAX_SCENE_VERTICES:
            raise InputError(
                f"obstacles: more than {MAX_SCENE_VERTICES} vertices by obstacles[{i}] "
                f"({vertices} so far), the limit (every distance call scans them); simplify "
                "the polygons"
            )
        far = float(np.max(np.abs(poly - base)))
        if far > bound:
            raise InputError(
                f"obstacles[{i}]: a vertex is {far:.3g} m from the robot's base, the limit "
                f"is {bound:.3g} m (max(100 m, 100 × reach)); remove or move the obstacle"
            )
        pieces = convex_decomposition(poly)
        parts += len(pieces)
        if parts > MAX_PARTS:  # before their checks (1000 star polygons took minutes)
            raise InputError(
                f"obstacles: more than {MAX_PARTS} convex parts by obstacles[{i}] ({parts} so "
                "far), the limit; use fewer or simpler (less non-convex) obstacles"
            )
        for part in pieces:
            check_part(part, f"obstacles[{i}]")
        checked.append(poly)
    return tuple(checked)


def no_unknown_keys(table: dict, allowed: Set[str], where: str) -> None:
    """ProblemFileError naming the keys of ``table`` not in ``allowed`` and listing these."""
    unknown = sorted(set(table) - allowed)
    if unknown:
        hint = did_you_mean(unknown[0], allowed)
        raise ProblemFileError(
            f"{where}: unknown key(s) {unknown}{hint}; allowed: {sorted(allowed)}", schema=True
        )


def call_reporting(where: str, factory: Callable, *args, **options):
    """factory(*args, **options), with an unsupported option or a bad value (TypeError,
    InputError) reported as a ProblemFileError naming the table."""
    try:
        return factory(*args, **options)
    except UnknownNameError:
        raise
    except (TypeError, InputError) as e:
        raise ProblemFileError(f"{where}: {e}") from e


__all__ = [
    "MAX_OBSTACLES",
    "MAX_PARTS",
    "MAX_SCENE_VERTICES",
    "call_reporting",
    "check_obstacles",
    "check_robot",
    "coordinate_bound",
    "describe",
    "no_unknown_keys",
]
