"""3-D scenes: a :class:`~gdnplan.arm3d.robot3d.Robot3D` among posed convex obstacles.

Obstacles are boxes, spheres, cylinders, capsules, convex hulls of points and convex hulls of
mesh files (STL, OBJ, …), each with a world pose: a position (3,) in metres and a rotation as a
quaternion (x, y, z, w) or a 3×3 rotation matrix (:func:`gdnplan.arm3d.shapes.as_pose`).
Every number is validated before coal sees it. A TOML schema comes later; the Python API is::

    scene = Scene3D(robot, [box_obstacle((0.2, 0.2, 0.4), (0.5, 0.0, 0.2)),
                            sphere_obstacle(0.1, (0.3, 0.3, 0.5))])

:func:`random_boxes` draws N axis-aligned boxes in the arm's workspace, clear of its base.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import coal
import numpy as np

from ..errors import InputError
from ..limits import check_int, check_number, is_number, read_only, shown
from ..robot import Robot, check_seed
from .robot3d import Robot3D
from .shapes import (
    as_pose,
    as_vector,
    bounding_sphere,
    box,
    capsule,
    check_shape,
    convex,
    cylinder,
    load_mesh,
    sphere,
)

MAX_OBSTACLES = 10_000
BOX_SIZE = (0.05, 0.2)  # m: random_boxes' default (smallest, largest) side
BASE_CLEARANCE = 0.25  # m: random_boxes' default distance of box centres from the base axis
MIN_ROOM = 1e-2  # random_boxes: least share of its draws that may land in the allowed region


@dataclass(frozen=True)
class Obstacle3D:
    """An obstacle: its coal shape and world placement.

    Attributes:
        name: for messages and reports. shape: the coal shape in its own frame (convex, or an
            octree of a point cloud, :mod:`gdnplan.arm3d.cloud3d`).
        pose: the shape frame's world placement (coal.Transform3s).
        center: (3,) world centre of its bounding sphere (m); radius: that sphere's radius (m).
        points: (k, 3) a point cloud's points in the shape frame (m); None for other shapes.
    """

    name: str
    shape: coal.CollisionGeometry
    pose: coal.Transform3s
    center: np.ndarray
    radius: float
    points: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        """InputError unless the obstacle is one :func:`obstacle` could build: a string name,
        a valid shape (:func:`~gdnplan.arm3d.shapes.check_shape`), a rigid pose, and a sphere
        (center, radius) enclosing the shape: the broad phase skips pairs by it, so a
        hand-built obstacle with a wrong one was never hit."""
        if not isinstance(self.name, str):
            raise InputError(f"name: expected a string, got {self.name!r}")
        check_shape(self.shape, self.name, octree=True)
        if not isinstance(self.pose, coal.Transform3s):
            raise InputError(f"{self.name}.pose: expected a coal.Transform3s, got {self.pose!r}")
        as_pose(self.pose.getTranslation(), self.pose.getRotation(), f"{self.name}.pose")
        center, radius = world_sphere(self.shape, self.pose)
        given = as_vector(self.center, 3, f"{self.name}.center")
        if not is_number(self.radius) or not (
            np.linalg.norm(given - center) + radius <= self.radius + 1e-9 * (1 + radius)
        ):
            raise InputError(
                f"{self.name}: center {given.tolist()} and radius {self.radius!r} m do not "
                f"enclose its shape (its bounding sphere: centre {center.round(6).tolist()}, "
                f"radius {radius:.6g} m); build obstacles with gdnplan.arm3d.obstacle"
            )
        # copies (read-only arrays): the pair tables cache the broad phase from them, and a
        # caller's pose object changed later must not move the obstacle under them
        object.__setattr__(self, "pose", coal.Transform3s(self.pose))
        object.__setattr__(self, "center", read_only(given))
        if self.points is not None:
            object.__setattr__(self, "points", read_only(self.points))


def world_sphere(shape, pose: coal.Transform3s) -> tuple[np.ndarray, float]:
    """World centre (3,) and radius (m) of the bounding sphere of ``shape`` posed at ``pose``."""
    local_center, radius = bounding_sphere(shape)
    center = np.asarray(pose.getRotation()) @ local_center + np.asarray(pose.getTranslation())
    return center, radius


def obstacle(shape, position=(0.0, 0.0, 0.0), rotation=None, name: str = "obstacle"):
    """An :class:`Obstacle3D` of a coal shape (built by :mod:`gdnplan.arm3d.shapes`) posed in
    the world: ``position`` (3,) in m, ``rotation`` a quaternion (x, y, z, w) or a 3×3 matrix."""
    pose = as_pose(position, rotation, name)
    check_shape(shape, name if isinstance(name, str) else "obstacle", octree=True)
    return Obstacle3D(name, shape, pose, *world_sphere(shape, pose))


def box_obstacle(size, position, rotation=None, name: str = "box") -> Obstacle3D:
    """A box of full sides ``size`` (3,) in m, centred at ``position``."""
    return obstacle(box(size, name), position, rotation, name)


def sphere_obstacle(radius, position, name: str = "sphere") -> Obstacle3D:
    """A sphere of ``radius`` (m) centred at ``position``."""
    return obstacle(sphere(radius, name), position, None, name)


def cylinder_obstacle(radius, length, position, rotation=None, name="cylinder") -> Obstacle3D:
    """A cylinder (axis = the rotated z axis), ``radius`` and full ``length`` in m."""
    return obstacle(cylinder(radius, length, name), position, rotation, name)


def capsule_obstacle(radius, length, position, rotation=None, name="capsule") -> Obstacle3D:
    """A capsule (segment of full ``length`` along the rotated z axis, swept by ``radius``)."""
    return obstacle(capsule(radius, length, name), position, rotation, name)


def convex_obstacle(points, position=(0, 0, 0), rotation=None, name="convex") -> Obstacle3D:
    """The convex hull of ``points`` (k, 3) given in the obstacle's frame (m)."""
    return obstacle(convex(points, name), position, rotation, name)


