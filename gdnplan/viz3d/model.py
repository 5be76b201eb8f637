"""The full Pinocchio model of a planar robot (locked joints recovered) and its held stick."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InputError
from ..robot import Robot
from ..ur5e.gripper import BODY_LENGTH, GRASP_GAP
from .objects import COLORS, Prism


@dataclass(frozen=True, eq=False)
class FullRobot:
    """The full Pinocchio model of a planar robot, its non-planning joints locked.

    Attributes:
        model: the full model (every joint of the URDF).
        geometry: its collision geometry (the URDF's, without a held stick).
        q_locked: (nq,) full configuration with the planning joints at 0 (rad or m).
        planning_index: (dof,) index of each planning joint in the full configuration.
    """

    model: pin.Model
    geometry: pin.GeometryModel
    q_locked: np.ndarray
    planning_index: np.ndarray

    def configuration(self, q: np.ndarray) -> np.ndarray:
        """(nq,) full configuration of the planar configuration q (dof,)."""
        full = self.q_locked.copy()
        full[self.planning_index] = q
        return full

    def placements(self, q: np.ndarray) -> tuple[pin.Data, pin.GeometryData]:
        """Frame and geometry placements (``data.oMf``, ``geometry_data.oMg``) at q (dof,)."""
        data, gdata = self.model.createData(), pin.GeometryData(self.geometry)
        pin.framesForwardKinematics(self.model, data, self.configuration(q))
        pin.updateGeometryPlacements(self.model, data, self.geometry, gdata)
        return data, gdata


def _locked_value(full: pin.Model, data: pin.Data, j: int, reduced_pose: pin.SE3) -> float:
    """Value of the 1-dof joint j of ``full`` whose frame sits at ``reduced_pose``.

    With the parent placed by ``data``: M_j(q_j) = (oMi[parent] · jointPlacement)⁻¹ · pose, and
    q_j = Sᵀ log6(M_j) / |S|² with S (6,) the joint's motion subspace (rotation or slide axis).
    """
    joint = full.joints[j]
    if joint.nq != 1 or joint.nv != 1:
        raise InputError(f"3-D view: joint {full.names[j]!r} is not a 1-dof joint")
    motion = (data.oMi[full.parents[j]] * full.jointPlacements[j]).inverse() * reduced_pose
    jdata = joint.createData()
    joint.calc(jdata, np.zeros(1))
    axis = np.asarray(jdata.S).reshape(6)
    return float(axis @ pin.log6(motion).vector / (axis @ axis))


@lru_cache(maxsize=8)
def full_robot(robot: Robot) -> FullRobot:
    """The full model of ``robot`` (from ``robot.info["urdf"]``) with its locked joints' values.

    Each locked joint's value is recovered from the reduced model (``robot.model``), where
    Pinocchio keeps the joint as a fixed frame of the same name placed at its locked value.
    ``package://`` mesh paths resolve against the URDF's parent folders.
    """
    urdf = Path(robot.info.get("urdf", ""))
    if not urdf.is_file():
        raise InputError(f"3-D view: robot {robot.name!r} has no URDF file ({urdf})")
    model = pin.buildModelFromUrdf(str(urdf))
    packages = [str(p) for p in urdf.resolve().parents]  # package:// meshes, as ROS lays them
    geometry = pin.buildGeomFromUrdf(
        model, str(urdf), pin.GeometryType.COLLISION, package_dirs=packages
    )
    reduced = robot.model
    rdata = reduced.createData()
    pin.framesForwardKinematics(reduced, rdata, np.zeros(robot.dof))
    q, data = pin.neutral(model), model.createData()
    planning = robot.joint_names
    for j in range(1, model.njoints):
        if model.names[j] in planning:
            continue
        pin.forwardKinematics(model, data, q)
        pose = rdata.oMf[reduced.getFrameId(model.names[j])]
        q[model.joints[j].idx_q] = _locked_value(model, data, j, pose)
    index = np.array([model.joints[model.getJointId(n)].idx_q for n in planning])
    return FullRobot(model, geometry, q, index)


def held_stick(robot: Robot, data: pin.Data, full: FullRobot) -> Prism | None:
    """The stick the robot holds (None when it holds none), placed by ``data.oMf`` of ``full``.

    Its frame has x along the stick (the tool axis), y across it in the plane (the opening
    direction), z out of the plane, like the obstacle stick of :func:`scene_objects`.
    """
    if "stick_length" not in robot.info:
        return None
    length, width = robot.info["stick_length"], robot.info["stick_width"]
    gripper = data.oMf[full.model.getFrameId("gripper_base_link")]
    local = np.eye(4)
    local[:3, :3] = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # x→z, z→−x
    local[2, 3] = BODY_LENGTH + GRASP_GAP + length / 2
    rectangle = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    return Prism(
        name="stick",
        polygon=rectangle * np.array([length / 2, width / 2]),
        depth=width,
        pose=gripper.homogeneous @ local,
        color=COLORS["stick"],
    )
