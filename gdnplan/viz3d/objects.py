"""The scene's obstacles as 3-D prisms: convex parts extruded along the plane normal."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..robot import Robot
from ..scene import Scene

DEPTH = 0.4  # m: out-of-plane depth of the extruded obstacles
COLORS = {"storage": 0x9C7A54, "table": 0x8C8C8C, "stick": 0xDAA520}  # 0xRRGGBB by name
OBSTACLE_COLOR = 0x4A7FB5


@dataclass(frozen=True)
class Prism:
    """A convex polygon extruded along its frame's z axis (an obstacle part or the stick).

    Attributes:
        name: viewer name, e.g. ``"storage/3"`` or ``"stick"``.
        polygon: (m, 2) CCW vertices in the frame's x–y plane (m).
        depth: extent along the frame's z, centred on z = 0 (m).
        pose: (4, 4) homogeneous transform frame → world.
        color: 0xRRGGBB.
    """

    name: str
    polygon: np.ndarray
    depth: float
    pose: np.ndarray
    color: int

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """Triangle mesh in the frame: vertices (2m, 3) (bottom ring, then top) and
        outward-facing CCW faces (4m − 4, 3)."""
        m = len(self.polygon)
        half = np.full((m, 1), self.depth / 2)
        vertices = np.vstack([np.hstack([self.polygon, -half]), np.hstack([self.polygon, half])])
        fan = np.arange(1, m - 1)
        top = np.stack([np.full(m - 2, m), m + fan, m + fan + 1], 1)
        bottom = np.stack([np.zeros(m - 2, int), fan + 1, fan], 1)
        i, j = np.arange(m), (np.arange(m) + 1) % m
        sides = np.vstack([np.stack([i, j, m + j], 1), np.stack([i, m + j, m + i], 1)])
        return vertices, np.vstack([bottom, top, sides])

    def world_vertices(self) -> np.ndarray:
        """(2m, 3) mesh vertices in world coordinates (m)."""
        vertices = self.mesh()[0]
        return vertices @ self.pose[:3, :3].T + self.pose[:3, 3]


def tool_offset(robot: Robot) -> float:
    """Out-of-plane coordinate (m, along the plane normal) of the robot's tool frame.

    The tool frame is ``robot.info["tcp_frame"]`` or the model's last frame; planar motion
    keeps its offset constant, so it is evaluated at q = 0.
    """
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.zeros(robot.dof))
    name = robot.info.get("tcp_frame", model.frames[model.nframes - 1].name)
    point = data.oMf[model.getFrameId(name)].translation
    return float(robot.plane.normal @ (point - robot.plane.origin))


def _plane_pose(robot: Robot, uv: np.ndarray, offset: float) -> np.ndarray:
    """(4, 4) frame at plane point ``uv`` (2,), ``offset`` along the normal, axes (u, v, n)."""
    plane = robot.plane
    pose = np.eye(4)
    pose[:3, :3] = np.column_stack([plane.axes[0], plane.axes[1], plane.normal])
    pose[:3, 3] = plane.lift(uv) + offset * plane.normal
    return pose


def _obstacle_names(scene: Scene) -> list[str]:
    """Name of each obstacle: its key in ``scene.info`` (storage, table, stick) or obstacle<i>."""
    names = []
    for i, poly in enumerate(scene.obstacles):
        named = [
            key
            for key in COLORS
            if np.shape(scene.info.get(key)) == poly.shape and np.allclose(scene.info[key], poly)
        ]
        names.append(named[0] if named else f"obstacle{i}")
    return names


def scene_objects(scene: Scene, depth: float = DEPTH) -> list[Prism]:
    """The scene's obstacles as 3-D prisms, one per convex part (what coal checks).

    Each part is centred on its vertex mean (in its frame's x–y = the plane's u–v) and
    extruded by ``depth`` (m) about the tool's out-of-plane offset (:func:`tool_offset`); a
    fetch stick is ``stick_width`` deep. Names: the obstacle's name, with ``/k`` for its k-th
    part when it has several.
    """
    offset = tool_offset(scene.robot)
    names = _obstacle_names(scene)
    counts = np.bincount(scene.part_owner, minlength=len(names))
    seen: dict[int, int] = {}
    objects = []
    for part, owner in zip(scene.obstacle_parts, scene.part_owner, strict=True):
        k = seen[owner] = seen.get(owner, -1) + 1
        name = names[owner]
        centre = part.mean(0)
        objects.append(
            Prism(
                name=name if counts[owner] == 1 else f"{name}/{k}",
                polygon=part - centre,
                depth=scene.info["stick_width"] if name == "stick" else depth,
                pose=_plane_pose(scene.robot, centre, offset),
                color=COLORS.get(name, OBSTACLE_COLOR),
            )
        )
    return objects
