"""The meshcat view of a 3-D plan: the arm's link shapes and the obstacles as triangle meshes.

The planar view (:mod:`gdnplan.viz3d.viewer`) rebuilds the full UR5e around a planar plan;
a 3-D plan needs nothing rebuilt. Every link shape of the :class:`~gdnplan.arm3d.Robot3D`
(the geometry coal checks, a held object included) is sent once as its mesh
(:func:`gdnplan.viz3d.meshes.shape_mesh`) in its own frame under ``robot/<shape name>``, every
obstacle under ``scene/<name>`` at its pose, and each frame of the animation sets the shapes'
world placements (4 × 4) from :func:`gdnplan.arm3d.fk3d.shape_placements_batch`.
:func:`scene3d_meshes` and :func:`frames3d` are pure (no meshcat).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..arm3d.fk3d import shape_placements_batch
from ..arm3d.held import HELD_LINK
from ..arm3d.scene3d import Scene3D
from ..errors import InputError
from ..timing import TimedTrajectory
from ..viz import interpolate_path
from .meshes import shape_mesh

ROBOT_COLOR3D = 0xE06A1A  # 0xRRGGBB, the colours of the GIF (gdnplan.viz3d.animate)
HELD_COLOR3D = 0xD9A521
OBSTACLE_COLOR3D = 0x4C80BF


@dataclass(frozen=True)
class Mesh3D:
    """A triangle mesh to send: ``vertices`` (k, 3) m and ``faces`` (f, 3) in its frame,
    ``pose`` (4, 4) frame → world (the first frame's, for robot shapes), ``color`` 0xRRGGBB,
    ``opacity`` in [0, 1]."""

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    pose: np.ndarray
    color: int
    opacity: float = 1.0


def scene3d_meshes(scene: Scene3D, q: np.ndarray) -> list[Mesh3D]:
    """The robot's shapes at q (dof,) (names ``robot/<shape>``) and the obstacles (names
    ``scene/<name>``, half transparent)."""
    robot = scene.robot
    placements = shape_placements_batch(robot, np.asarray(q, float)[None])[0]
    out = []
    for s, pose in zip(robot.shapes, placements, strict=True):
        v, f = shape_mesh(s.shape)
        color = HELD_COLOR3D if s.link == HELD_LINK else ROBOT_COLOR3D
        out.append(Mesh3D(f"robot/{s.name}", v, f, pose, color))
    for k, o in enumerate(scene.obstacles):
        v, f = shape_mesh(o.shape)
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = np.asarray(o.pose.getRotation()), o.pose.getTranslation()
        out.append(Mesh3D(f"scene/{k}_{o.name}", v, f, pose, OBSTACLE_COLOR3D, 0.5))
    return out


def frames3d(
    stages: Sequence[tuple[Scene3D, np.ndarray | TimedTrajectory]],
    per_segment: int = 4,
    fps: int = 20,
) -> tuple[list[str], np.ndarray]:
    """Robot shape names (``robot/<shape>``) and their world placements (N, S, 4, 4) over
    the stages: a path (T, dof) gives ``per_segment`` frames per segment (waypoints
    included), a TimedTrajectory one frame every 1/fps s (real time at ``fps``)."""
    if not stages:
        raise InputError("3-D view: no path to show")
    names = {tuple(s.name for s in scene.robot.shapes) for scene, _ in stages}
    if len(names) != 1:
        raise InputError("3-D view: all stages must show the same robot shapes")
    poses = []
    for scene, path in stages:
        if isinstance(path, TimedTrajectory):
            q = path.sample(1.0 / fps)[1]
        else:
            q = interpolate_path(scene.robot.check_q(path, "path"), per_segment)
        poses.append(shape_placements_batch(scene.robot, q))
    return [f"robot/{n}" for n in names.pop()], np.concatenate(poses)


def send_plan3d(
    viewer,
    stages: Sequence[tuple[Scene3D, np.ndarray | TimedTrajectory]],
    per_segment: int = 4,
    fps: int = 20,
) -> int:
    """Load a 3-D plan into a ``meshcat.Visualizer``: meshes, the animation (played once; the
    Animations panel replays it) and a camera facing the scene. Returns the frame count."""
    import meshcat.geometry as mg
    from meshcat.animation import Animation

    names, poses = frames3d(stages, per_segment, fps)
    meshes = scene3d_meshes(stages[0][0], np.asarray(_first_q(stages[0][1])))
    for m in meshes:
        material = mg.MeshLambertMaterial(
            color=m.color, opacity=m.opacity, transparent=m.opacity < 1
        )
        viewer[m.name].set_object(mg.TriangularMeshGeometry(m.vertices, m.faces), material)
        viewer[m.name].set_transform(m.pose)
    animation = Animation(default_framerate=fps)
    for i, frame in enumerate(poses):
        with animation.at_frame(viewer, i) as node:
            for name, pose in zip(names, frame, strict=True):
                node[name].set_transform(pose)
    target, position = camera3d(meshes)
    pose = np.eye(4)
    pose[:3, 3] = target
    viewer["/Cameras/default"].set_transform(pose)
    x, y, z = position - target
    viewer["/Cameras/default/rotated/<object>"].set_property("position", [x, z, -y])  # y-up
    viewer.set_animation(animation, play=True)
    return len(poses)


def _first_q(path) -> np.ndarray:
    return path.waypoints[0] if isinstance(path, TimedTrajectory) else np.asarray(path)[0]


def camera3d(meshes: Sequence[Mesh3D]) -> tuple[np.ndarray, np.ndarray]:
    """Orbit target (3,) and camera position (3,) (world, m): the centre of the meshes'
    bounding box, seen from 1.2 box diagonals away along (1, −1, 0.7) (front right, above)."""
    points = np.vstack([m.vertices @ m.pose[:3, :3].T + m.pose[:3, 3] for m in meshes])
    low, high = points.min(0), points.max(0)
    target = (low + high) / 2
    direction = np.array([1.0, -1.0, 0.7]) / np.linalg.norm([1.0, -1.0, 0.7])
    return target, target + 1.2 * float(np.linalg.norm(high - low)) * direction


__all__ = ["Mesh3D", "camera3d", "frames3d", "scene3d_meshes", "send_plan3d"]
