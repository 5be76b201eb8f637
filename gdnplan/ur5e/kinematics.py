"""UR5e and UR5 kinematics: standard Denavit–Hartenberg parameters, joints and the planning plane.

UR5e kinematics (standard Denavit–Hartenberg, Universal Robots' published parameters)::

    T_0^6(θ) = Π_i Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)
    d = (0.1625, 0, 0, 0.1333, 0.0997, 0.0996) m,  a = (0, −0.425, −0.3922, 0, 0, 0) m,
    α = (π/2, 0, 0, π/2, −π/2, 0)

Planning plane (both arms): the vertical plane of shoulder_lift, elbow and wrist_1 at
shoulder_pan = 0, i.e. world x–z with u = x (horizontal, forward), v = z (up) and its origin at
the shoulder_lift axis (v = 0 is shoulder height, the mounting surface is at v = −d1).
wrist_2 = π/2 puts the tool axis into the plane (at q = 0 the gripper continues the stretched
arm along +u, its axis d5 = 0.0997 m below the forearm's line) and wrist_3 = 0 turns the
finger-opening direction into the plane, so the fingers open and close in the plane.
Planning joints q = (shoulder_lift, elbow, wrist_1) with limits shoulder_lift ∈ [−π, 0]
(upper arm above the shoulder's horizontal), elbow ∈ [−0.9π, 0.9π] (keeps the forearm off the
upper arm: self-collision is not modelled) and wrist_1 ∈ [−π, π]. In the plane, a positive
joint angle turns clockwise (the joint axes point along +y = −(u × v)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PI = float(np.pi)


@dataclass(frozen=True)
class DH:
    """Standard DH parameters of a six-axis arm (m, rad), one entry per joint."""

    d: tuple[float, ...]
    a: tuple[float, ...]
    alpha: tuple[float, ...]

    def forward(self, q: np.ndarray) -> np.ndarray:
        """Flange poses T_0^6 (B, 4, 4) in the DH base frame for joint angles q (B, 6).

        T_{i−1}^i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i), written out as the textbook matrix.
        """
        q = np.atleast_2d(np.asarray(q, dtype=float))
        out = np.broadcast_to(np.eye(4), (len(q), 4, 4)).copy()
        for i in range(6):
            ct, st = np.cos(q[:, i]), np.sin(q[:, i])
            ca, sa = np.cos(self.alpha[i]), np.sin(self.alpha[i])
            t = np.zeros((len(q), 4, 4))
            t[:, 0] = np.stack([ct, -st * ca, st * sa, self.a[i] * ct], 1)
            t[:, 1] = np.stack([st, ct * ca, -ct * sa, self.a[i] * st], 1)
            t[:, 2] = [0.0, sa, ca, self.d[i]]
            t[:, 3] = [0.0, 0.0, 0.0, 1.0]
            out = out @ t
        return out


UR5E_DH = DH(
    d=(0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996),
    a=(0.0, -0.425, -0.3922, 0.0, 0.0, 0.0),
    alpha=(PI / 2, 0.0, 0.0, PI / 2, -PI / 2, 0.0),
)
UR5_DH = DH(  # the classic UR5 (example-robot-data's ur5)
    d=(0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823),
    a=(0.0, -0.425, -0.39225, 0.0, 0.0, 0.0),
    alpha=(PI / 2, 0.0, 0.0, PI / 2, -PI / 2, 0.0),
)
JOINTS = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
LINKS = (
    "shoulder_link",
    "upper_arm_link",
    "forearm_link",
    "wrist_1_link",
    "wrist_2_link",
    "wrist_3_link",
)
PLANNING_JOINTS = JOINTS[1:4]
LOCKED = {"shoulder_pan_joint": 0.0, "wrist_2_joint": PI / 2, "wrist_3_joint": 0.0}
PLANNING_LIMITS = (np.array([-PI, -0.9 * PI, -PI]), np.array([0.0, 0.9 * PI, PI]))
PLANE_AXES = ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0))
