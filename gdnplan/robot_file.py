"""A problem file's own robot: the ``[robot]`` table with ``urdf = "arm.urdf"``.

::

    [robot]
    urdf = "three_link_arm.urdf"          # relative to the problem file's folder, or absolute
    joints = ["shoulder", "elbow", "wrist"]   # planning joints, base to tip
    plane = [[1, 0, 0], [0, 1, 0]]        # world directions of the plane axes u, v
    locked = { tool_roll = 0.0 }          # values of other joints (rad or m; default 0)
    package_dirs = ["meshes"]             # folders searched for package:// meshes
    max_vertices = 12                     # vertices of each projected link polygon
    base_radius = 0.15                    # m kept free of generated obstacles around joint 1
    collision_geometry = true             # project the URDF's <collision> shapes

    [[robot.polygons]]                    # hand-made convex link polygons (any number)
    link = "tool"                         # the link (or frame) it is attached to
    polygon = [[0.5, -0.02], [0.6, -0.02], [0.6, 0.02], [0.5, 0.02]]  # plane coords at q = 0

The robot's name is the URDF's ``<robot name>``, with ``-urdf`` appended when that is a shipped
robot's name (``planar2``, …): learned weights are matched to robots by name.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .errors import InputError, ProblemFileError, UnknownNameError
from .geometry import as_polygon, check_part, is_convex, min_width
from .limits import is_number
from .robot import Robot, robot_names
from .urdf_robot import RobotSpec, load_urdf, robot_from_models

URDF_KEYS = {
    "urdf",
    "joints",
    "plane",
    "locked",
    "package_dirs",
    "max_vertices",
    "base_radius",
    "collision_geometry",
    "polygons",
}
DEFAULT_PLANE = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))


def robot_from_table(table: dict, base_dir: str | Path | None = None) -> Robot:
    """The robot of a ``[robot]`` table with ``urdf`` (schema in the module docstring).

    Args:
        table: the parsed ``[robot]`` table.
        base_dir: folder that relative ``urdf`` and ``package_dirs`` paths start from (the
            problem file's folder); the current directory when None.

    Raises:
        ProblemFileError: a bad key or value, or a robot the URDF cannot give (message starts
            with ``[robot]`` and names the key).
        UnknownNameError: a missing URDF, an unknown joint or link.
    """
    try:
        spec, polygons, skip = _spec(table, Path.cwd() if base_dir is None else Path(base_dir))
        model, geom = load_urdf(spec)
        return robot_from_models(
            user_robot_name(model.name, spec.urdf),
            model,
            geom,
            spec,
            extra_polygons=polygons,
            skip_geometry=lambda _: skip,
            info={"source": "problem file"},
        )
    except UnknownNameError as e:
        raise UnknownNameError(f"[robot] {e}") from e
    except InputError as e:
        raise ProblemFileError(f"[robot] {e}") from e


def user_robot_name(urdf_name: str, urdf: Path) -> str:
    """``Robot.name`` of a problem file's URDF robot: the URDF's robot name (the file's stem when
    empty), with ``-urdf`` appended when it is a shipped robot's name."""
    name = urdf_name.strip() or Path(urdf).stem
    return f"{name}-urdf" if name in robot_names() else name


def _spec(table: dict, base_dir: Path) -> tuple[RobotSpec, list, bool]:
    """RobotSpec, extra polygons and whether to skip the collision geometry of a table."""
    if "name" in table:
        raise ProblemFileError(
            "[robot]: give either name (a shipped robot) or urdf (your own), not both"
        )
    unknown = sorted(set(table) - URDF_KEYS)
    if unknown:
        raise ProblemFileError(
            f"[robot]: unknown key(s) {unknown} for a URDF robot; allowed: {sorted(URDF_KEYS)}"
        )
    urdf = table["urdf"]
    if not isinstance(urdf, str) or not urdf.strip():
        raise ProblemFileError(f"[robot] urdf: expected a file path, got {urdf!r}")
    joints = table.get("joints")
    if joints is None:
        raise ProblemFileError("[robot] joints: missing; list the planning joints, base to tip")
    if not isinstance(joints, list) or not joints or not all(isinstance(j, str) for j in joints):
        raise ProblemFileError(f"[robot] joints: expected a list of joint names, got {joints!r}")
    locked = table.get("locked", {})
    if not isinstance(locked, dict) or not all(is_number(v) for v in locked.values()):
        raise ProblemFileError(
            f"[robot] locked: expected a table joint = value (rad or m), got {locked!r}"
        )
    dirs = table.get("package_dirs", [])
    if not isinstance(dirs, list) or not all(isinstance(d, str) for d in dirs):
        raise ProblemFileError(f"[robot] package_dirs: expected a list of folders, got {dirs!r}")
    collision = table.get("collision_geometry", True)
    if not isinstance(collision, bool):
        raise ProblemFileError(
            f"[robot] collision_geometry: expected true or false, got {collision!r}"
        )
    spec = RobotSpec(
        urdf=base_dir / Path(urdf).expanduser(),
        planning_joints=tuple(joints),
        locked={k: float(v) for k, v in locked.items()},
        plane_axes=table.get("plane", DEFAULT_PLANE),
        package_dirs=tuple(str(base_dir / Path(d).expanduser()) for d in dirs),
        max_vertices=table.get("max_vertices", 12),
        base_radius=table.get("base_radius", 0.15),
    )
    return spec, _polygons(table.get("polygons", [])), not collision


def _polygons(items) -> list[tuple[str, str, np.ndarray]]:
    """``(name, link, vertices)`` of the ``[[robot.polygons]]`` entries."""
    if not isinstance(items, list):
        raise ProblemFileError("[[robot.polygons]]: expected an array of tables")
    out = []
    for i, item in enumerate(items):
        where = f"[[robot.polygons]] #{i}"
        if not isinstance(item, dict) or set(item) != {"link", "polygon"}:
            keys = sorted(item) if isinstance(item, dict) else item
            raise ProblemFileError(f"{where}: expected exactly link and polygon, got {keys!r}")
        if not isinstance(item["link"], str):
            raise ProblemFileError(f"{where} link: expected a link name, got {item['link']!r}")
        try:
            poly = as_polygon(item["polygon"], f"{where} polygon")
        except InputError as e:
            raise ProblemFileError(str(e)) from e
        if not is_convex(poly):
            raise ProblemFileError(
                f"{where} polygon: not convex; split it into several convex [[robot.polygons]]"
            )
        try:
            check_part(poly, f"{where} polygon")
        except InputError as e:
            raise ProblemFileError(
                f"{where} polygon: only {min_width(poly):.3g} m thick; make it thicker"
            ) from e
        out.append((f"{item['link']}_polygon{i}", item["link"], poly))
    return out
