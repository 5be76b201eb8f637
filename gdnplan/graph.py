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

Modules: the padded batch of ring graphs (:class:`GraphBatch`, :func:`rings`,
:func:`densify_padded`, :func:`collate`) in :mod:`gdnplan.graph_batch`, obstacle graphs
(:func:`obstacle_graph`, :func:`scene_obstacles`) in :mod:`gdnplan.graph_obstacles`, robot
graphs (:class:`RobotGraph`, :func:`robot_graph`, :func:`variant_graphs`) in
:mod:`gdnplan.graph_robot`; this module re-exports their names.
"""

from __future__ import annotations

from .graph_batch import GraphBatch, collate, densify_padded, rings
from .graph_obstacles import obstacle_graph, scene_obstacles
from .graph_robot import RobotGraph, robot_graph, variant_graphs
from .graph_robot import _rotate as _rotate

__all__ = [
    "GraphBatch",
    "RobotGraph",
    "collate",
    "densify_padded",
    "obstacle_graph",
    "rings",
    "robot_graph",
    "scene_obstacles",
    "variant_graphs",
]
