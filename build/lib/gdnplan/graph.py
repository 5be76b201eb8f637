"""Robot and obstacle graphs (paper §IV-A) as dense, padded batch tensors.

A graph is a union of rings: the vertices of a polygon are its nodes (features: plane
coordinates, m) and every node is linked to its predecessor and successor on the polygon, so
the neighbourhood of node i is N(i) = {prev(i), next(i)}. The robot graph holds the link
polygons at q, the obstacle graph the (possibly non-convex) obstacle polygons. Long edges can
be densified: extra nodes split every edge into pieces no longer than ``max_edge``; on the
robot they are placed in the body frame at q = 0 and move with the chain,

    p(q) = T_1(q_1) ∘ … ∘ T_b(q_b)(p⁰),   ∂p/∂q_j = s_j ẑ × (p − o_j(q)) for j ≤ b

(see :mod:`gdnplan.robot`). A batch of B graphs of different sizes is padded to the largest,
N nodes: padded slots have ``mask = False`` and point to themselves.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import torch

from .errors import InputError
from .geometry import densify
from .robot import Robot
from .scene import Scene


@dataclass(frozen=True)
class GraphBatch:
    """B ring graphs padded to N nodes.

    Attributes:
        nodes: (B, N, 2) node coordinates (m, or normalised units inside the model).
        prev: (B, N) long, index of the previous node on the same ring.
        next: (B, N) long, index of the next node on the same ring.
        mask: (B, N) bool, True for real nodes.
    """

    nodes: torch.Tensor
    prev: torch.Tensor
    next: torch.Tensor
    mask: torch.Tensor

    @classmethod
    def from_numpy(
        cls,
        nodes: np.ndarray,
        prev: np.ndarray,
        next: np.ndarray,
        mask: np.ndarray,
        device: str | torch.device = "cpu",
        dtype: torch.dtype = torch.float32,
    ) -> GraphBatch:
        return cls(
            torch.as_tensor(nodes, dtype=dtype, device=device),
            torch.as_tensor(prev, dtype=torch.long, device=device),
            torch.as_tensor(next, dtype=torch.long, device=device),
            torch.as_tensor(mask, dtype=torch.bool, device=device),
        )

    def __len__(self) -> int:
        return self.nodes.shape[0]

    def with_nodes(self, nodes: torch.Tensor) -> GraphBatch:
        """The same structure with other node coordinates (B, N, 2)."""
        return GraphBatch(nodes, self.prev, self.next, self.mask)

    def index(self, rows: torch.Tensor | slice) -> GraphBatch:
        """The graphs at ``rows``, trimmed to their largest node count."""
        mask = self.mask[rows]
        n = max(int(mask.sum(1).max()), 1) if mask.numel() else 1
        return GraphBatch(
            self.nodes[rows][:, :n], self.prev[rows][:, :n], self.next[rows][:, :n], mask[:, :n]
        )

    def to(self, device: str | torch.device) -> GraphBatch:
        return GraphBatch(*(t.to(device) for t in (self.nodes, self.prev, self.next, self.mask)))


def rings(
    points: np.ndarray, valid: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Compact padded polygons into padded ring graphs, without a loop over samples.

    Args:
        points: (B, P, S, 2) vertex slots of P polygons, in ring order along S.
        valid: (B, P, S) True for real vertices (any pattern; order along S is kept).

    Returns:
        nodes (B, N, 2), prev (B, N), next (B, N), mask (B, N) with N the largest node count.
    """
    b = valid.shape[0]
    count = valid.sum(-1)  # (B, P)
    pos = np.cumsum(valid, -1) - 1  # position of each slot within its ring
    offset = np.cumsum(count, -1) - count  # first node of each ring
    total = count.sum(-1)  # (B,)
    n = max(int(total.max(initial=0)), 1)
    idx = offset[..., None] + pos  # (B, P, S) compacted index of each slot
    cnt = np.maximum(count, 1)[..., None]
    bi = np.broadcast_to(np.arange(b)[:, None, None], valid.shape)[valid]
    slot = idx[valid]
    nodes = np.zeros((b, n, 2), dtype=points.dtype)
    nodes[bi, slot] = points[valid]
    prev = np.broadcast_to(np.arange(n), (b, n)).copy()
    next = prev.copy()
    prev[bi, slot] = (offset[..., None] + (pos - 1) % cnt)[valid]
    next[bi, slot] = (offset[..., None] + (pos + 1) % cnt)[valid]
    mask = np.arange(n) < total[:, None]
    return nodes, prev, next, mask


