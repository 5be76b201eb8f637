"""How far a planar robot's points move along a straight joint-space segment: lever arms and
the motion bound of the continuous certificate (:mod:`gdnplan.ccd`).

Along the straight joint-space segment q(s) = q_a + s (q_b − q_a), s ∈ [0, 1], a robot point p
on link l moves with ṗ = Σ_j s_j ẑ × (p − o_j(q)) Δq_j and |p − o_j(q)| ≤ r_{l,j}, the largest
lever arm from joint j to any vertex of link l (a rigid, configuration-independent bound, chained
through the joint-to-joint distances; the farthest point of a polygon from any point is a vertex).
So no point of link l travels farther than

    δ_l(q_a, q_b) = Σ_j r_{l,j} |Δq_j|                                        (m)

along the piece.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .errors import InputError
from .robot import Robot
from .robot_checks import check_pairs


@cache
def _lever_arms(robot: Robot) -> np.ndarray:
    o = robot.chain.joint_origins  # (dof, 2) at q = 0; distances are rigid
    hops = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(o, axis=0), axis=1))])
    arms = np.zeros((robot.n_links, robot.dof))
    for node, p0 in enumerate(robot.nodes0):
        link, body = robot.node_polygon[node], robot.node_body[node]
        if body == 0:
            continue
        last = body - 1  # the joint the node's body hangs from
        reach = hops[last] - hops[: last + 1] + np.linalg.norm(p0 - o[last])  # joints 0..last
        arms[link, : last + 1] = np.maximum(arms[link, : last + 1], reach)
    return arms


def lever_arms(robot: Robot) -> np.ndarray:
    """(n_links, dof) bound r_{l,j} ≥ |p − o_j(q)| for every point p of link l, any q (m).

    r_{l,j} = max_p Σ_{i=j}^{b−2} |o_{i+1} − o_i| + |p − o_{b−1}| over the vertices p of link l on
    body b > j (joints 0-indexed), and 0 where joint j is downstream of the link.
    """
    return _lever_arms(check_robot(robot))


def motion_bound(
    robot: Robot, qa: np.ndarray, qb: np.ndarray, per_link: bool = False
) -> np.ndarray:
    """Largest distance any robot point travels from qa to qb (B, dof) along the segment (m).

    Returns (B,) = max_l δ_l, or (B, n_links) with ``per_link``; δ_l = Σ_j r_{l,j} |Δq_j|.
    One configuration on either side pairs with every row of the other.
    """
    check_robot(robot)
    delta = np.abs(check_pairs(robot, qa, qb)) @ lever_arms(robot).T
    return delta if per_link else delta.max(axis=1)


def check_robot(robot: object) -> Robot:
    """``robot`` when it is a planar :class:`~gdnplan.robot.Robot`, else InputError naming it."""
    if not isinstance(robot, Robot):
        hint = "; a 3-D robot: use gdnplan.arm3d" if type(robot).__name__ == "Robot3D" else ""
        raise InputError(f"robot: expected a planar Robot, got {type(robot).__name__}{hint}")
    return robot
