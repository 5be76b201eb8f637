"""The paper's planar arms, ``planar2`` and ``planar7``, built from their shipped URDFs.

Each arm is a chain of 0.06 m wide links with revolute joints about the plane normal, limited
to ±π; :mod:`gdnplan.urdf_robot` reads the URDF and reduces it to the plane. The factories
register in the robot registry (:func:`gdnplan.robot.load_robot`) when this module is imported;
the package declares them there (:mod:`gdnplan.registry`).
"""

from __future__ import annotations

from .assets import robot_urdf
from .robot import Robot, register_robot
from .urdf_robot import RobotSpec, load_urdf, robot_from_models


def _planar(name: str) -> Robot:
    spec = RobotSpec(
        urdf=robot_urdf(name),
        planning_joints=tuple(f"joint{i}" for i in range(1, int(name[-1]) + 1)),
    )
    return robot_from_models(name, *load_urdf(spec), spec)


@register_robot("planar2")
def planar2() -> Robot:
    """Two 0.6 m links, 0.06 m wide, joints limited to ±π: reach 1.2 m."""
    return _planar("planar2")


@register_robot("planar7")
def planar7() -> Robot:
    """Seven 0.3 m links, 0.06 m wide, joints limited to ±π: reach 2.1 m."""
    return _planar("planar7")