def mesh_obstacle(path, position=(0, 0, 0), rotation=None, scale=(1, 1, 1), name="mesh"):
    """The convex hull of a mesh file (a non-convex mesh logs a note and uses its hull)."""
    return obstacle(load_mesh(path, scale, name), position, rotation, name)


def check_robot3d(robot: object) -> Robot3D:
    """``robot`` when it is a :class:`Robot3D`, else InputError naming it (a planar Robot, None
    or a name raised AttributeError deep inside the 3-D functions that take a robot)."""
    if not isinstance(robot, Robot3D):
        hint = "; a planar Robot belongs in gdnplan.Scene" if isinstance(robot, Robot) else ""
        hint = "; build it with gdnplan.arm3d.load_robot3d" if isinstance(robot, str) else hint
        raise InputError(f"robot: expected a Robot3D, got {type(robot).__name__}{hint}")
    return robot


class Scene3D:
    """A 3-D robot and its obstacles (a sequence of :class:`Obstacle3D`)."""

    def __init__(self, robot: Robot3D, obstacles: Sequence[Obstacle3D] = ()):
        check_robot3d(robot)
        if isinstance(obstacles, Scene3D):
            raise InputError("obstacles: got a Scene3D; pass its obstacles (scene.obstacles)")
        if not isinstance(obstacles, (list, tuple)):
            raise InputError(
                f"obstacles: expected a list of Obstacle3D, got {type(obstacles).__name__}"
            )
        obstacles = tuple(obstacles)
        if len(obstacles) > MAX_OBSTACLES:
            raise InputError(f"obstacles: {len(obstacles)} given, the limit is {MAX_OBSTACLES}")
        for k, o in enumerate(obstacles):
            if not isinstance(o, Obstacle3D):
                raise InputError(f"obstacles[{k}]: expected an Obstacle3D, got {type(o).__name__}")
        self.robot = robot
        self.obstacles = obstacles
        object.__setattr__(self, "_frozen", True)

    def __setattr__(self, name: str, value) -> None:
        """Immutable once built: its checker, pair table and certificates are cached per scene
        object, so a scene whose obstacles were replaced afterwards was certified against the
        old ones (build a new Scene3D instead)."""
        if getattr(self, "_frozen", False):
            raise AttributeError(
                f"Scene3D is immutable: build a new scene instead of setting {name!r}"
            )
        object.__setattr__(self, name, value)

    def __repr__(self) -> str:
        return f"Scene3D({self.robot.name}, {len(self.obstacles)} obstacles)"


