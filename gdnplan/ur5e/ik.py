"""The UR5e's planar tool pose and its exact (analytic) inverse kinematics, both elbows."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..robot import Robot


def tcp_pose(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Planar pose (u, v, φ) of the grasp centre: position (m) and tool-axis angle φ (rad)."""
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.asarray(q, dtype=float))
    frame = data.oMf[model.getFrameId("gripper_tcp")]
    axis = robot.plane.axes @ frame.rotation[:, 2]
    return np.array([*robot.plane.project(frame.translation), np.arctan2(axis[1], axis[0])])


def analytic_ik(robot: Robot, target: np.ndarray) -> list[np.ndarray]:
    """Exact planar inverse kinematics of the tcp pose ``target`` = (u, v, φ), both elbows.

    Body j turns by θ_j = Σ_{i≤j} s_i q_i. The tcp is rigid on body 3, so joint 3 sits at
    o₃(q) = p* − R(θ₃) c with c = tcp − o₃ at q = 0 and θ₃ = φ* − φ(0). Reaching
    w = o₃ − o₁ with links ℓ₁ = |o₂ − o₁|, ℓ₂ = |o₃ − o₂| (directions β₁, β₂ at q = 0) gives the
    elbow angle γ = ±acos((|w|² − ℓ₁² − ℓ₂²) / 2ℓ₁ℓ₂), the first link's direction
    a₁ = ∠w − atan2(ℓ₂ sin γ, ℓ₁ + ℓ₂ cos γ), θ₁ = a₁ − β₁, θ₂ = a₁ + γ − β₂. Angles are
    shifted by 2π into the joint limits; solutions outside them are dropped. (The planner's
    goal IK for a tip position, damped least squares on any arm, is
    :func:`gdnplan.trajopt.numeric_ik`.)

    Returns:
        0, 1 or 2 configurations (3,) (rad), each checked against Pinocchio's tcp pose.
    """
    o, s = robot.chain.joint_origins, robot.chain.joint_signs
    zero = tcp_pose(robot, np.zeros(robot.dof))
    theta3 = target[2] - zero[2]
    c3, s3 = np.cos(theta3), np.sin(theta3)
    c = zero[:2] - o[2]
    w = target[:2] - np.array([c3 * c[0] - s3 * c[1], s3 * c[0] + c3 * c[1]]) - o[0]
    l1v, l2v = o[1] - o[0], o[2] - o[1]
    l1, l2 = np.linalg.norm(l1v), np.linalg.norm(l2v)
    cos_g = (w @ w - l1**2 - l2**2) / (2 * l1 * l2)
    if abs(cos_g) > 1:
        return []
    found = []
    for gamma in {np.arccos(cos_g), -np.arccos(cos_g)}:
        a1 = np.arctan2(w[1], w[0]) - np.arctan2(l2 * np.sin(gamma), l1 + l2 * np.cos(gamma))
        theta1 = a1 - np.arctan2(l1v[1], l1v[0])
        theta2 = a1 + gamma - np.arctan2(l2v[1], l2v[0])
        q = s * np.array([theta1, theta2 - theta1, theta3 - theta2])
        q = (q + np.pi) % (2 * np.pi) - np.pi
        q = np.where(q > robot.upper, q - 2 * np.pi, np.where(q < robot.lower, q + 2 * np.pi, q))
        if robot.within_limits(q)[0]:
            pose = tcp_pose(robot, q)
            err = np.r_[pose[:2] - target[:2], np.sin(pose[2] - target[2])]
            assert np.abs(err).max() < 1e-9, f"planar IK disagrees with Pinocchio: {err}"
            found.append(q)
    return found
