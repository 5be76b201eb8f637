"""The registered ``ur5e`` (with its gripper states) and ``ur5`` robots, reduced to the plane.

Both arms plan shoulder_lift, elbow and wrist_1 in the plane of :mod:`gdnplan.ur5e.kinematics`;
:mod:`gdnplan.urdf_robot` reduces their Pinocchio models and projects the link geometry. The
UR5e's link polygons group its URDF links (``POLYGON_GROUPS``); holding a stick adds the box of
:mod:`gdnplan.ur5e.gripper` to the gripper body as one more polygon.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..assets import robot_urdf
from ..errors import InputError, UnknownNameError
from ..limits import is_number
from ..robot import Robot, register_robot
from ..urdf_robot import RobotSpec, robot_from_models
from .gripper import BODY_LENGTH, GRASP_GAP, GRIPPER_STATES, MAX_OPENING
from .kinematics import LOCKED, PI, PLANE_AXES, PLANNING_JOINTS, PLANNING_LIMITS

POLYGON_GROUPS = {  # URDF link -> robot polygon (hull of the link's projected geometry)
    "base_link": "base",
    "shoulder_link": "base",
    "upper_arm_link": "upper_arm",
    "forearm_link": "forearm",
    "wrist_1_link": "wrist",
    "wrist_2_link": "hand",
    "wrist_3_link": "hand",
    "gripper_base_link": "hand",
    "left_finger_link": "finger_left",
    "right_finger_link": "finger_right",
    "stick": "stick",
}


def _group(geometry_name: str) -> str:
    """Polygon of a Pinocchio geometry name ``<link>_<index>``."""
    return POLYGON_GROUPS[geometry_name.rsplit("_", 1)[0]]


def _add_stick(model: pin.Model, geom: pin.GeometryModel, length: float, width: float) -> None:
    """Attach the held stick (a box along the tool axis) to the gripper body."""
    import coal

    frame = model.getFrameId("gripper_base_link")
    local = pin.SE3(np.eye(3), np.array([0.0, 0.0, BODY_LENGTH + GRASP_GAP + length / 2]))
    placement = model.frames[frame].placement * local  # geometry placements are joint-relative
    box = coal.Box(width, width, length)
    geom.addGeometryObject(
        pin.GeometryObject("stick_0", model.frames[frame].parentJoint, frame, placement, box)
    )


@lru_cache(maxsize=32)
def _ur5e(gripper: str, stick_length: float, stick_width: float) -> Robot:
    urdf = robot_urdf("ur5e")
    model = pin.buildModelFromUrdf(str(urdf))
    geom = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION)
    half = {"open": MAX_OPENING / 2, "closed": 0.0, "holding": stick_width / 2}[gripper]
    if gripper == "holding":
        _add_stick(model, geom, stick_length, stick_width)
    spec = RobotSpec(
        urdf=urdf,
        planning_joints=PLANNING_JOINTS,
        locked={**LOCKED, "left_finger_joint": half, "right_finger_joint": half},
        plane_axes=PLANE_AXES,
        max_vertices=12,
        base_radius=0.2,
    )
    info = {"gripper": gripper, "opening": 2 * half, "tcp_frame": "gripper_tcp"}
    if gripper == "holding":
        info.update(stick_length=stick_length, stick_width=stick_width)
    return robot_from_models("ur5e", model, geom, spec, PLANNING_LIMITS, info=info, group=_group)


@register_robot("ur5e")
def ur5e(gripper: str = "open", stick_length: float = 0.25, stick_width: float = 0.03) -> Robot:
    """The UR5e with its gripper ``open``, ``closed`` or ``holding`` a stick, dof = 3.

    Polygons: base (base + shoulder, fixed), upper_arm, forearm, wrist (wrist_1 link), hand
    (wrist_2/3 links + gripper body), finger_left, finger_right, and stick when holding.
    ``stick_length`` and ``stick_width`` (m) size the held stick (ignored otherwise).
    """
    if gripper not in GRIPPER_STATES:
        raise UnknownNameError(
            f"gripper: unknown state {gripper!r}; choose one of {list(GRIPPER_STATES)}"
        )
    for field_name, value, low, high in (
        ("stick_length", stick_length, 0.02, 1.0),
        ("stick_width", stick_width, 0.005, MAX_OPENING),
    ):
        if not is_number(value) or not low <= value <= high:
            raise InputError(f"{field_name}: expected a length in [{low}, {high}] m, got {value!r}")
    if gripper != "holding":  # one robot per state: the stick size only matters when held
        stick_length, stick_width = 0.25, 0.03
    return _ur5e(gripper, float(stick_length), float(stick_width))


UR5_GROUPS = {
    "base_link": "base",
    "shoulder_link": "base",
    "upper_arm_link": "upper_arm",
    "forearm_link": "forearm",
    "wrist_1_link": "wrist",
    "wrist_2_link": "hand",
    "wrist_3_link": "hand",
    "ee_link": "hand",
}


@register_robot("ur5")
def ur5() -> Robot:
    """The classic UR5 of example-robot-data, polygons projected from its collision meshes.

    Same plane, planning joints and limits as the UR5e; wrist_2 = π/2 puts the tool axis
    in the plane (along +u at q = 0). Polygons: base, upper_arm, forearm, wrist, hand.
    """
    import example_robot_data

    loaded = example_robot_data.load("ur5")
    spec = RobotSpec(
        urdf=Path(loaded.urdf),
        planning_joints=PLANNING_JOINTS,
        locked={"shoulder_pan_joint": 0.0, "wrist_2_joint": PI / 2, "wrist_3_joint": 0.0},
        plane_axes=PLANE_AXES,
        max_vertices=12,
        base_radius=0.2,
    )
    return robot_from_models(
        "ur5",
        loaded.model,
        loaded.collision_model,
        spec,
        PLANNING_LIMITS,
        info={"source": "example-robot-data ur5"},
        group=lambda name: UR5_GROUPS[name.rsplit("_", 1)[0]],
    )
