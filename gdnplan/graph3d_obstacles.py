"""3-D obstacle graphs: convex obstacles, large boxes with grid faces, point clouds, scenes.

A convex obstacle's nodes are its shape's points (:func:`~gdnplan.graph3d_shapes.shape_points`)
posed in the world (m) with its polytope's edges; a box with a side longer than
``FACE_SPACING`` gets grid nodes over its faces (:func:`box_grid`); a point cloud (an array of
points, or a coal octree obstacle: its occupied voxels' centres) is the symmetrised
k-nearest-neighbour graph. A scene's graph is the :func:`union` of its obstacles' graphs.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np

from .arm3d.scene3d import Obstacle3D, Scene3D
from .errors import InputError
from .graph3d_shapes import RIM, hull_edges, knn_edges, neighbourhoods, shape_points

FACE_SPACING = 0.2  # m: the largest training box side; larger box sides get grid nodes


@dataclass(frozen=True)
class ObstacleGraph3D:
    """An obstacle graph: nodes (N, 3) (m), nbr and nbr_mask (N, D) padded neighbourhoods
    (:func:`~gdnplan.graph3d_shapes.neighbourhoods`)."""

    nodes: np.ndarray
    nbr: np.ndarray
    nbr_mask: np.ndarray

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)


def graph_of_points(points: np.ndarray, edges: np.ndarray) -> ObstacleGraph3D:
    """The graph of nodes ``points`` (k, 3) (m) joined by ``edges`` (E, 2) (node indices)."""
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
    """The symmetrised k-nearest-neighbour graph of a point cloud (n, 3) (m)
    (:func:`~gdnplan.graph3d_shapes.knn_edges`)."""
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
    "ObstacleGraph3D",
    "box_graphs",
    "box_grid",
    "graph_of_points",
    "obstacle_graph3d",
    "point_cloud_graph",
    "scene_graph3d",
    "union",
]
