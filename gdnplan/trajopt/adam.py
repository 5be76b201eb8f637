"""The paper's baseline: Adam on the collision cost plus the path cost."""

from __future__ import annotations

import logging
import math
import time

import numpy as np

from ..exact import certify
from ..models import DistanceModel
from .check_points import _interpolation_matrix, distance_bounds, straight_line
from .config import PlanConfig
from .problem import Problem
from .result import _Run
from .seeds import SeedInfo

log = logging.getLogger("gdnplan.trajopt")  # one logger for the package: the stage lines


def collision_cost(
    d: np.ndarray, margin: float | np.ndarray, c: float, eps: float
) -> tuple[np.ndarray, np.ndarray]:
    """The paper's C(d) = c / ((d − d_margin)² + ε) for d ≥ d_margin and its derivative.

    Below the margin the paper's form would fall again (pushing deeper into collision), so
    there C continues linearly with slope −c/ε per metre: C = c/ε + (c/ε)(d_margin − d)/√ε.
    """
    gap = d - margin
    above = gap >= 0
    slope = c / eps / math.sqrt(eps)
    cost = np.where(above, c / (gap**2 + eps), c / eps - slope * gap)
    dcost = np.where(above, -2 * c * gap / (gap**2 + eps) ** 2, -slope)
    return cost, dcost


def project_steps(
    q: np.ndarray, max_step: float, lower: np.ndarray, upper: np.ndarray, sweeps: int = 50
) -> np.ndarray:
    """q (T, dof) moved into {|q_{t+1} − q_t| ≤ max_step, lower ≤ q ≤ upper} with q_0 and
    q_{T−1} fixed (rad). Alternating projections first: each sweep projects the even, then the
    odd segments (disjoint, so each half is exact: a step too long is shortened symmetrically
    about its middle, or towards a fixed end), then clips to the limits. What the sweeps leave
    over max_step is removed by moving towards the straight line between the ends, which keeps
    both bounds (Problem checks max_step · (T − 1) against the start-goal distance, and the
    ends lie within the limits): q ← L + β (q − L), the largest such β ∈ [0, 1]."""
    q = q.copy()
    free = np.ones(len(q), bool)
    free[[0, -1]] = False
    for _ in range(sweeps):
        if np.max(np.abs(np.diff(q, axis=0))) <= max_step:
            return q
        for first in (0, 1):
            t = np.arange(first, len(q) - 1, 2)
            step = q[t + 1] - q[t]
            excess = np.sign(step) * np.maximum(np.abs(step) - max_step, 0.0)
            a, b = free[t][:, None], free[t + 1][:, None]
            share = np.where(a & b, 0.5, 1.0)  # both free: half each; else all to the free one
            q[t] += np.where(a, share * excess, 0.0)
            q[t + 1] -= np.where(b, share * excess, 0.0)
        q[1:-1] = np.clip(q[1:-1], lower, upper)
    line = straight_line(q[0], q[-1], len(q))
    d, dl = np.diff(q, axis=0), np.diff(line, axis=0)
    over = np.abs(d) > max_step
    if not over.any():
        return q
    bound = np.sign(d[over]) * max_step  # the bound each long step crosses
    beta = np.min(np.clip((bound - dl[over]) / (d[over] - dl[over]), 0.0, 1.0))
    return line + beta * (q - line)


def _plan_adam(
    problem: Problem,
    model: DistanceModel,
    goal: np.ndarray,
    cfg: PlanConfig,
    seed: int = 0,
    deadline: float = math.inf,
) -> _Run:
    """Adam on the interior waypoints of Σ_k C(d(p_k)) + Σ_t ‖q_{t+1} − q_t‖², from the
    straight line, until the collision cost falls below the threshold — every term below
    C(margin + adam_stop), i.e. min_k d(p_k) ≥ margin + adam_stop as C decreases above the
    margin — or the iteration cap; every iterate is projected onto the step bound
    ``max_step`` and the joint limits (:func:`project_steps`). With ``ccd``, reaching the
    threshold triggers the continuous certificate; uncertified segments get twice the check
    points and Adam continues. The margin of each check point is that of
    :func:`distance_bounds` (relaxed next to an endpoint a learned model rates below the
    margin). It stops at ``deadline`` (a :func:`time.perf_counter` value) too; the
    certificate judges the path it has then, and after a non-finite step (an overflowing
    cost: huge ``c`` or ``lr``, tiny ``eps``) the last finite path."""
    opts, refine = cfg.optimizer, cfg.refine
    T = problem.waypoints
    splits = np.full(T - 1, opts.interpolated + 1)
    W = _interpolation_matrix(splits)
    slack = opts.stop + 0.005  # the fixed endpoints must pass the stop test
    lower = distance_bounds(problem, model, goal, splits, problem.margin, slack)
    q = straight_line(problem.start, goal, T)
    m, v = np.zeros_like(q), np.zeros_like(q)
    b1, b2 = 0.9, 0.999
    calls, refinements, status = 0, 0, "adam: iteration cap"
    for it in range(1, opts.iterations + 1):
        if time.perf_counter() >= deadline:
            status = "adam: time budget ended"
            break
        d, g = model.distance_and_grad(problem.scene, W @ q)
        calls += 1
        if np.all(d >= lower + opts.stop):
            clearance = problem.certified_clearance
            cert = certify(problem.scene, q, clearance) if refine.ccd else None
            if cert is None or cert.ok or refinements == refine.rounds:
                status = "adam: cost below threshold"
                break
            splits[list(cert.bad_segments)] *= 2
            W, refinements = _interpolation_matrix(splits), refinements + 1
            lower = distance_bounds(problem, model, goal, splits, problem.margin, slack)
            continue
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # checked below
            _, dc = collision_cost(np.asarray(d), lower, opts.c, opts.eps)
            grad = W.T @ (dc[:, None] * g)
            grad[1:] += 2 * (q[1:] - q[:-1])
            grad[:-1] -= 2 * (q[1:] - q[:-1])
            grad[[0, -1]] = 0.0
            m = b1 * m + (1 - b1) * grad
            v = b2 * v + (1 - b2) * grad**2
            step = opts.lr * (m / (1 - b1**it)) / (np.sqrt(v / (1 - b2**it)) + 1e-8)
        if not np.all(np.isfinite(step)):  # the cost overflowed (c/ε^1.5 or lr huge)
            status = "adam: diverged (a non-finite step; lower lr or c, or raise eps)"
            break  # keep the last finite path: the certificate judges it
        q = project_steps(q - step, problem.max_step, problem.lower, problem.upper)
    log.info("solve: %s, %d iterations", status, it)
    return _Run(
        q=q,
        iterations=it,
        status=status,
        reason=status,
        model_calls=calls,
        attempts=1,
        seed=SeedInfo("straight", 0, seed),
    )
