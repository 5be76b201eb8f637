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

Modules: shapes → nodes and edges (:func:`shape_points`, :func:`hull_edges`, :func:`knn_edges`,
:func:`neighbourhoods`) in :mod:`gdnplan.graph3d_shapes`, the robot graph
(:class:`RobotGraph3D`, :func:`robot_graph3d`) in :mod:`gdnplan.graph3d_robot`, obstacle graphs
(:class:`ObstacleGraph3D`, :func:`obstacle_graph3d`, :func:`scene_graph3d`, :func:`box_graphs`,
:func:`point_cloud_graph`) in :mod:`gdnplan.graph3d_obstacles`; this module re-exports their
names.
"""

from __future__ import annotations

from .graph3d_obstacles import (
    FACE_SPACING,
    ObstacleGraph3D,
    box_graphs,
    box_grid,
    graph_of_points,
    obstacle_graph3d,
    point_cloud_graph,
    scene_graph3d,
    union,
)
from .graph3d_robot import RobotGraph3D, robot_graph3d
from .graph3d_shapes import (
    COPLANAR,
    HULL_POINTS,
    RIM,
    farthest_points,
    fibonacci_sphere,
    hull_edges,
    knn_edges,
    neighbourhoods,
    shape_points,
)

__all__ = [
    "COPLANAR",
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
