"""3-D robot and obstacle graphs (paper §IV-A lifted to 3-D) for GraphDistNet-3D.

A graph's nodes are points of the geometry (features: world coordinates, m) and its edges are
the geometry's own: for a convex shape, the edges of the convex polytope of its nodes (hull
edges: the edges of scipy's Qhull triangulation between facets that are not coplanar, so a box
has its 12 edges, a sampled cylinder its two rims and the lines between them); for a point
cloud (an array of points, or a coal octree obstacle: its occupied voxels' centres), the
symmetrised k-nearest-neighbour graph. Node degrees differ, so a graph stores its
neighbourhoods padded to the largest degree D with a mask: ``nbr`` (N, D) node indices (padded
slots point to the node itself) and ``nbr_mask`` (N, D).

Robot nodes (:func:`robot_graph3d`) are surface points of each link shape in the frame of the
body it moves with: a box's 8 corners, ``rim`` points on each rim circle of a cylinder (a
capsule: the rims of its cylinder and the tips of its caps), a Fibonacci sample of ``rim²/2``
points on a sphere, and at most ``hull_points`` hull vertices of a mesh hull (farthest-point
sampling). At a configuration q (rad) node n on body i is at

    p_n(q) = oMᵢ(q) · p_n⁰,     ∂p_n/∂q_j = J_v,j + ω_j × p_n   for the joints j supporting i,

with [J_v; ω] Pinocchio's joint Jacobian columns in the WORLD frame (the velocity of the point
at the world origin, :func:`pinocchio.computeJointJacobians`); zero for the other joints.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import coal
import numpy as np
import pinocchio as pin
from scipy.spatial import ConvexHull, QhullError, cKDTree

from .arm3d.robot3d import Robot3D
from .arm3d.scene3d import Obstacle3D, Scene3D
from .arm3d.shapes import bvh_vertices
from .errors import InputError

RIM = 8  # points per cylinder rim (docs/decisions.md#graphdistnet-3d-robot-graph-nodes)
HULL_POINTS = 24  # most vertices kept of a mesh hull
COPLANAR = 1e-10  # facets with 1 − n₁·n₂ below this (unit normals) are one face
FACE_SPACING = 0.2  # m: the largest training box side; larger box sides get grid nodes


# -------------------------------------------------------------------- shapes → points
def fibonacci_sphere(n: int) -> np.ndarray:
    """(n, 3) nearly uniform unit vectors (golden-angle spiral)."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = np.pi * (1 + 5**0.5) * k
    r = np.sqrt(1 - z * z)
    return np.c_[r * np.cos(phi), r * np.sin(phi), z]


def farthest_points(points: np.ndarray, n: int) -> np.ndarray:
    """Indices of n of ``points`` (k, 3), farthest-point sampling from the first (all if k ≤ n)."""
    if len(points) <= n:
        return np.arange(len(points))
    chosen = [0]
    d = np.linalg.norm(points - points[0], axis=1)
    for _ in range(n - 1):
        chosen.append(int(np.argmax(d)))
        d = np.minimum(d, np.linalg.norm(points - points[chosen[-1]], axis=1))
    return np.array(chosen)


