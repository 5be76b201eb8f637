"""Robots from URDF files: a Pinocchio model reduced to its planning joints, link geometry
projected onto the planning plane.

A :class:`RobotSpec` names the URDF, the planning joints (a serial chain, base to tip), the
values of every other joint and the plane's axes u, v (orthonormal world directions, normal
n = u × v). Every other joint is locked, and at q = 0 each planning joint must turn about
±n: then every robot point moves parallel to the plane and its plane coordinates

    x ↦ (u · (x − o₁), v · (x − o₁)),     o₁ = planning joint 1's world position at q = 0,

move by the plane rotations of :class:`~gdnplan.planar_chain.PlanarChain`. A collision geometry
becomes one link polygon that contains its projection: the convex hull of points whose hull
contains the shape (box corners, polygons circumscribing the circles of cylinders, polyhedra
circumscribing spheres, mesh vertices) in plane coordinates, simplified to at most
``max_vertices`` vertices by dropping the edge whose removal (its neighbours extended to
meet) adds the least area, so the polygon only grows.
Hand-made polygons (plane coordinates at q = 0) can replace or extend the projected ones.

Modules: :mod:`~gdnplan.urdf_robot.spec` (:class:`RobotSpec`), :mod:`~gdnplan.urdf_robot.build`
(the robot from a URDF or from built models), :mod:`~gdnplan.urdf_robot.checks` (plane axes,
planning joints), :mod:`~gdnplan.urdf_robot.locking` (locked values and ``<mimic>`` followers,
shared with the 3-D loader), :mod:`~gdnplan.urdf_robot.load` (URDF parsing with readable
errors, shared with the 3-D loader: every ``<collision>`` loads or the file is refused),
:mod:`~gdnplan.urdf_robot.xml_checks` (the numbers of collisions and origins),
:mod:`~gdnplan.urdf_robot.meshes` (mesh files), :mod:`~gdnplan.urdf_robot.joint_limits`
(joint limits, continuous planning joints) and :mod:`~gdnplan.urdf_robot.shapes` (collision
shapes → projected link polygons). Every public name is re-exported here.
"""

from __future__ import annotations

from .build import robot_from_models, robot_from_urdf
from .checks import AXIS_TOLERANCE, JOINT_KINDS, PLANE_TOLERANCE, REVOLUTE, plane_basis
from .joint_limits import CONTINUOUS_VELOCITY, MAX_LIMIT
from .load import load_urdf
from .locking import CONTINUOUS
from .shapes import geometry_points
from .spec import RobotSpec

__all__ = [
    "AXIS_TOLERANCE",
    "CONTINUOUS",
    "CONTINUOUS_VELOCITY",
    "JOINT_KINDS",
    "MAX_LIMIT",
    "PLANE_TOLERANCE",
    "REVOLUTE",
    "RobotSpec",
    "geometry_points",
    "load_urdf",
    "plane_basis",
    "robot_from_models",
    "robot_from_urdf",
]
