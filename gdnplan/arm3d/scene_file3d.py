"""3-D scenes from a problem file's tables: ``[robot]`` (a built-in 3-D robot or a URDF) and
``[scene3d]`` (a random-box generator and posed obstacles). ``docs/problem_file_3d.md`` is the
schema; every bad value is a one-line :class:`~gdnplan.errors.ProblemFileError` naming it.

An obstacle's rotation is one of ``quaternion = [x, y, z, w]`` (normalised),
``rpy = [roll, pitch, yaw]`` (rad, URDF's convention R = R_z(yaw) R_y(pitch) R_x(roll)) or
``matrix = [[…], […], […]]`` (rows, orthonormal with determinant +1); none: the identity.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..errors import GdnplanError, InputError, ProblemFileError
from ..limits import is_number
from ..scene import no_unknown_keys
from .builtin import load_robot3d
from .ik3d import solve_pose_ik
from .robot3d import Robot3D, robot3d_from_urdf
from .scene3d import (
    Obstacle3D,
    Scene3D,
    box_obstacle,
    capsule_obstacle,
    convex_obstacle,
    cylinder_obstacle,
    mesh_obstacle,
    random_boxes,
    sphere_obstacle,
)
from .shapes import as_vector

ROBOT3D_KEYS = frozenset({"name", "urdf", "srdf", "package_dirs", "joints", "locked"})
SCENE3D_KEYS = frozenset({"random_boxes", "obstacles"})
RANDOM_BOXES_KEYS = frozenset({"n", "seed", "size", "base_clearance"})
ROTATION_KEYS = ("quaternion", "rpy", "matrix")
POSE_GOAL_KEYS = frozenset({"position", "frame", *ROTATION_KEYS})
POSE_KEYS = frozenset({"type", "name", "position", *ROTATION_KEYS})
OBSTACLE3D_KEYS = {  # type -> its own keys besides POSE_KEYS
    "box": frozenset({"size"}),
    "sphere": frozenset({"radius"}),
    "cylinder": frozenset({"radius", "length"}),
    "capsule": frozenset({"radius", "length"}),
    "convex": frozenset({"points"}),
    "mesh": frozenset({"file", "scale"}),
}


def rpy_matrix(rpy) -> np.ndarray:
    """R = R_z(yaw) R_y(pitch) R_x(roll) (URDF's fixed-axis roll-pitch-yaw), rpy in rad."""
    r, p, y = as_vector(rpy, 3, "rpy")
    cr, sr, cp, sp, cy, sy = (f(a) for a in (r, p, y) for f in (math.cos, math.sin))
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def robot_from_table(table, base_dir: Path) -> Robot3D:
    """The ``[robot]`` of a 3-D file: ``name`` (ur5e, panda, ur5) or ``urdf`` (+ ``srdf``,
    ``package_dirs``, ``joints``, ``locked``), paths relative to ``base_dir``."""
    if not isinstance(table, dict):
        raise ProblemFileError("[robot]: expected a table with name = ... or urdf = ...")
    no_unknown_keys(table, ROBOT3D_KEYS, "[robot]")
    if ("name" in table) == ("urdf" in table):
        raise ProblemFileError("[robot]: give exactly one of name (ur5e, panda, ur5) or urdf")
    if "name" in table:
        extra = sorted(set(table) - {"name"})
        if extra:
            raise ProblemFileError(f"[robot] {extra[0]}: only with urdf = ...; a name is built in")
        if not isinstance(table["name"], str):
            raise ProblemFileError(f"[robot] name: expected a string, got {table['name']!r}")
        return load_robot3d(table["name"])
    paths = {k: _path(table[k], base_dir, f"[robot] {k}") for k in ("urdf", "srdf") if k in table}
    dirs = table.get("package_dirs", [])
    joints = table.get("joints")
    locked = table.get("locked", {})
    if not isinstance(dirs, list) or not all(isinstance(d, str) for d in dirs):
        raise ProblemFileError("[robot] package_dirs: expected a list of folder paths")
    if joints is not None and (
        not isinstance(joints, list) or not all(isinstance(j, str) for j in joints)
    ):
        raise ProblemFileError("[robot] joints: expected a list of joint names")
    if not isinstance(locked, dict) or not all(is_number(v) for v in locked.values()):
        raise ProblemFileError("[robot] locked: expected a table joint name = value")
    return robot3d_from_urdf(
        paths["urdf"],
        [base_dir / d for d in dirs],
        joints=joints,
        locked={k: float(v) for k, v in locked.items()},
        srdf=paths.get("srdf"),
    )


def _path(value, base_dir: Path, where: str) -> Path:
    if not isinstance(value, str) or not value:
        raise ProblemFileError(f"{where}: expected a file path, got {value!r}")
    return base_dir / value


def rotation_of(table: dict, where: str):
    """The rotation an obstacle table gives (quaternion, rpy or matrix; None: identity)."""
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


def obstacle_from_table(table, k: int, base_dir: Path) -> Obstacle3D:
    """``[[scene3d.obstacles]]`` entry k as an :class:`Obstacle3D`."""
    where = f"[[scene3d.obstacles]] {k}"
    if not isinstance(table, dict):
        raise ProblemFileError(f"{where}: expected a table with type = ...")
    kind = table.get("type")
    if not isinstance(kind, str) or kind not in OBSTACLE3D_KEYS:
        raise ProblemFileError(
            f"{where} type: expected one of {list(OBSTACLE3D_KEYS)}, got {kind!r}"
        )
    no_unknown_keys(table, POSE_KEYS | OBSTACLE3D_KEYS[kind], where)
    missing = sorted(OBSTACLE3D_KEYS[kind] - {"scale"} - set(table))
    if missing:
        raise ProblemFileError(f"{where} {missing[0]}: missing for a {kind}")
    name = table.get("name", f"{kind}{k}")
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
        path = _path(table["file"], base_dir, f"{where} file")
        return mesh_obstacle(path, position, rotation, table.get("scale", [1, 1, 1]), name)
    except ProblemFileError:
        raise
    except GdnplanError as e:
        raise ProblemFileError(f"{where} ({name}): {e}") from e


def pose_goal(scene: Scene3D, table, reference, margin: float) -> np.ndarray:
    """The joint goal (dof,) of ``[goal] pose = {position = [x, y, z], quaternion | rpy |
    matrix = …, frame = "…"}``: the tool frame's pose IK
    (:func:`gdnplan.arm3d.ik3d.solve_pose_ik`) clear of ``margin`` (m), nearest ``reference``
    (the start). InfeasibleProblemError when no collision-free IK solution exists."""
    where = "[goal] pose"
    if not isinstance(table, dict):
        raise ProblemFileError(f"{where}: expected a table {{position = [x, y, z], rpy = [...]}}")
    no_unknown_keys(table, POSE_GOAL_KEYS, where)
    if "position" not in table:
        raise ProblemFileError(f"{where} position: missing; give the tool position [x, y, z] (m)")
    frame = table.get("frame")
    if frame is not None and not isinstance(frame, str):
        raise ProblemFileError(f"{where} frame: expected a frame name, got {frame!r}")
    rotation = rotation_of(table, where)
    try:
        solved = solve_pose_ik(scene, table["position"], rotation, reference, frame, margin)
    except ProblemFileError:
        raise
    except InputError as e:
        raise ProblemFileError(f"{where}: {e}") from e
    return solved.q


def scene3d_from_config(cfg: dict, base_dir=None) -> Scene3D:
    """The :class:`Scene3D` of a parsed 3-D problem file (``[robot]`` and ``[scene3d]``);
    random boxes first (named box0 …), then the listed obstacles."""
    base = Path(base_dir) if base_dir is not None else Path.cwd()
    if "robot" not in cfg:
        raise ProblemFileError("[robot]: missing table; name a 3-D robot (ur5e, panda, ur5)")
    try:
        robot = robot_from_table(cfg["robot"], base)
    except ProblemFileError:
        raise
    except GdnplanError as e:
        raise ProblemFileError(f"[robot]: {e}") from e
    table = cfg["scene3d"]
    if not isinstance(table, dict):
        raise ProblemFileError("[scene3d]: expected a table")
    no_unknown_keys(table, SCENE3D_KEYS, "[scene3d]")
    obstacles: list[Obstacle3D] = []
    if "random_boxes" in table:
        obstacles += _random_boxes(table["random_boxes"], robot)
    listed = table.get("obstacles", [])
    if not isinstance(listed, list):
        raise ProblemFileError("[scene3d] obstacles: expected [[scene3d.obstacles]] tables")
    obstacles += [obstacle_from_table(t, k, base) for k, t in enumerate(listed)]
    try:
        return Scene3D(robot, obstacles)
    except GdnplanError as e:
        raise ProblemFileError(f"[scene3d]: {e}") from e


def _random_boxes(spec, robot: Robot3D) -> list[Obstacle3D]:
    where = "[scene3d] random_boxes"
    if not isinstance(spec, dict):
        raise ProblemFileError(f"{where}: expected a table {{n = 20, seed = 0}}")
    no_unknown_keys(spec, RANDOM_BOXES_KEYS, where)
    options = dict(spec)
    if "size" in options:
        size = options["size"]
        if not (isinstance(size, list) and len(size) == 2):
            raise ProblemFileError(f"{where} size: expected [smallest, largest] side (m)")
        options["size"] = tuple(size)
    for key in ("n", "seed"):
        if key in options and (type(options[key]) is not int or options[key] < 0):
            raise ProblemFileError(f"{where} {key}: expected an integer ≥ 0, got {options[key]!r}")
    try:
        return list(random_boxes(robot, **options).obstacles)
    except (GdnplanError, TypeError) as e:
        raise ProblemFileError(f"{where}: {e}") from e


__all__ = [
    "OBSTACLE3D_KEYS",
    "POSE_GOAL_KEYS",
    "POSE_KEYS",
    "RANDOM_BOXES_KEYS",
    "ROBOT3D_KEYS",
    "SCENE3D_KEYS",
    "pose_goal",
    "rpy_matrix",
    "scene3d_from_config",
]