def densify_padded(
    polygons: np.ndarray, sizes: np.ndarray, max_edge: float | None
) -> tuple[np.ndarray, np.ndarray]:
    """Vertex slots and validity of padded polygons, edges split to at most ``max_edge`` (m).

    Edge v → v+1 of a polygon with m vertices is split into k = ⌈|e| / max_edge⌉ pieces with
    points a + (t/k)(b − a), t = 0 … k − 1 (the same points as :func:`geometry.densify`).

    Args:
        polygons: (B, P, V, 2) zero-padded CCW polygons.
        sizes: (B, P) vertex counts.
        max_edge: longest edge after splitting, or None to keep the vertices.

    Returns:
        points (B, P, S, 2) and valid (B, P, S), S = V · (most pieces of any edge).
    """
    v = polygons.shape[2]
    valid = np.arange(v) < sizes[..., None]  # (B, P, V)
    if max_edge is None:
        return polygons, valid
    if max_edge <= 0:
        raise InputError(f"max_edge: expected a positive length (m) or None, got {max_edge}")
    nxt = (np.arange(v) + 1) % np.maximum(sizes[..., None], 1)  # (B, P, V)
    b_vertex = np.take_along_axis(polygons, nxt[..., None], 2)
    length = np.linalg.norm(b_vertex - polygons, axis=-1)
    pieces = np.where(valid, np.maximum(np.ceil(length / max_edge), 1), 0).astype(int)
    k = max(int(pieces.max(initial=1)), 1)
    t = np.arange(k)  # (k,)
    frac = t / np.maximum(pieces, 1)[..., None]  # (B, P, V, k)
    pts = polygons[..., None, :] + frac[..., None] * (b_vertex - polygons)[..., None, :]
    ok = t < pieces[..., None]
    shape = (*polygons.shape[:2], v * k)
    return pts.reshape(*shape, 2), ok.reshape(shape)


def obstacle_graph(
    polygons: np.ndarray,
    sizes: np.ndarray,
    max_edge: float | None = None,
    device: str | torch.device = "cpu",
    dtype: torch.dtype = torch.float32,
) -> GraphBatch:
    """Obstacle graphs of a batch of obstacle sets.

    Args:
        polygons: (B, P, V, 2) zero-padded CCW polygons (m), as stored by :mod:`gdnplan.data`.
        sizes: (B, P) vertex counts (0 = no polygon in this slot).
        max_edge: densify edges longer than this (m), or None.

    Returns:
        GraphBatch with the union of the rings of each sample's polygons.
    """
    polygons = np.asarray(polygons, dtype=float)
    sizes = np.asarray(sizes)
    if polygons.ndim != 4 or polygons.shape[-1] != 2 or sizes.shape != polygons.shape[:2]:
        raise InputError(
            f"obstacles: expected polygons (B, P, V, 2) and sizes (B, P), got "
            f"{polygons.shape} and {sizes.shape}"
        )
    if np.any(sizes > polygons.shape[2]) or np.any((sizes > 0) & (sizes < 3)):
        raise InputError("obstacles sizes: each polygon needs 3 … V vertices (or 0 for none)")
    if not np.all(np.isfinite(polygons)):
        raise InputError("obstacles: contains NaN or infinite coordinates")
    points, valid = densify_padded(polygons, sizes, max_edge)
    return GraphBatch.from_numpy(*rings(points, valid), device=device, dtype=dtype)


def scene_obstacles(scenes: list[Scene]) -> tuple[np.ndarray, np.ndarray]:
    """Padded obstacle polygons (B, P, V, 2) and sizes (B, P) of a list of scenes."""
    if not scenes or any(len(s.obstacles) == 0 for s in scenes):
        raise InputError("scene.obstacles: GraphDistNet needs at least one obstacle polygon")
    n_poly = max(len(s.obstacles) for s in scenes)
    n_vert = max(len(p) for s in scenes for p in s.obstacles)
    out = np.zeros((len(scenes), n_poly, n_vert, 2))
    sizes = np.zeros((len(scenes), n_poly), np.int64)
    for i, s in enumerate(scenes):
        for j, p in enumerate(s.obstacles):
            out[i, j, : len(p)] = p
            sizes[i, j] = len(p)
    return out, sizes


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


def collate(graphs: list[tuple[np.ndarray, np.ndarray, np.ndarray]], **kwargs) -> GraphBatch:
    """Pad per-sample graphs (nodes (n_i, 2), prev (n_i,), next (n_i,)) into one GraphBatch.

    For robots whose graph changes between samples (e.g. the UR5e with different grippers).
    """
    if not graphs:
        raise InputError("graphs: expected at least one graph to collate")
    n = max(len(g[0]) for g in graphs)
    b = len(graphs)
    nodes = np.zeros((b, n, 2))
    prev = np.broadcast_to(np.arange(n), (b, n)).copy()
    next = prev.copy()
    mask = np.zeros((b, n), bool)
    for i, (x, p, nx) in enumerate(graphs):
        k = len(x)
        nodes[i, :k], prev[i, :k], next[i, :k], mask[i, :k] = x, p, nx, True
    return GraphBatch.from_numpy(nodes, prev, next, mask, **kwargs)


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