def shape_points(shape, rim: int = RIM, hull_points: int = HULL_POINTS) -> np.ndarray:
    """(k, 3) surface points of a coal shape in its own frame (m), module docstring."""
    if isinstance(shape, coal.Box):
        h = np.asarray(shape.halfSide)
        return np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * h
    if isinstance(shape, coal.Sphere):
        return shape.radius * fibonacci_sphere(max(rim * rim // 2, 4))
    if isinstance(shape, (coal.Cylinder, coal.Capsule)):
        t = 2 * np.pi * np.arange(rim) / rim
        circle = shape.radius * np.c_[np.cos(t), np.sin(t)]
        h = shape.halfLength
        pts = [np.c_[circle, np.full(rim, z)] for z in (-h, h)]
        if isinstance(shape, coal.Capsule):
            pts.append(np.array([[0.0, 0.0, -h - shape.radius], [0.0, 0.0, h + shape.radius]]))
        return np.concatenate(pts)
    if hasattr(shape, "points") or hasattr(shape, "vertices"):
        v = bvh_vertices(shape)
        return v[farthest_points(v, hull_points)]
    raise InputError(f"shape: no graph nodes for coal {type(shape).__name__}")


def hull_edges(points: np.ndarray) -> np.ndarray:
    """(E, 2) edges of the convex polytope of ``points`` (k, 3), k ≥ 4 and not flat: the edges
    shared by two hull facets that are not coplanar (module docstring)."""
    try:
        hull = ConvexHull(points)
    except (QhullError, ValueError) as e:
        raise InputError("points: their convex hull is flat or degenerate") from e
    normals = hull.equations[:, :3]
    faces: dict[tuple[int, int], list[int]] = {}
    for f, tri in enumerate(hull.simplices):
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            faces.setdefault((min(a, b), max(a, b)), []).append(f)
    edges = [e for e, fs in faces.items() if 1 - normals[fs[0]] @ normals[fs[-1]] > COPLANAR]
    return np.array(sorted(edges), dtype=int).reshape(-1, 2)


def knn_edges(points: np.ndarray, k: int) -> np.ndarray:
    """(E, 2) symmetrised k-nearest-neighbour edges (i < j) of a point cloud (n, 3)."""
    k = min(k, len(points) - 1)
    if k < 1:
        return np.zeros((0, 2), dtype=int)
    _, idx = cKDTree(points).query(points, k + 1)
    rows = np.repeat(np.arange(len(points)), k)
    pairs = np.sort(np.c_[rows, idx[:, 1:].ravel()], axis=1)
    return np.unique(pairs, axis=0)


def neighbourhoods(n: int, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Padded neighbourhoods of an undirected graph: nbr (n, D) and nbr_mask (n, D), D the
    largest degree (at least 1); padded slots point to the node itself."""
    edges = np.asarray(edges, dtype=int).reshape(-1, 2)
    both = np.concatenate([edges, edges[:, ::-1]])
    degree = np.bincount(both[:, 0], minlength=n)
    width = max(int(degree.max(initial=0)), 1)
    nbr = np.repeat(np.arange(n)[:, None], width, 1)
    mask = np.zeros((n, width), bool)
    order = np.argsort(both[:, 0], kind="stable")
    src, dst = both[order, 0], both[order, 1]
    slot = np.arange(len(src)) - np.searchsorted(src, src)
    nbr[src, slot], mask[src, slot] = dst, True
    return nbr, mask


# -------------------------------------------------------------------- robot graph
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


# -------------------------------------------------------------------- obstacle graphs
@dataclass(frozen=True)
class ObstacleGraph3D:
    """An obstacle graph: nodes (N, 3) (m), nbr and nbr_mask (N, D) (module docstring)."""

    nodes: np.ndarray
    nbr: np.ndarray
    nbr_mask: np.ndarray

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)


def graph_of_points(points: np.ndarray, edges: np.ndarray) -> ObstacleGraph3D:
    nbr, mask = neighbourhoods(len(points), edges)
    return ObstacleGraph3D(np.asarray(points, dtype=float), nbr, mask)


def union(graphs: list[ObstacleGraph3D]) -> ObstacleGraph3D:
    """One graph of disjoint graphs (node indices shifted, neighbourhoods padded to the widest)."""
    if not graphs:
        raise InputError("obstacles: GraphDistNet-3D needs at least one obstacle")
    width = max(g.nbr.shape[1] for g in graphs)
    nodes, nbr, mask, offset = [], [], [], 0
    for g in graphs:
        pad = width - g.nbr.shape[1]
        own = np.repeat(np.arange(g.n_nodes)[:, None], pad, 1)
        nodes.append(g.nodes)
        nbr.append(np.concatenate([g.nbr, own], 1) + offset)
        mask.append(np.concatenate([g.nbr_mask, np.zeros((g.n_nodes, pad), bool)], 1))
        offset += g.n_nodes
    return ObstacleGraph3D(np.concatenate(nodes), np.concatenate(nbr), np.concatenate(mask))


def box_grid(half: np.ndarray, spacing: float = FACE_SPACING) -> tuple[np.ndarray, np.ndarray]:
    """Surface nodes (k, 3) and edges (E, 2) of a box of half sides ``half`` (3,) (m) in its
    own frame, for a box with a side longer than ``spacing``.

    Side a is cut into n_a = ⌈2h_a / spacing⌉ equal steps; the nodes are the points of the
    lattice x_a = −h_a + 2h_a i / n_a (i = 0 … n_a) on the surface (some coordinate at ±h_a),
    the edges join lattice neighbours (one step along one axis) that are both on the surface:
    every face is a grid of spacing ≤ ``spacing`` and the box's 12 edges are paths of it. A box
    with every side ≤ ``spacing`` has n = (1, 1, 1): its 8 corners and 12 edges (the caller
    keeps :func:`shape_points`' order for those, so their graphs do not change)."""
    n = np.maximum(1, np.ceil(2 * half / spacing - 1e-9)).astype(int)
    axes = [np.linspace(-h, h, k + 1) for h, k in zip(half, n, strict=True)]
    idx = np.stack(np.meshgrid(*(np.arange(k + 1) for k in n), indexing="ij"), -1).reshape(-1, 3)
    on = np.any((idx == 0) | (idx == n), axis=1)
    number = -np.ones(len(idx), int)
    number[on] = np.arange(on.sum())
    grid = number.reshape(*(n + 1))
    edges = []
    for a in range(3):
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[a], hi[a] = slice(0, -1), slice(1, None)
        u, v = grid[tuple(lo)].ravel(), grid[tuple(hi)].ravel()
        keep = (u >= 0) & (v >= 0)
        edges.append(np.c_[u[keep], v[keep]])
    pts = np.array([[axes[a][i[a]] for a in range(3)] for i in idx[on]])
    return pts, np.concatenate(edges)


def obstacle_graph3d(obstacle: Obstacle3D, rim: int = RIM, k: int = 6) -> ObstacleGraph3D:
    """The graph of one obstacle posed in the world: a convex shape's points
    (:func:`shape_points`) with its polytope's edges, but a box with a side longer than
    FACE_SPACING gets grid nodes over its faces (:func:`box_grid`: its corners alone would
    leave the middle of a table or a wall unseen); a coal octree (a sensor's point cloud as
    coal sees it) as the k-nearest-neighbour graph of its occupied voxels' centres."""
    rot, trans = np.asarray(obstacle.pose.getRotation()), np.asarray(obstacle.pose.getTranslation())
    if isinstance(obstacle.shape, coal.OcTree):
        centres = np.asarray(obstacle.shape.toBoxes(), dtype=float).reshape(-1, 6)[:, :3]
        return point_cloud_graph(centres @ rot.T + trans, k)
    if isinstance(obstacle.shape, coal.Box):
        half = np.asarray(obstacle.shape.halfSide)
        if 2 * half.max() > FACE_SPACING + 1e-9:
            pts, edges = box_grid(half)
            return graph_of_points(pts @ rot.T + trans, edges)
    pts = shape_points(obstacle.shape, rim)
    return graph_of_points(pts @ rot.T + trans, hull_edges(pts))


def point_cloud_graph(points, k: int = 6) -> ObstacleGraph3D:
    """The k-nearest-neighbour graph of a point cloud (n, 3) (m) (module docstring)."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 1 or not np.all(np.isfinite(pts)):
        raise InputError(f"points: expected a finite (n, 3) point cloud, got shape {pts.shape}")
    return graph_of_points(pts, knn_edges(pts, k))


def scene_graph3d(scene: Scene3D, clouds=(), k: int = 6, rim: int = RIM) -> ObstacleGraph3D:
    """The obstacle graph of a scene: every obstacle's graph (:func:`obstacle_graph3d`) and the
    kNN graph of each point cloud in ``clouds`` ((n_i, 3) arrays, m)."""
    graphs = [obstacle_graph3d(o, rim, k) for o in scene.obstacles]
    graphs += [point_cloud_graph(c, k) for c in clouds]
    return union(graphs)


def box_graphs(centers: np.ndarray, sizes: np.ndarray) -> ObstacleGraph3D:
    """The graph of axis-aligned boxes, centres (M, 3) and full sides (M, 3) (m): 8 corners and
    12 edges each (the same as :func:`obstacle_graph3d` of the boxes)."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * 0.5
    edges = hull_edges(corners)
    graphs = [graph_of_points(c + corners * s, edges) for c, s in zip(centers, sizes, strict=True)]
    return union(graphs)


__all__ = [
    "FACE_SPACING",
    "HULL_POINTS",
    "RIM",
    "ObstacleGraph3D",
    "RobotGraph3D",
    "box_graphs",
    "box_grid",
    "farthest_points",
    "fibonacci_sphere",
    "graph_of_points",
    "hull_edges",
    "knn_edges",
    "neighbourhoods",
    "obstacle_graph3d",
    "point_cloud_graph",
    "robot_graph3d",
    "scene_graph3d",
    "shape_points",
    "union",
]
