"""The end effector (the robot's last frame), what it can reach, and the numeric inverse
kinematics that turns a problem's ``goal_position`` into a joint goal."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ..distance import signed_distance
from ..errors import InfeasibleProblemError
from ..robot import Robot
from ..scene import Scene

if TYPE_CHECKING:
    from .problem import Problem


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


def numeric_ik(
    problem: Problem, seed: int = 0, restarts: int = 64, iterations: int = 100
) -> np.ndarray:
    """Collision-free joint goal (dof,) whose tip is at ``problem.goal_position``.

    Batched damped least squares Δq = Jᵀ(JJᵀ + λ²I)⁻¹ e from the start and ``restarts`` random
    configurations, clipped to the limits; among solutions within ``goal_tolerance`` and clear
    of the margin, the one closest to the start. Raises InfeasibleProblemError if none exists.
    """
    robot, target = problem.scene.robot, problem.goal_position
    rng = np.random.default_rng(seed)
    q = np.vstack([problem.start, rng.uniform(problem.lower, problem.upper, (restarts, robot.dof))])
    tip0, body = tip_point(robot)[None], np.array([robot.dof])
    for _ in range(iterations):
        p = robot.chain.transform(tip0, body, q)
        jac = robot.chain.jacobian(p, body, q)[:, 0]  # (B, 2, dof)
        err = target - p[:, 0]
        jjt = jac @ np.swapaxes(jac, 1, 2) + 1e-4 * np.eye(2)
        step = np.einsum("bji,bj->bi", jac, np.linalg.solve(jjt, err[..., None])[..., 0])
        q = np.clip(q + step, problem.lower, problem.upper)
    err = np.linalg.norm(tip_position(robot, q) - target, axis=1)
    ok = err <= problem.goal_tolerance / 2
    if ok.any():
        ok[ok] = signed_distance(problem.scene, q[ok]) > problem.margin
    for i in np.flatnonzero(ok):
        ok[i] = first_joint_barrier(problem.scene, problem.start[0], q[i, 0], n=50) is None
    if not ok.any():
        raise InfeasibleProblemError(
            f"goal.position {target.tolist()}: no collision-free joint configuration within the "
            "limits reaches it; move the goal or lower options.margin"
        )
    candidates = q[ok]
    return candidates[np.argmin(np.linalg.norm(candidates - problem.start, axis=1))]
