"""Triangle meshes of a 3-D scene's coal shapes: the robot's link shapes and the obstacles.

Each coal shape becomes a triangle mesh in its own frame, the geometry coal checks:

* ``Box``: its 8 corners, 12 triangles;
* ``Sphere``, ``Cylinder``, ``Capsule`` (axis z): surfaces of revolution of their profile,
  ``SEGMENTS`` around the axis (a polyhedron inscribed in the shape);
* ``ConvexBase`` (a mesh or a point set as coal's convex hull): the convex hull of its points.

:func:`robot_triangles` places the robot's meshes for a batch of configurations with the
batched forward kinematics of :mod:`gdnplan.arm3d.fk3d` (the shapes' placements the distance
uses, a held object included); :func:`obstacle_triangles` places the obstacles by their poses.
Triangles are (F, 3, 3) arrays: F triangles, 3 corners, x y z in metres (world frame).
"""

from __future__ import annotations

import weakref

import coal
import numpy as np
from scipy.spatial import ConvexHull

from ..arm3d.fk3d import body_placements_batch, shape_placements_batch
from ..arm3d.ik3d import tool_frame
from ..arm3d.robot3d import Robot3D
from ..arm3d.scene3d import Scene3D
from ..errors import InputError

SEGMENTS = 16  # polygon sides around a round shape's axis
RINGS = 4  # latitude rings of a hemisphere


def _revolve(profile: np.ndarray, segments: int = SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """Surface of revolution about z of ``profile`` (k, 2) rows (r, z), first and last r = 0
    (the poles): vertices (2 + (k − 2) · segments, 3) and triangles (f, 3) (vertex indices)."""
    angle = 2 * np.pi * np.arange(segments) / segments
    rings = profile[1:-1]
    ring_xyz = np.stack(
        [
            rings[:, :1] * np.cos(angle),
            rings[:, :1] * np.sin(angle),
            np.repeat(rings[:, 1:], segments, 1),
        ],
        -1,
    ).reshape(-1, 3)
    poles = np.array([[0.0, 0.0, profile[0, 1]], [0.0, 0.0, profile[-1, 1]]])
    vertices = np.vstack([poles, ring_xyz])
    k = len(rings)
    j, jn = np.arange(segments), (np.arange(segments) + 1) % segments
    faces = [np.stack([np.zeros(segments, int), 2 + jn, 2 + j], 1)]  # bottom fan
    for i in range(k - 1):
        a, b = 2 + i * segments, 2 + (i + 1) * segments
        faces += [np.stack([a + j, a + jn, b + jn], 1), np.stack([a + j, b + jn, b + j], 1)]
    top = 2 + (k - 1) * segments
    faces.append(np.stack([np.ones(segments, int), top + j, top + jn], 1))  # top fan
    return vertices, np.vstack(faces)


def _hemisphere_profile(radius: float, half: float) -> np.ndarray:
    """(r, z) profile of a capsule of half length ``half`` (a sphere for half = 0)."""
    lat = np.linspace(-np.pi / 2, np.pi / 2, 2 * RINGS + 1)
    r, z = radius * np.cos(lat), radius * np.sin(lat)
    z = np.where(lat < 0, z - half, np.where(lat > 0, z + half, z))
    rows = np.column_stack([r, z])
    if half > 0:  # the equator splits into the cylinder's two rims
        eq = RINGS
        rows = np.vstack([rows[:eq], [[radius, -half], [radius, half]], rows[eq + 1 :]])
    rows[[0, -1], 0] = 0.0
    return rows


def shape_mesh(shape) -> tuple[np.ndarray, np.ndarray]:
    """Triangle mesh of a coal shape in its frame: vertices (k, 3) in m, triangles (f, 3)."""
    if isinstance(shape, coal.Box):
        h = np.asarray(shape.halfSide, float)
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * h
        return corners, ConvexHull(corners).simplices
    if isinstance(shape, coal.Sphere):
        return _revolve(_hemisphere_profile(shape.radius, 0.0))
    if isinstance(shape, coal.Capsule):
        return _revolve(_hemisphere_profile(shape.radius, shape.halfLength))
    if isinstance(shape, coal.Cylinder):
        r, h = shape.radius, shape.halfLength
        return _revolve(np.array([[0.0, -h], [r, -h], [r, h], [0.0, h]]))
    if isinstance(shape, coal.ConvexBase):
        points = np.asarray(shape.points(), float)
        return points, ConvexHull(points).simplices
    raise InputError(f"3-D view: no mesh for a coal {type(shape).__name__}")


_ROBOT: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # robot -> its local meshes


def _robot_mesh(robot: Robot3D) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Local vertices (V, 3), the shape of each vertex (V,), triangles (F, 3) into the stacked
    vertices and the shape of each triangle (F,); computed once per robot."""
    if robot not in _ROBOT:
        vertices, owner, faces, face_owner, base = [], [], [], [], 0
        for k, s in enumerate(robot.shapes):
            v, f = shape_mesh(s.shape)
            vertices.append(v)
            owner.append(np.full(len(v), k))
            faces.append(f + base)
            face_owner.append(np.full(len(f), k))
            base += len(v)
        _ROBOT[robot] = tuple(np.concatenate(x) for x in (vertices, owner, faces, face_owner))
    return _ROBOT[robot]


def robot_triangles(robot: Robot3D, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World triangles (B, F, 3, 3) of every link shape at q (B, dof), and the index into
    ``robot.shapes`` of each triangle (F,)."""
    vertices, owner, faces, face_owner = _robot_mesh(robot)
    tf = shape_placements_batch(robot, q)[:, owner]  # (B, V, 4, 4)
    world = np.einsum("bvij,vj->bvi", tf[..., :3, :3], vertices) + tf[..., :3, 3]
    return world[:, faces], face_owner


def obstacle_triangles(scene: Scene3D) -> tuple[np.ndarray, np.ndarray]:
    """World triangles (F, 3, 3) of every obstacle and the obstacle index of each (F,)."""
    tris, owner = [np.zeros((0, 3, 3))], [np.zeros(0, int)]
    for k, o in enumerate(scene.obstacles):
        v, f = shape_mesh(o.shape)
        world = v @ np.asarray(o.pose.getRotation()).T + np.asarray(o.pose.getTranslation())
        tris.append(world[f])
        owner.append(np.full(len(f), k))
    return np.concatenate(tris), np.concatenate(owner)


def tool_positions(robot: Robot3D, q: np.ndarray) -> np.ndarray:
    """(B, 3) world position (m) of the robot's tool frame (:func:`tool_frame`) at q (B, dof)."""
    model = robot.model
    frame = model.frames[model.getFrameId(tool_frame(robot))]
    body = body_placements_batch(robot, q)[:, int(frame.parentJoint)]
    return body[:, :3, :3] @ frame.placement.translation + body[:, :3, 3]


__all__ = ["obstacle_triangles", "robot_triangles", "shape_mesh", "tool_positions"]
