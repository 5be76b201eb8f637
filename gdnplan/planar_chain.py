"""Planar chain kinematics: batched positions and Jacobians of points on a serial chain of
revolute joints that all turn about the plane normal ``n``.

A point ``p`` rigidly attached to body ``b`` (the body after the first ``b`` planning joints)
moves as the composition of plane rotations

    p(q) = T_1(q_1) ∘ T_2(q_2) ∘ … ∘ T_b(q_b) (p⁰),    T_j(θ) = rotation by s_j θ about o_j⁰,

where ``p⁰`` and ``o_j⁰`` are the point and joint ``j`` at ``q = 0`` (2-D plane coordinates) and
``s_j = ±1`` is the sign of the joint axis along ``n``. Its Jacobian column is

    ∂p/∂q_j = s_j ẑ × (p − o_j(q))   for j ≤ b,   0 otherwise.

:class:`PlanarChain` evaluates both for a batch with a handful of numpy operations; Pinocchio
stays the reference (:meth:`gdnplan.robot.Robot.node_positions_pinocchio`) and a test proves the
two equal.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .limits import read_only


def rot2(theta: np.ndarray) -> np.ndarray:
    """Rotation matrices of angles ``theta`` (...,) -> (..., 2, 2)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def cross_z(v: np.ndarray) -> np.ndarray:
    """ẑ × v for planar vectors v (..., 2)."""
    return np.stack([-v[..., 1], v[..., 0]], -1)


@dataclass(frozen=True)
class PlanarChain:
    """Serial chain of revolute joints that all rotate about the plane normal.

    Attributes:
        joint_origins: (dof, 2) joint positions at q = 0, plane coordinates (m).
        joint_signs: (dof,) +1 when the joint axis is along the plane normal, -1 when opposite.
    """

    joint_origins: np.ndarray
    joint_signs: np.ndarray

    def __post_init__(self) -> None:  # read-only: the lever arms are cached from them
        object.__setattr__(self, "joint_origins", read_only(self.joint_origins))
        object.__setattr__(self, "joint_signs", read_only(self.joint_signs))

    @property
    def dof(self) -> int:
        return len(self.joint_signs)

    def transform(self, points0: np.ndarray, body: np.ndarray, q: np.ndarray) -> np.ndarray:
        """World positions at q of points attached to bodies.

        Args:
            points0: (N, 2) positions at q = 0.
            body: (N,) number of planning joints upstream of each point (0 = fixed base).
            q: (B, dof) joint angles (rad).

        Returns:
            (B, N, 2) positions (m).
        """
        p = np.broadcast_to(points0, (q.shape[0], *points0.shape)).copy()
        for j in range(self.dof - 1, -1, -1):  # tip joint first: p = T_1 ∘ … ∘ T_b (p⁰)
            moved = body > j
            if not moved.any():
                continue
            o = self.joint_origins[j]
            r = rot2(self.joint_signs[j] * q[:, j])  # (B, 2, 2)
            p[:, moved] = o + np.einsum("bij,bnj->bni", r, p[:, moved] - o)
        return p

    def joint_positions(self, q: np.ndarray) -> np.ndarray:
        """(B, dof, 2) positions of the joints at q (joint j sits on body j)."""
        return self.transform(self.joint_origins, np.arange(self.dof), q)

    def jacobian(self, points: np.ndarray, body: np.ndarray, q: np.ndarray) -> np.ndarray:
        """Jacobians ∂p/∂q of attached points already placed at q.

        Args:
            points: (B, N, 2) positions at q (from :meth:`transform`).
            body: (N,) body index of each point.
            q: (B, dof) joint angles.

        Returns:
            (B, N, 2, dof), column j = s_j ẑ × (p − o_j(q)) where joint j is upstream.
        """
        joints = self.joint_positions(q)  # (B, dof, 2)
        lever = points[:, :, None, :] - joints[:, None, :, :]  # (B, N, dof, 2)
        jac = cross_z(lever) * self.joint_signs[:, None]
        jac = jac * (body[:, None] > np.arange(self.dof))[None, :, :, None]
        return np.moveaxis(jac, 2, 3)


__all__ = ["PlanarChain", "cross_z", "rot2"]
