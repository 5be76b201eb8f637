"""3-D scenes from a problem file's tables: ``[robot]`` (:mod:`gdnplan.arm3d.robot_file3d`: a
built-in 3-D robot or a URDF, and an object it holds), ``[scene3d]`` (a random-box generator and
posed obstacles, :mod:`gdnplan.arm3d.shape_file3d`) and a ``[goal] pose``.
``docs/problem_file_3d.md`` is the schema; every bad value is a one-line
:class:`~gdnplan.errors.ProblemFileError` naming it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import GdnplanError, InputError, ProblemFileError
from ..scene import no_unknown_keys
from .ik3d import solve_pose_ik
from .robot3d import Robot3D
from .robot_file3d import ROBOT3D_KEYS, robot_from_table
from .scene3d import Obstacle3D, Scene3D, random_boxes
from .shape_file3d import (
    OBSTACLE3D_KEYS,
    POSE_KEYS,
    ROTATION_KEYS,
    obstacle_from_table,
    rotation_of,
    rpy_matrix,
)

SCENE3D_KEYS = frozenset({"random_boxes", "obstacles"})
RANDOM_BOXES_KEYS = frozenset({"n", "seed", "size", "base_clearance"})
POSE_GOAL_KEYS = frozenset({"position", "frame", *ROTATION_KEYS})


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


__all__ = [  # OBSTACLE3D_KEYS … rpy_matrix: re-exported from where they now live
    "OBSTACLE3D_KEYS",
    "POSE_GOAL_KEYS",
    "POSE_KEYS",
    "RANDOM_BOXES_KEYS",
    "ROBOT3D_KEYS",
    "ROTATION_KEYS",
    "SCENE3D_KEYS",
    "obstacle_from_table",
    "pose_goal",
    "robot_from_table",
    "rpy_matrix",
    "scene3d_from_config",
]
