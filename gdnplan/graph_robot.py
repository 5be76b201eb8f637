"""Robot graphs (paper §IV-A): a robot's link polygons as rings whose nodes move with the chain.

The nodes of a link polygon are its vertices (densified to ``max_edge``: extra nodes placed in
the body frame at q = 0), attached to the polygon's body, so at q (rad)

    p(q) = T_1(q_1) ∘ … ∘ T_b(q_b)(p⁰),   ∂p/∂q_j = s_j ẑ × (p − o_j(q)) for j ≤ b

(see :mod:`gdnplan.robot`). :class:`RobotGraph` is the (cached, :func:`robot_graph`) structure
with batched positions, Jacobians and the gradient pull-back; :func:`variant_graphs` pads the
graphs of samples whose robots differ.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import torch

from .errors import InputError
from .geometry import densify
from .graph_batch import GraphBatch, rings
from .robot import Robot


@dataclass(frozen=True, eq=False)
class RobotGraph:
    """The node structure of a robot's graph: nodes attached to bodies, ring neighbours.

    Attributes:
        robot: the robot.
        max_edge: densification length (m) or None.
        nodes0: (N, 2) node positions at q = 0 (m).
        body: (N,) body of each node (planning joints upstream).
        prev, next: (N,) ring neighbours.
    """

    robot: Robot
    max_edge: float | None
    nodes0: np.ndarray
    body: np.ndarray
    prev: np.ndarray
    next: np.ndarray

    @property
    def n_nodes(self) -> int:
        return len(self.nodes0)

    def kinematics(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Node positions (B, N, 2) and joint positions (B, dof, 2) at q (B, dof) (m).

        Body b moves rigidly, x ↦ R(θ_b) x + t_b (:meth:`~gdnplan.robot.Robot.body_poses`), so a
        node on body b is at p = R(θ_b) p⁰ + t_b and joint j, sitting on body j, at
        o_j(q) = R(θ_j) o_j⁰ + t_j: O(B (dof + N)) work, no per-joint copies.
        """
        poses = self.robot.body_poses(q)  # (B, dof + 1, 3)
        t, cos, sin = poses[..., :2], np.cos(poses[..., 2]), np.sin(poses[..., 2])
        dof = self.robot.dof
        joints = _rotate(cos[:, :dof], sin[:, :dof], self.robot.chain.joint_origins) + t[:, :dof]
        nodes = _rotate(cos[:, self.body], sin[:, self.body], self.nodes0) + t[:, self.body]
        return nodes, joints

    def positions(self, q: np.ndarray) -> np.ndarray:
        """(B, N, 2) node positions at q (B, dof) (m)."""
        return self.kinematics(q)[0]

    def pullback(self, nodes: np.ndarray, joints: np.ndarray, grad: np.ndarray) -> np.ndarray:
        """(B, dof) Σ_n (∂p_n/∂q)ᵀ g_n: a gradient g (B, N, 2) on the nodes chained to q.

        With ∂p_n/∂q_j = s_j ẑ × (p_n − o_j) for nodes downstream of joint j (M_nj = 1),
        g_n · (ẑ × r) = r × g_n, so (joint torques of the node forces g_n)

            ∂/∂q_j = s_j (Σ_n M_nj p_n × g_n − o_j × Σ_n M_nj g_n),

        two (N × dof) products instead of the (B, N, 2, dof) Jacobians.

        Args:
            nodes: (B, N, 2) and joints: (B, dof, 2) from :meth:`kinematics` (m).
            grad: (B, N, 2) gradient with respect to the node positions.
        """
        m = self.downstream
        torque = (nodes[..., 0] * grad[..., 1] - nodes[..., 1] * grad[..., 0]) @ m  # (B, dof)
        fx, fy = grad[..., 0] @ m, grad[..., 1] @ m
        lever = joints[..., 0] * fy - joints[..., 1] * fx
        return self.robot.chain.joint_signs * (torque - lever)

    @property
    def downstream(self) -> np.ndarray:
        """(N, dof) 1.0 where node n is moved by joint j (body_n > j)."""
        return (self.body[:, None] > np.arange(self.robot.dof)).astype(float)

    def positions_and_jacobians(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(B, N, 2) node positions and (B, N, 2, dof) Jacobians ∂p/∂q at q (B, dof)."""
        q = self.robot.check_q(q)
        p = self.positions(q)
        return p, self.robot.chain.jacobian(p, self.body, q)

    def batch(
        self,
        nodes: np.ndarray | torch.Tensor,
        device: str | torch.device = "cpu",
        dtype: torch.dtype = torch.float32,
    ) -> GraphBatch:
        """GraphBatch of node positions (B, N, 2) with this structure."""
        b = nodes.shape[0]
        nodes = torch.as_tensor(nodes, dtype=dtype, device=device)
        prev = torch.as_tensor(self.prev, device=device).expand(b, -1)
        next = torch.as_tensor(self.next, device=device).expand(b, -1)
        mask = torch.ones(b, self.n_nodes, dtype=torch.bool, device=device)
        return GraphBatch(nodes, prev, next, mask)


def _rotate(c: np.ndarray, s: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(B, N, 2) rotations R(θ_bn) p_n of points (N, 2) given cos θ and sin θ (B, N)."""
    x, y = points[:, 0], points[:, 1]
    return np.stack([c * x - s * y, s * x + c * y], -1)


@lru_cache(maxsize=64)
def robot_graph(robot: Robot, max_edge: float | None = None) -> RobotGraph:
    """The (cached) graph structure of a robot's link polygons, densified to ``max_edge``."""
    polys, bodies = [], []
    for poly in robot.polygons:
        v = poly.vertices0 if max_edge is None else densify(poly.vertices0, max_edge)
        polys.append(v)
        bodies.append(np.full(len(v), poly.body))
    sizes = np.array([[len(v) for v in polys]])
    padded = np.zeros((1, len(polys), sizes.max(), 2))
    for j, v in enumerate(polys):
        padded[0, j, : len(v)] = v
    nodes, prev, next, _ = rings(padded, np.arange(sizes.max()) < sizes[..., None])
    return RobotGraph(robot, max_edge, nodes[0], np.concatenate(bodies), prev[0], next[0])


def variant_graphs(
    groups: list[tuple[Robot, np.ndarray]], q: np.ndarray, max_edge: float | None = None
) -> tuple[np.ndarray, np.ndarray, GraphBatch]:
    """Robot graphs of samples whose robots differ (e.g. the UR5e's gripper states), padded.

    Args:
        groups: (robot, rows) pairs: the samples ``rows`` (index array) use ``robot``; every
            sample belongs to exactly one group, all robots have the same dof.
        q: (B, dof) joint angles (rad).
        max_edge: densification length (m) or None.

    Returns:
        nodes (B, N, 2) (m), Jacobians (B, N, 2, dof) and the structure as a GraphBatch with
        those nodes (float32), N the largest node count; padded slots have zero nodes and
        Jacobians, ``mask = False`` and point to themselves.
    """
    q = np.asarray(q, dtype=float)
    graphs = [(robot_graph(robot, max_edge), np.asarray(rows)) for robot, rows in groups]
    b, n = len(q), max(g.n_nodes for g, _ in graphs)
    if sorted(np.concatenate([rows for _, rows in graphs]).tolist()) != list(range(b)):
        raise InputError("groups: every sample must belong to exactly one robot group")
    nodes = np.zeros((b, n, 2))
    jac = np.zeros((b, n, 2, q.shape[1]))
    prev = np.broadcast_to(np.arange(n), (b, n)).copy()
    next = prev.copy()
    mask = np.zeros((b, n), bool)
    for g, rows in graphs:
        k = g.n_nodes
        nodes[rows, :k], jac[rows, :k] = g.positions_and_jacobians(q[rows])
        prev[rows, :k], next[rows, :k], mask[rows, :k] = g.prev, g.next, True
    return nodes, jac, GraphBatch.from_numpy(nodes, prev, next, mask)


__all__ = [
    "RobotGraph",
    "robot_graph",
    "variant_graphs",
]