def workspace_radius(robot: Robot3D, samples: int = 256, seed: int = 0) -> float:
    """Radius (m) around the base origin that encloses every link shape's bounding sphere at
    ``samples`` random configurations (an estimate of the arm's reach)."""
    check_robot3d(robot)
    check_int(samples, "samples", 1, 10**6)
    rng = np.random.default_rng(check_seed(seed))
    centers = np.array([s.center for s in robot.shapes])
    radii = np.array([s.radius for s in robot.shapes])
    reach = 0.0
    for q in robot.random_configurations(samples, rng):
        tf = robot.shape_placements(q)
        world = np.einsum("sij,sj->si", tf[:, :3, :3], centers) + tf[:, :3, 3]
        reach = max(reach, float(np.max(np.linalg.norm(world, axis=1) + radii)))
    return reach


def random_boxes(
    robot: Robot3D,
    n: int = 20,
    seed: int = 0,
    size: tuple[float, float] = BOX_SIZE,
    base_clearance: float = BASE_CLEARANCE,
) -> Scene3D:
    """N random axis-aligned boxes in the arm's workspace: centres uniform in the upper half
    of the ball of radius :func:`workspace_radius` (z ≥ 0), sides uniform in ``size`` (m),
    centres farther than ``base_clearance`` (m) from the base's vertical axis."""
    check_robot3d(robot)
    check_int(n, "n", 0, MAX_OBSTACLES)
    check_seed(seed)
    if not isinstance(size, (list, tuple, np.ndarray)) or len(size) != 2:  # 3 were cut to 2
        raise InputError(f"size: expected [smallest, largest] side (m), got {shown(size)}")
    lo = check_number(size[0], "size[0]", 0.0, strict=True)
    hi = check_number(size[1], "size[1]", lo)
    clearance = check_number(base_clearance, "base_clearance")
    reach = workspace_radius(robot)
    if clearance >= reach:
        raise InputError(f"base_clearance: {clearance} m leaves no room in reach {reach:.3g} m")
    # draws land in the region with probability p = (π/6)(h/reach)³, h = √(reach² − clearance²)
    # (its volume (2π/3)h³ over the drawn box's 4 reach³): a clearance just below the reach
    # looped (almost) forever
    room = math.pi / 6 * (1.0 - (clearance / reach) ** 2) ** 1.5
    if room < MIN_ROOM:
        most = reach * math.sqrt(1.0 - (6.0 * MIN_ROOM / math.pi) ** (2.0 / 3.0))
        raise InputError(
            f"base_clearance: {clearance} m leaves box centres a sliver of reach "
            f"{reach:.4g} m ({room:.2g} of the draws); give at most {most:.4g} m"
        )
    rng = np.random.default_rng(seed)
    boxes: list[Obstacle3D] = []
    while len(boxes) < n:
        c = rng.uniform(-reach, reach, 3)
        c[2] = abs(c[2])
        if np.linalg.norm(c) > reach or np.linalg.norm(c[:2]) < clearance:
            continue
        boxes.append(box_obstacle(rng.uniform(lo, hi, 3), c, name=f"box{len(boxes)}"))
    return Scene3D(robot, boxes)
