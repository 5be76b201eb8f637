"""The 3-D robot graph (paper §IV-A lifted to 3-D): link-shape nodes that move with the joints.

Robot nodes (:func:`robot_graph3d`) are the surface points of each link shape
(:func:`~gdnplan.graph3d_shapes.shape_points`) in the frame of the body it moves with, joined by
each shape's polytope edges. At a configuration q (rad) node n on body i is at

    p_n(q) = oMᵢ(q) · p_n⁰,     ∂p_n/∂q_j = J_v,j + ω_j × p_n   for the joints j supporting i,

with [J_v; ω] Pinocchio's joint Jacobian columns in the WORLD frame (the velocity of the point
at the world origin, :func:`pinocchio.computeJointJacobians`); zero for the other joints.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import pinocchio as pin

from .arm3d.robot3d import Robot3D
from .errors import InputError
from .graph3d_shapes import HULL_POINTS, RIM, hull_edges, neighbourhoods, shape_points


@dataclass(frozen=True, eq=False)
class RobotGraph3D:
    """The node structure of a 3-D robot's graph.

    Attributes:
        robot: the robot. rim: points per cylinder rim.
        local: (N, 3) node positions in the joint frame of their body (m).
        body: (N,) body (reduced-model joint index; 0 = base) of each node.
        link: (N,) index into ``robot.links`` of each node.
        nbr, nbr_mask: (N, D) padded neighbourhoods (hull edges of each shape's nodes).
        support: (N, dof) 1.0 where joint j moves node n.
    """

    robot: Robot3D
    rim: int
    local: np.ndarray
    body: np.ndarray
    link: np.ndarray
    nbr: np.ndarray
    nbr_mask: np.ndarray
    support: np.ndarray

    @property
    def n_nodes(self) -> int:
        return len(self.local)

    def _frames(self, q: np.ndarray, jacobians: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """(B, njoints, 4, 4) body placements and, with ``jacobians``, (B, 6, dof) WORLD joint
        Jacobian columns, one Pinocchio pass per configuration."""
        model, data = self.robot.model, self.robot.data
        tf = np.empty((len(q), model.njoints, 4, 4))
        jac = np.empty((len(q), 6, model.nv)) if jacobians else None
        for b, qb in enumerate(q):
            if jacobians:
                pin.computeJointJacobians(model, data, qb)
                jac[b] = data.J
            else:
                pin.forwardKinematics(model, data, qb)
            tf[b] = [m.homogeneous for m in data.oMi]
        return tf, jac

    def kinematics(self, q) -> tuple[np.ndarray, np.ndarray]:
        """(B, N, 3) node positions (m) and (B, 6, dof) WORLD joint Jacobian columns at q
        (B, dof) or (dof,) (rad): what :meth:`pullback` needs."""
        q = self.robot.check_q(q)
        tf, jac = self._frames(q, True)
        return self._place(tf), jac

    def positions(self, q) -> np.ndarray:
        """(B, N, 3) world node positions (m) at q (B, dof) or (dof,) (rad)."""
        q = self.robot.check_q(q)
        tf, _ = self._frames(q, False)
        return self._place(tf)

    def _place(self, tf: np.ndarray) -> np.ndarray:
        """p = R_i p⁰ + t_i for the nodes of every body i (one product per body)."""
        out = np.empty((len(tf), self.n_nodes, 3))
        for i in np.unique(self.body):
            rows = self.body == i
            out[:, rows] = self.local[rows] @ tf[:, i, :3, :3].transpose(0, 2, 1)
            out[:, rows] += tf[:, i, None, :3, 3]
        return out

    def positions_and_jacobians(self, q) -> tuple[np.ndarray, np.ndarray]:
        """(B, N, 3) node positions (m) and (B, N, 3, dof) Jacobians ∂p/∂q (m/rad)."""
        p, jac = self.kinematics(q)
        jv, jw = jac[:, None, :3], jac[:, None, 3:]  # (B, 1, 3, dof)
        cross = np.cross(jw, p[..., None], axisa=2, axisb=2, axisc=2)  # ω_j × p
        return p, (jv + cross) * self.support[None, :, None, :]

    def pullback(self, nodes: np.ndarray, jac: np.ndarray, grad: np.ndarray) -> np.ndarray:
        """(B, dof) Σ_n (∂p_n/∂q)ᵀ g_n of a gradient g (B, N, 3) on the nodes.

        With ∂p_n/∂q_j = S_nj (v_j + ω_j × p_n), (ω_j × p_n) · g_n = ω_j · (p_n × g_n), so

            ∂/∂q_j = v_j · Σ_n S_nj g_n + ω_j · Σ_n S_nj p_n × g_n,

        two (N × dof) products instead of the (B, N, 3, dof) Jacobians.

        Args:
            nodes: (B, N, 3) and jac: (B, 6, dof) from :meth:`kinematics`.
            grad: (B, N, 3) gradient with respect to the node positions.
        """
        force = np.einsum("bni,nj->bij", grad, self.support)  # (B, 3, dof)
        torque = np.einsum("bni,nj->bij", np.cross(nodes, grad), self.support)
        return np.einsum("bij,bij->bj", jac[:, :3], force) + np.einsum(
            "bij,bij->bj", jac[:, 3:], torque
        )


@lru_cache(maxsize=16)
def robot_graph3d(robot: Robot3D, rim: int = RIM, hull_points: int = HULL_POINTS) -> RobotGraph3D:
    """The (cached) graph of a 3-D robot's link shapes (module docstring)."""
    if rim < 3:
        raise InputError(f"rim: expected at least 3 points per rim, got {rim}")
    local, body, link, edges = [], [], [], []
    count = 0
    for s, k in zip(robot.shapes, robot.shape_link, strict=True):
        pts = shape_points(s.shape, rim, hull_points)
        world = pts @ s.placement[:3, :3].T + s.placement[:3, 3]
        local.append(world)
        body.append(np.full(len(pts), s.body))
        link.append(np.full(len(pts), k))
        edges.append(hull_edges(pts) + count)
        count += len(pts)
    local_arr = np.concatenate(local)
    body_arr = np.concatenate(body)
    nbr, mask = neighbourhoods(count, np.concatenate(edges))
    model = robot.model
    support = np.zeros((count, model.nv))
    for n, i in enumerate(body_arr):
        for j in model.supports[int(i)][1:]:
            support[n, model.joints[j].idx_v] = 1.0
    return RobotGraph3D(robot, rim, local_arr, body_arr, np.concatenate(link), nbr, mask, support)


__all__ = [
    "RobotGraph3D",
    "robot_graph3d",
]
