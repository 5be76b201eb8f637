"""Paths and their check points: the straight line, the check points p = q_t + i/n_t
(q_{t+1} − q_t) of every segment as rows of an interpolation matrix, and the margins there
(raised near rejected segments for a learned model, relaxed next to an endpoint it rates below
the margin)."""

from __future__ import annotations

import numpy as np
from scipy import sparse

from ..arm3d.distance3d import Coal3DModel
from ..exact import exact_distance
from ..models import CoalModel, DistanceModel
from .problem import Problem


def is_exact(model: DistanceModel) -> bool:
    """True for the exact coal models (planar :class:`~gdnplan.models.CoalModel`, 3-D
    :class:`~gdnplan.arm3d.Coal3DModel`): no learned error to allow for."""
    return isinstance(model, (CoalModel, Coal3DModel))


def straight_line(start: np.ndarray, goal: np.ndarray, n: int) -> np.ndarray:
    """(n, dof) evenly spaced joint-space interpolation from start to goal, ending exactly at
    goal for n ≥ 2 (start + 1 · (goal − start) can be an ulp off it: a plan whose straight line
    was certified then ended beside its goal, and the 3-D fetch's pieces, stacked on the
    promise that each ends where the next begins, joined by a segment no certificate saw)."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    line = start + s * (goal - start)
    if n >= 2:
        line[-1] = goal
    return line


def _path_parameters(splits: np.ndarray) -> np.ndarray:
    """(Σ n_t + 1,) path parameter t + i / n_t of every check point of :func:`_interpolation_matrix`
    (waypoint t at t)."""
    parts = [t + np.arange(n_t) / n_t for t, n_t in enumerate(splits)]
    return np.concatenate([*parts, [float(len(splits))]])


def _interpolation_matrix(splits: np.ndarray) -> sparse.csr_matrix:
    """(Σ n_t + 1, T) sparse weights: row k of W·Q is the k-th check point along the path,
    with segment t split into n_t = splits[t] pieces (two nonzeros per row: 1 − i/n_t at
    waypoint t, i/n_t at t + 1; the last row is the goal). Sparse: refine rounds double the
    rejected segments' pieces, and a dense (K, T) array grew by K·T·8 bytes."""
    splits = np.asarray(splits, dtype=np.int64)
    T = len(splits) + 1
    seg = np.repeat(np.arange(T - 1), splits)  # the segment of each check point
    first = np.repeat(np.cumsum(splits) - splits, splits)  # row of each segment's waypoint
    frac = (np.arange(len(seg)) - first) / splits[seg]  # i / n_t
    k = np.arange(len(seg))
    rows = np.concatenate([k, k, [len(seg)]])
    cols = np.concatenate([seg, seg + 1, [T - 1]])
    vals = np.concatenate([1 - frac, frac, [1.0]])
    return sparse.csr_matrix((vals, (rows, cols)), shape=(len(seg) + 1, T))


def _near_segments(bad: list[int], n: int, window: int | None) -> np.ndarray:
    """(n,) bool: the segments ``bad`` and ``window`` segments either side of each (all n
    segments when window is None)."""
    if window is None:
        return np.ones(n, bool)
    near = np.zeros(n, bool)
    for t in bad:
        near[max(t - window, 0) : t + window + 1] = True
    return near


def _check_point_raise(splits: np.ndarray, raised: np.ndarray) -> np.ndarray:
    """(K,) margin raise of every inner check point: its segment's, the larger of the two at a
    waypoint."""
    s = _path_parameters(splits)[1:-1]
    lo = np.clip(np.ceil(s).astype(int) - 1, 0, len(splits) - 1)
    hi = np.clip(np.floor(s).astype(int), 0, len(splits) - 1)
    return np.maximum(raised[lo], raised[hi])


def constraint_margin(problem: Problem, buffer: float) -> float:
    """The check points' bound d ≥ max(margin, certified clearance + buffer) (m): above the
    clearance the certificate must prove (``TrajoptOptions.clearance_buffer``)."""
    return max(problem.margin, problem.certified_clearance + buffer)


def model_overestimate(
    scene, model: DistanceModel, q: np.ndarray, segments: list[int], margin: float
) -> float:
    """How much a learned model overestimates the distance where coal finds the path too close.

    Samples the given waypoint segments of q (T, dof) densely (20 points each) and returns
    max(d̂ − d_coal) over the points with d_coal < margin, at least 5 mm (m).
    """
    t = np.linspace(0.0, 1.0, 21)[:, None]
    points = np.concatenate([q[i] + t * (q[i + 1] - q[i]) for i in segments])
    d_coal = exact_distance(scene, points)
    close = d_coal < margin
    if not close.any():
        return 0.005
    excess = model.distance(scene, points[close]) - d_coal[close]
    return max(float(np.max(excess)), 0.005)


def distance_bounds(
    problem: Problem,
    model: DistanceModel,
    goal: np.ndarray,
    splits: np.ndarray,
    margin: float,
    slack: float = 0.005,
) -> np.ndarray:
    """(K,) lower bounds of the distance at the check points of ``splits`` (m).

    margin everywhere — except that a learned model may rate a fixed endpoint q_e (start or
    goal) below the margin although coal certifies it (e.g. the fingers around the stick at
    the grasp): then no path satisfies d̂ ≥ margin at q_e. The check points of the segment
    touching q_e are bounded instead by

        b_e = min(margin, d̂(q_e) − slack),

    which q_e itself satisfies; the coal certificate still judges the whole path. Used by the
    Adam optimiser, whose stop test (over every check point, q_e included) would otherwise
    never pass. Ipopt keeps the plain margin and has no rows at q_e (package docstring): with
    these bounds it was slow and its path hugged the obstacles
    (docs/decisions.md#endpoint-relaxed-bounds-adam-only).
    """
    bounds = np.full(int(np.sum(splits)) + 1, margin)
    if is_exact(model):
        return bounds
    d_ends = model.distance(problem.scene, np.stack([problem.start, goal]))
    first, last = slice(0, int(splits[0])), slice(len(bounds) - 1 - int(splits[-1]), None)
    for part, d_end in ((first, d_ends[0]), (last, d_ends[1])):
        bounds[part] = np.minimum(bounds[part], d_end - slack)
    return bounds
