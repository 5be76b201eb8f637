"""The ``[robot]`` table of a 3-D problem file: a built-in 3-D robot or a URDF, and an object
it holds.

``name`` (ur5e, panda, ur5; ``finger``: each gripper finger's opening in m) or ``urdf`` (+
``srdf``, ``package_dirs``, ``joints``, ``locked``, ``contact_only``: [link, link] pairs checked
for contact only, :mod:`gdnplan.arm3d.pairs`), and an optional ``[robot.held]`` table: a
shape (the keys of an obstacle, :mod:`gdnplan.arm3d.shape_file3d`) whose ``position`` and
rotation are its pose ᶠM_obj in the tool frame f (``frame``, default the robot's tool frame),
attached by :func:`gdnplan.arm3d.held.hold`. ``docs/problem_file_3d.md`` is the schema; every
bad value is a one-line :class:`~gdnplan.errors.ProblemFileError` naming it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import GdnplanError, ProblemFileError
from ..limits import is_number
from ..scene import no_unknown_keys
from ..ur5e.gripper import MAX_OPENING
from .builtin import load_robot3d, panda3d, ur5e3d
from .held import hold
from .robot3d import Robot3D, robot3d_from_urdf
from .shape_file3d import file_path, posed_shape

ROBOT3D_KEYS = frozenset(
    {"name", "finger", "urdf", "srdf", "package_dirs", "joints", "locked", "held", "contact_only"}
)
FINGERS = {"ur5e": (ur5e3d, MAX_OPENING / 2), "panda": (panda3d, 0.04)}  # name -> (make, max m)
HELD_FRAME_KEY = "frame"  # [robot.held]'s own key besides a posed shape's (POSE_KEYS, sizes)


def robot_from_table(table, base_dir: Path) -> Robot3D:
    """The ``[robot]`` of a 3-D file (module doc), paths relative to ``base_dir``."""
    if not isinstance(table, dict):
        raise ProblemFileError("[robot]: expected a table with name = ... or urdf = ...")
    no_unknown_keys(table, ROBOT3D_KEYS, "[robot]")
    if ("name" in table) == ("urdf" in table):
        raise ProblemFileError("[robot]: give exactly one of name (ur5e, panda, ur5) or urdf")
    robot = _builtin(table) if "name" in table else _urdf(table, base_dir)
    if "held" in table:
        robot = held_from_table(robot, table["held"], base_dir)
    return robot


def _builtin(table: dict) -> Robot3D:
    extra = sorted(set(table) - {"name", "finger", "held"})
    if extra:
        raise ProblemFileError(f"[robot] {extra[0]}: only with urdf = ...; a name is built in")
    name = table["name"]
    if not isinstance(name, str):
        raise ProblemFileError(f"[robot] name: expected a string, got {name!r}")
    if "finger" not in table:
        return load_robot3d(name)
    if name not in FINGERS:
        raise ProblemFileError(f"[robot] finger: only for {list(FINGERS)}, not {name!r}")
    make, most = FINGERS[name]
    finger = table["finger"]
    if not is_number(finger) or not 0.0 <= finger <= most:
        raise ProblemFileError(
            f"[robot] finger: expected each finger's opening in [0, {most:g}] m, got {finger!r}"
        )
    return make(finger=float(finger))


def _urdf(table: dict, base_dir: Path) -> Robot3D:
    if "finger" in table:
        raise ProblemFileError("[robot] finger: only with a built-in name; use locked = {...}")
    paths = {
        k: file_path(table[k], base_dir, f"[robot] {k}") for k in ("urdf", "srdf") if k in table
    }
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
        contact_only=table.get("contact_only", ()),
    )


def held_from_table(robot: Robot3D, table, base_dir: Path) -> Robot3D:
    """``robot`` holding the ``[robot.held]`` shape at its pose in the tool frame."""
    where = "[robot.held]"
    part = posed_shape(table, where, base_dir, "held", frozenset({HELD_FRAME_KEY}), solid=True)
    frame = table.get(HELD_FRAME_KEY)
    if frame is not None and not isinstance(frame, str):
        raise ProblemFileError(f"{where} frame: expected a frame name, got {frame!r}")
    placement = np.eye(4)
    placement[:3, :3] = np.asarray(part.pose.getRotation())
    placement[:3, 3] = np.asarray(part.pose.getTranslation())
    try:
        return hold(robot, part.shape, placement, part.name, frame)
    except GdnplanError as e:
        raise ProblemFileError(f"{where}: {e}") from e


__all__ = ["FINGERS", "ROBOT3D_KEYS", "held_from_table", "robot_from_table"]
