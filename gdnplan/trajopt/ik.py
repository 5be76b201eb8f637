"""The end effector (the robot's last frame), what it can reach, and the numeric inverse
kinematics' building blocks (the planner's ``numeric_ik`` turns a ``goal_position`` into a
joint goal)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..distance import signed_distance
from ..robot import Robot
from ..scene import Scene


def tip_point(robot: Robot) -> np.ndarray:
    """(2,) plane position at q = 0 of the robot's last frame (its tip / end effector)."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, np.zeros(robot.dof))
    return robot.plane.project(data.oMf[robot.model.nframes - 1].translation)


def tip_position(robot: Robot, q: np.ndarray) -> np.ndarray:
    """(B, 2) end-effector positions (m) at q (B, dof)."""
    q = robot.check_q(q)
    return robot.chain.transform(tip_point(robot)[None], np.array([robot.dof]), q)[:, 0]


def tip_reach(robot: Robot) -> float:
    """Largest possible distance of the tip from joint 1 (m), chained over joint distances."""
    o = robot.chain.joint_origins
    hops = np.sum(np.linalg.norm(np.diff(o, axis=0), axis=1))
    return float(hops + np.linalg.norm(tip_point(robot) - o[-1]))


def first_joint_barrier(scene: Scene, a: float, b: float, n: int = 200) -> float | None:
    """A joint-1 angle between a and b (rad) where the links moved by joint 1 alone collide,
    or None when none of n samples does.

    Links on body 1 depend on q_1 only and joints do not wrap, so every path from q_1 = a to
    q_1 = b passes each angle between them in the same link pose: a collision there proves the
    problem infeasible. (Only a necessary condition is tested; None proves nothing.)
    """
    robot = scene.robot
    first = [k for k, p in enumerate(robot.polygons) if p.body == 1]
    if not first:
        return None
    q = np.zeros((n, robot.dof))
    q[:, 0] = np.linspace(a, b, n)
    d = signed_distance(scene, q, per_link=True)[:, first].min(axis=1)
    hit = np.flatnonzero(d <= 0)
    return float(q[hit[0], 0]) if hit.size else None
