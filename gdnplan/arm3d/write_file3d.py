"""3-D problem files written from Python objects: the inverse of
:mod:`gdnplan.arm3d.scene_file3d` for the shapes a file can name.

:func:`problem_file_text` turns a :class:`~gdnplan.arm3d.scene3d.Scene3D`, its robot's
``[robot]`` table (built-in name or URDF keys, which a Robot3D does not remember), a start and a
goal into the TOML text of ``docs/problem_file_3d.md``: every obstacle as a
``[[scene3d.obstacles]]`` table (:func:`shape_table`: boxes, spheres, cylinders, capsules and
convex hulls, the latter as their points; a mesh file's hull is written as its points), the
robot's held object (:func:`gdnplan.arm3d.held.hold`) as ``[robot.held]`` at its pose in the
tool frame. Numbers are written with Python's shortest round-trip repr, so reading the text back
gives the same floats (:func:`gdnplan.trajopt.Problem.from_toml`).
"""

from __future__ import annotations

import math
import re

import coal
import numpy as np

from ..errors import InputError
from .held import HELD_LINK
from .robot3d import Robot3D
from .scene3d import Obstacle3D, Scene3D

BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")
# TOML basic strings hold no control character (U+0000–U+001F, U+007F) but a tab: an obstacle
# named "a\nb" (a problem file's escape) was written raw and the file could not be read back
_ESCAPES = {chr(c): f"\\u{c:04X}" for c in [*range(0x20), 0x7F] if c != 0x09}
_ESCAPES.update({"\\": "\\\\", '"': '\\"'})


def shape_table(shape, rotation: np.ndarray, position: np.ndarray, name: str, points=None) -> dict:
    """The table of a posed coal shape (type, sizes, name, position, matrix; m); ``points``:
    a point cloud's points (k, 3) when ``shape`` is its octree.

    InputError for a shape a problem file cannot name (an octree without its points, a
    non-convex mesh)."""
    if isinstance(shape, coal.OcTree) and points is not None:
        pts = np.asarray(points, float).tolist()
        sizes = {"type": "cloud", "points": pts, "resolution": float(shape.getResolution())}
    elif isinstance(shape, coal.Box):
        sizes = {"type": "box", "size": (2 * np.asarray(shape.halfSide)).tolist()}
    elif isinstance(shape, coal.Sphere):
        sizes = {"type": "sphere", "radius": float(shape.radius)}
    elif isinstance(shape, (coal.Cylinder, coal.Capsule)):
        kind = "cylinder" if isinstance(shape, coal.Cylinder) else "capsule"
        sizes = {"type": kind, "radius": float(shape.radius), "length": 2 * shape.halfLength}
    elif isinstance(shape, coal.ConvexBase):
        sizes = {"type": "convex", "points": np.asarray(shape.points(), float).tolist()}
    else:
        raise InputError(f"{name}: a {type(shape).__name__} has no problem-file table")
    table = {**sizes, "name": name, "position": np.asarray(position, float).tolist()}
    if not np.array_equal(rotation, np.eye(3)):
        table["matrix"] = np.asarray(rotation, float).tolist()
    return table


def obstacle_table(obstacle: Obstacle3D) -> dict:
    """An obstacle's ``[[scene3d.obstacles]]`` table (world pose)."""
    pose = obstacle.pose
    rotation, position = np.asarray(pose.getRotation()), pose.getTranslation()
    return shape_table(obstacle.shape, rotation, position, obstacle.name, obstacle.points)


def held_table(robot: Robot3D) -> dict | None:
    """The ``[robot.held]`` table of a robot holding an object (None when it holds none)."""
    held = [s for s in robot.shapes if s.link == HELD_LINK]
    if not held:
        return None
    tf = np.asarray(robot.info["held_placement"], float)
    table = shape_table(held[0].shape, tf[:3, :3], tf[:3, 3], robot.info["held"])
    table["frame"] = robot.info["tool_frame"]
    return table


def _value(v) -> str:
    """A TOML value: string, boolean, finite number, list or inline table."""
    if isinstance(v, str):
        return '"' + "".join(_ESCAPES.get(c, c) for c in v) + '"'
    if isinstance(v, bool | np.bool_):
        return "true" if v else "false"
    if isinstance(v, int | np.integer):
        return str(int(v))
    if isinstance(v, float | np.floating):
        if not math.isfinite(v):
            raise InputError(f"problem file: cannot write the number {v!r}")
        return repr(float(v))
    if isinstance(v, list | tuple | np.ndarray):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + "}"
    raise InputError(f"problem file: cannot write a {type(v).__name__}")


def _key(k: str) -> str:
    return k if BARE_KEY.match(k) else _value(k)


def toml_text(cfg: dict, comment: str = "") -> str:
    """TOML text of ``cfg``: top-level tables whose values are values, sub-tables (a dict) or
    arrays of tables (a list of dicts), one level deep as the problem files use them."""
    lines = [f"# {line}" for line in comment.splitlines()]
    for name, table in cfg.items():
        plain = {k: v for k, v in table.items() if not _nested(v)}
        lines += ["", f"[{name}]", *(f"{_key(k)} = {_value(v)}" for k, v in plain.items())]
        for key, value in table.items():
            if isinstance(value, dict):
                lines += ["", f"[{name}.{key}]"]
                lines += [f"{_key(k)} = {_value(v)}" for k, v in value.items()]
            elif _nested(value):
                for entry in value:
                    lines += ["", f"[[{name}.{key}]]"]
                    lines += [f"{_key(k)} = {_value(v)}" for k, v in entry.items()]
    return "\n".join(lines).lstrip("\n") + "\n"


def _nested(v) -> bool:
    return isinstance(v, dict) or (isinstance(v, list) and bool(v) and isinstance(v[0], dict))


def problem_file_text(
    robot_table: dict,
    scene: Scene3D,
    start,
    goal,
    options: dict | None = None,
    tables: dict | None = None,
    comment: str = "",
) -> str:
    """The 3-D problem file of ``scene`` (module doc): ``robot_table`` is its ``[robot]`` without
    ``held`` (added from the robot), ``start``/``goal`` (dof,) joint angles (rad), ``options``
    the ``[options]`` table, ``tables`` planner tables (``{"seed": {...}}``)."""
    robot = dict(robot_table)
    held = held_table(scene.robot)
    if held is not None:
        robot["held"] = held
    cfg = {
        "robot": robot,
        "scene3d": {"obstacles": [obstacle_table(o) for o in scene.obstacles]},
        "start": {"q": np.asarray(start, float).tolist()},
        "goal": {"q": np.asarray(goal, float).tolist()},
    }
    if options:
        cfg["options"] = dict(options)
    cfg.update(tables or {})
    return toml_text(cfg, comment)


__all__ = ["held_table", "obstacle_table", "problem_file_text", "shape_table", "toml_text"]
