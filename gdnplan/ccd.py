"""Continuous collision certificates for joint-space segments (conservative advancement).

Along the straight joint-space segment q(s) = q_a + s (q_b − q_a), s ∈ [0, 1], a robot point p
on link l moves with ṗ = Σ_j ∂p/∂q_j Δq_j and |∂p/∂q_j| = |p − o_j(q)| ≤ r_{l,j}, the largest
lever arm from joint j to any vertex of link l (a rigid, configuration-independent bound, chained
through the joint-to-joint distances). So no point of link l travels farther than

    δ_l(q_a, q_b) = Σ_j r_{l,j} |Δq_j|                                        (m)

and, signed distance being 1-Lipschitz in point displacement,
d_l(q(s)) ≥ max(d_l(q_a) − s δ_l, d_l(q_b) − (1 − s) δ_l) ≥ (d_l(q_a) + d_l(q_b) − δ_l) / 2.
Hence ``d(q_a) + d(q_b) ≥ δ + 2·margin`` certifies the whole segment at ``margin``.
:func:`certify_path` bisects every segment that this does not yet certify, until it is certified,
a checked configuration is within the margin (failure), or no robot point moves more than ``tol``
between two checked configurations (accepted: then d ≥ min(d_a, d_b) − tol/2 on the segment).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

from .distance import signed_distance
from .robot import Robot
from .scene import Scene


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
    """(n_links, dof) bound r_{l,j} ≥ |p − o_j(q)| for every vertex p of link l, any q (m).

    r_{l,j} = max_p Σ_{i=j}^{b−2} |o_{i+1} − o_i| + |p − o_{b−1}| over the vertices p of link l on
    body b > j (joints 0-indexed), and 0 where joint j is downstream of the link.
    """
    return _lever_arms(robot)


def motion_bound(
    robot: Robot, qa: np.ndarray, qb: np.ndarray, per_link: bool = False
) -> np.ndarray:
    """Largest distance any robot point travels from qa to qb (B, dof) along the segment (m).

    Returns (B,) = max_l δ_l, or (B, n_links) with ``per_link``; δ_l = Σ_j r_{l,j} |Δq_j|.
    """
    delta = np.abs(np.asarray(qb, float) - np.asarray(qa, float)) @ lever_arms(robot).T
    return delta if per_link else delta.max(axis=1)


@dataclass(frozen=True)
class Certificate:
    """Result of :func:`certify_path`.

    Attributes:
        ok: every segment is certified to stay above the margin (or subdivided to ``tol``).
        min_distance: smallest exact coal distance over all checked configurations (m).
        lower_bound: certified lower bound on the distance along the whole path (m).
        n_checks: coal evaluations made.
        bad_segments: indices of the waypoint segments holding a configuration within the
            margin (or left uncertified by the check budget).
    """

    ok: bool
    min_distance: float
    lower_bound: float
    n_checks: int
    bad_segments: tuple[int, ...]


def certify_path(
    scene: Scene,
    q_path: np.ndarray,
    margin: float = 0.0,
    tol: float = 1e-3,
    min_splits: int = 10,
    stop_early: bool = False,
    max_checks: int = 200_000,
) -> Certificate:
    """Certify the piecewise-linear joint path q_path (K, dof) against coal at ``margin``.

    Each waypoint segment starts split into ``min_splits`` pieces; uncertified pieces are
    bisected (all of them per round, one batched coal call) as described in the module doc.
    ``stop_early`` returns at the first configuration within the margin (for edge checks).
    """
    robot = scene.robot
    q_path = robot.check_q(q_path)
    s = np.linspace(0.0, 1.0, min_splits + 1)
    if len(q_path) == 1:
        qa, qb, seg = q_path, q_path, np.zeros(1, int)
    else:
        starts = q_path[:-1, None] + s[None, :-1, None] * (q_path[1:] - q_path[:-1])[:, None]
        ends = q_path[:-1, None] + s[None, 1:, None] * (q_path[1:] - q_path[:-1])[:, None]
        qa, qb = starts.reshape(-1, robot.dof), ends.reshape(-1, robot.dof)
        seg = np.repeat(np.arange(len(q_path) - 1), min_splits)
    nodes = np.concatenate([qa, qb[-1:]])
    d_nodes = signed_distance(scene, nodes)
    da, db = d_nodes[:-1], d_nodes[1:]
    n_checks = len(nodes)
    checked_d = [d_nodes]
    lower, bad_segments = np.inf, set()
    while len(qa):
        delta = motion_bound(robot, qa, qb)
        bad = (da <= margin) | (db <= margin)
        bad_segments.update(seg[bad].tolist())
        if bad_segments and stop_early:
            break
        done = bad | (da + db - delta >= 2 * margin) | (delta <= tol)
        if done.any():
            bound = np.minimum((da + db - delta) / 2, np.minimum(da, db))
            lower = min(
                lower,
                float(np.min(np.where(delta <= tol, np.minimum(da, db) - delta / 2, bound)[done])),
            )
        keep = ~done
        if n_checks + keep.sum() > max_checks:
            bad_segments.update(seg[keep].tolist())
            break
        qa, qb, da, db, seg = qa[keep], qb[keep], da[keep], db[keep], seg[keep]
        mid = (qa + qb) / 2
        dm = signed_distance(scene, mid) if len(mid) else np.zeros(0)
        n_checks += len(mid)
        checked_d.append(dm)
        qa, qb = np.concatenate([qa, mid]), np.concatenate([mid, qb])
        da, db = np.concatenate([da, dm]), np.concatenate([dm, db])
        seg = np.concatenate([seg, seg])
    min_d = float(np.min(np.concatenate(checked_d)))
    ok = not bad_segments
    return Certificate(ok, min_d, lower, n_checks, tuple(sorted(bad_segments)))


def verify_path(scene: Scene, q_path: np.ndarray, margin: float = 0.0) -> tuple[bool, float]:
    """Certified coal check of a joint path (K, dof): (no configuration on it within
    ``margin``, smallest checked distance in m). At least 10 checks per segment, bisection
    until conservative advancement certifies each piece or no point moves more than 1 mm."""
    cert = certify_path(scene, q_path, margin=margin, tol=1e-3, min_splits=10)
    return cert.ok, cert.min_distance


__all__ = ["Certificate", "certify_path", "lever_arms", "motion_bound", "verify_path"]
