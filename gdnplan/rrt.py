"""Seed paths: RRT-Connect in joint space on certified coal edge checks, shortcut, resample.

Edges are straight joint-space segments accepted only when the scene's certificate
(:func:`gdnplan.exact.certify`: planar or 3-D) certifies them at the clearance asked for, so a
seed path is collision-free as a continuous motion, not only at its vertices.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from .errors import InputError
from .exact import certify, motion_bound_of
from .limits import is_number, shown
from .scene import Scene


@dataclass(frozen=True)
class RRTResult:
    """A joint path (K, dof) from start to goal (empty when ``success`` is False)."""

    success: bool
    path: np.ndarray
    iterations: int
    time: float


def edge_free(scene: Scene, qa: np.ndarray, qb: np.ndarray, clearance: float) -> bool:
    """True when the segment qa -> qb (dof,) is certified to stay above ``clearance`` (m)."""
    cert = certify(
        scene, np.stack([qa, qb]), margin=clearance, tol=np.inf, min_splits=1, stop_early=True
    )
    return cert.ok


class _Tree:
    """Growing array of configurations with parent indices."""

    def __init__(self, root: np.ndarray):
        self.q = root[None].copy()
        self.parent = [-1]

    def nearest(self, q: np.ndarray) -> int:
        return int(np.argmin(np.sum((self.q - q) ** 2, axis=1)))

    def add(self, q: np.ndarray, parent: int) -> int:
        self.q = np.vstack([self.q, q])
        self.parent.append(parent)
        return len(self.parent) - 1

    def branch(self, i: int) -> np.ndarray:
        """Configurations from the root to node i, (k, dof)."""
        out = []
        while i >= 0:
            out.append(self.q[i])
            i = self.parent[i]
        return np.array(out[::-1])


def _steer(q_from: np.ndarray, q_to: np.ndarray, step: float) -> np.ndarray:
    gap = q_to - q_from
    n = np.linalg.norm(gap)
    return q_to if n <= step else q_from + gap * (step / n)


def rrt_connect(
    scene: Scene,
    start: np.ndarray,
    goal: np.ndarray,
    clearance: float = 0.0,
    step: float = 2.0,
    max_iterations: int = 5000,
    time_limit: float = 10.0,
    seed: int = 0,
    lower: np.ndarray | None = None,
    upper: np.ndarray | None = None,
) -> RRTResult:
    """Bidirectional RRT-Connect (Kuffner & LaValle 2000) between start and goal (dof,).

    ``step`` is the largest joint-space (2-norm, rad) extension; samples are uniform within
    the joint limits; every edge is certified at ``clearance`` (m). Both the outer loop and
    the greedy connect loop stop at ``time_limit`` (s) or ``max_iterations`` extensions.
    Raises InputError for a step, time limit or clearance that is not a finite number > 0
    (clearance ≥ 0), or ``max_iterations`` < 1.
    """
    _check_settings(step, time_limit, clearance, max_iterations)
    robot = scene.robot
    lower = robot.lower if lower is None else lower
    upper = robot.upper if upper is None else upper
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    deadline = t0 + time_limit
    if edge_free(scene, start, goal, clearance):
        return RRTResult(True, np.stack([start, goal]), 0, time.perf_counter() - t0)
    trees = [_Tree(start), _Tree(goal)]
    for it in range(1, max_iterations + 1):
        if time.perf_counter() - t0 > time_limit:
            break
        a, b = trees if it % 2 else trees[::-1]
        target = rng.uniform(lower, upper)
        i = a.nearest(target)
        q_new = _steer(a.q[i], target, step)
        if not edge_free(scene, a.q[i], q_new, clearance):
            continue
        i_new = a.add(q_new, i)
        j = _connect(scene, b, q_new, step, clearance, deadline)
        if j is not None:
            path_a, path_b = a.branch(i_new), b.branch(j)[::-1]
            path = np.vstack([path_a, path_b])
            path = path if a is trees[0] else path[::-1]
            return RRTResult(True, path, it, time.perf_counter() - t0)
    return RRTResult(False, np.zeros((0, robot.dof)), it, time.perf_counter() - t0)


def _check_settings(step, time_limit, clearance, max_iterations) -> None:
    for name, value in (("rrt_step", step), ("rrt_time", time_limit)):
        if not is_number(value) or not math.isfinite(value) or value <= 0:
            raise InputError(f"{name}: expected a finite number > 0, got {shown(value)}")
    if not is_number(clearance) or not math.isfinite(clearance) or clearance < 0:
        raise InputError(f"rrt clearance: expected a finite number ≥ 0, got {shown(clearance)}")
    if (
        isinstance(max_iterations, bool)
        or not isinstance(max_iterations, int)
        or max_iterations < 1
    ):
        raise InputError(f"max_iterations: expected an integer ≥ 1, got {max_iterations!r}")


def _connect(
    scene: Scene, tree: _Tree, target: np.ndarray, step: float, clearance: float, deadline: float
):
    """Extend ``tree`` greedily towards target; the index of the node reaching it, else None
    (also when the clock passes ``deadline``)."""
    i = tree.nearest(target)
    while time.perf_counter() <= deadline:
        q_new = _steer(tree.q[i], target, step)
        if not edge_free(scene, tree.q[i], q_new, clearance):
            return None
        i = tree.add(q_new, i)
        if np.array_equal(q_new, target):
            return i
    return None


def shortcut(
    scene: Scene, path: np.ndarray, clearance: float, attempts: int = 100, seed: int = 0
) -> np.ndarray:
    """Random shortcutting: replace the stretch between two random vertices by a straight
    segment whenever that segment is certified free; path (K, dof) -> (K', dof).

    A short path offers few vertex pairs, so draws repeat: a pair whose segment failed the
    check is remembered and not checked again (the check is deterministic, so the result is
    the same as re-checking)."""
    rng = np.random.default_rng(seed)
    path = path.copy()
    blocked: set[tuple[bytes, bytes]] = set()
    for _ in range(attempts):
        if len(path) <= 2:
            break
        i, j = np.sort(rng.choice(len(path), 2, replace=False))
        pair = (path[i].tobytes(), path[j].tobytes())
        if j - i <= 1 or pair in blocked:
            continue
        if edge_free(scene, path[i], path[j], clearance):
            path = np.vstack([path[: i + 1], path[j:]])
        else:
            blocked.add(pair)
    return path


def resample(robot, path: np.ndarray, n: int) -> np.ndarray:
    """n configurations along the piecewise-linear path (K, dof), keeping its vertices when
    n ≥ K and spacing the others evenly by the motion bound (how far the robot moves)."""
    if len(path) == 1:
        return np.repeat(path, n, 0)
    length = motion_bound_of(robot, path[:-1], path[1:]) + 1e-12  # (K-1,)
    if n < len(path):
        s = np.concatenate([[0.0], np.cumsum(length)])
        targets = np.linspace(0.0, s[-1], n)
        k = np.clip(np.searchsorted(s, targets, side="right") - 1, 0, len(path) - 2)
        w = ((targets - s[k]) / length[k])[:, None]
        return path[k] + w * (path[k + 1] - path[k])
    pieces = _split_counts(length, n - 1)
    out = [path[0][None]]
    for k, m in enumerate(pieces):
        w = np.arange(1, m + 1)[:, None] / m
        out.append(path[k] + w * (path[k + 1] - path[k]))
    return np.vstack(out)


def _split_counts(length: np.ndarray, total: int) -> np.ndarray:
    """Split ``total`` ≥ len(length) pieces over segments, ≥ 1 each, ~proportional to length."""
    counts = np.ones(len(length), int)
    for _ in range(total - len(length)):
        counts[np.argmax(length / counts)] += 1
    return counts


def seed_path(
    scene: Scene,
    start: np.ndarray,
    goal: np.ndarray,
    n_waypoints: int,
    clearance: float,
    seed: int = 0,
    time_limit: float = 10.0,
    step: float = 2.0,
    max_iterations: int = 5000,
    lower: np.ndarray | None = None,
    upper: np.ndarray | None = None,
) -> tuple[np.ndarray | None, RRTResult]:
    """RRT-Connect (at most ``max_iterations`` extensions, sampling within the joint limits
    [``lower``, ``upper``] (dof,) rad, the robot's when None) + shortcut + resample:
    (n_waypoints, dof) seed, or None on failure. Shortcuts and resampling stay within the
    limits (a box holds the straight segment between two of its points)."""
    res = rrt_connect(scene, start, goal, clearance, step=step, seed=seed, time_limit=time_limit,
                      max_iterations=max_iterations, lower=lower, upper=upper)  # fmt: skip
    if not res.success:
        return None, res
    path = shortcut(scene, res.path, clearance, seed=seed)
    return resample(scene.robot, path, n_waypoints), res


__all__ = ["RRTResult", "edge_free", "resample", "rrt_connect", "seed_path", "shortcut"]
