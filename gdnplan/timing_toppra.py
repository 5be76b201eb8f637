"""The ``smooth`` timing of :mod:`gdnplan.timing`: toppra's time-optimal s(t) along the PCHIP
curve through the waypoints, and proven bounds of |q̇| and |q̈| over every grid cell
(:func:`cell_bounds`) that set the time stretch c making the limits hold between grid points.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import InputError
from .timing_profiles import SmoothProfile

GRID_PER_SEGMENT = 8  # toppra grid cells per waypoint segment (fewer above MAX_GRID)
MAX_GRID = 4000  # toppra grid points at most
BEFORE_KNOT = (1e-6, 1e-3, 1e-2, 0.0)  # grid points this share of a segment before inner knots
STRETCH_SLACK = 1e-9  # c is raised by this fraction (rounding of the cell bounds)


def chord_knots(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cumulative chord length of the distinct waypoints (K,) and each waypoint's knot (T,).

    Each chord is the scaled norm h = m ‖Δq / m‖ with m = max_j |Δq_j| (rad), so a step whose
    squared components underflow (|Δq| ≲ 1e-154 rad) still has h ≥ m > 0 (a plain ‖Δq‖ gave 0:
    two distinct waypoints on one knot). Knots can still repeat (a step below the rounding of
    the knot before it); :func:`pchip_curve` refuses them.
    """
    keep = np.concatenate([[True], np.any(np.diff(q, axis=0) != 0, axis=1)])
    index = np.cumsum(keep) - 1
    step = np.diff(q[keep], axis=0)
    scale = np.max(np.abs(step), axis=1, initial=0.0)
    unit = step / np.where(scale > 0, scale, 1.0)[:, None]
    knots = np.concatenate([[0.0], np.cumsum(scale * np.linalg.norm(unit, axis=1))])
    return knots, index


def pchip_curve(knots: np.ndarray, points: np.ndarray):
    """The PCHIP curve p(s) through ``points`` (K, dof) rad at ``knots`` (K,), a cubic
    ``PPoly``; None when there is no segment or float64 cannot hold the curve.

    That is: knots not strictly increasing (a waypoint step below the rounding of the chord
    length before it), or a coefficient that is not finite. The secant slopes are at most 1
    (chord parameter), so a piece of chord h (rad) has a cubic coefficient up to ~1 / h²,
    which overflows for h ≲ 1e-154 rad: the coefficients became inf and NaN, and the
    certificate then raised on NaN configurations, or SciPy on repeated knots (a step whose
    chord underflowed to 0). The caller times the polygon instead.
    """
    if len(knots) < 2 or not np.all(np.diff(knots) > 0):
        return None
    # imported here: a slow import (docs/decisions.md#lazy-imports)
    from scipy.interpolate import PchipInterpolator

    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        curve = PchipInterpolator(knots, points, axis=0)
    return curve if np.all(np.isfinite(curve.c)) else None


def toppra_profile(curve, knots: np.ndarray, v: np.ndarray, a: np.ndarray) -> SmoothProfile | None:
    """toppra's time-optimal s(t) on ``curve``; None when toppra finds no parametrisation."""
    import logging

    try:
        import toppra  # noqa: F401  (imported for use in _toppra_on_grid)
    except ImportError as e:  # PyPI has toppra wheels for Linux x86-64 only
        raise InputError(
            f"max_acceleration: the smooth timing needs toppra ({e}); pip install toppra, "
            "or time the plan without max_acceleration"
        ) from e

    logging.getLogger("toppra").setLevel(logging.ERROR)
    scale = time_scale(v, a)
    segments = len(knots) - 1
    m = max(2, min(GRID_PER_SEGMENT, MAX_GRID // (2 * segments)))
    cells = np.linspace(0.0, 1.0, m + 1)[:-1]
    cells = (knots[:-1, None] + cells[None] * np.diff(knots)[:, None]).ravel()
    for offset in BEFORE_KNOT:  # the closest first; toppra may call a grid uncontrollable
        before = knots[1:-1] - offset * np.diff(knots)[:-1]  # p'' jumps at every knot
        grid = np.unique(np.concatenate([cells, before if offset else [], knots[-1:]]))
        prof = _toppra_on_grid(curve, knots, grid, v, a, scale)
        if prof is not None:
            return prof
    return None


def time_scale(v: np.ndarray, a: np.ndarray) -> float:
    """λ > 0 with min(min_j v_j λ, √(min_j a_j) λ) = 1: toppra runs under the limits v λ and
    a λ², whose path speed ṡ is of order 1, and its ṡ is divided by λ (a time-optimal
    parametrisation scales exactly so). toppra's tolerances are absolute: under
    a = 1e-6 rad/s² (ṡ ~ 1e-3) its ṡ broke the acceleration limit between grid points so far
    that the stretch c was 25 (1.02 under a = 1): the smooth timing took 83 000 s where
    stopping at every waypoint took 12 000 s."""
    return 1.0 / min(float(np.min(v)), math.sqrt(float(np.min(a))))


def _toppra_on_grid(curve, knots, grid, v, a, scale: float = 1.0) -> SmoothProfile | None:
    """toppra on one grid under the limits v ``scale`` and a ``scale``² (:func:`time_scale`),
    its ṡ divided by ``scale`` (None when it finds no parametrisation); the time stretch c
    makes the limits v, a hold on every cell whatever the grid (:func:`cell_bounds`)."""
    import toppra
    import toppra.algorithm
    import toppra.constraint as tc
    from toppra.algorithm.algorithm import ParameterizationReturnCode

    class Path(toppra.interpolator.AbstractGeometricPath):
        dof = curve.c.shape[2]
        path_interval = np.array([knots[0], knots[-1]])

        def __call__(self, s, order=0):
            return curve(s, order)

    constraints = [
        tc.JointVelocityConstraint(np.column_stack([-v, v]) * scale),
        tc.JointAccelerationConstraint(
            np.column_stack([-a, a]) * scale**2,
            discretization_scheme=tc.DiscretizationType.Interpolation,
        ),
    ]
    algo = toppra.algorithm.TOPPRA(constraints, Path(), gridpoints=grid)
    algo.compute_parameterization(0.0, 0.0)
    data = algo.problem_data
    sd = data.sd_vec
    if data.return_code != ParameterizationReturnCode.Ok or sd is None:
        return None
    sd = np.maximum(np.asarray(sd, float), 0.0) / scale
    if not np.all(np.isfinite(sd)) or np.any(sd[1:] + sd[:-1] <= 0):
        return None
    prof = SmoothProfile(curve, grid, sd)
    vel, acc = cell_bounds(curve, grid, sd, prof.u)
    worst = max(float(np.max(vel / v)), math.sqrt(float(np.max(acc / a))))
    prof.c = max(1.0, worst * (1.0 + STRETCH_SLACK))
    return prof


def max_abs_quadratic(a2, a1, a0, h0, h1):
    """max |a2 h² + a1 h + a0| over h ∈ [h0, h1] (elementwise): the ends and the vertex."""

    def f(h):
        return (a2 * h + a1) * h + a0

    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(a2 != 0, -a1 / (2 * a2), h0)
    inside = (vertex > h0) & (vertex < h1)
    ends = np.maximum(np.abs(f(h0)), np.abs(f(h1)))
    return np.where(inside, np.maximum(ends, np.abs(f(np.where(inside, vertex, h0)))), ends)


def cell_bounds(curve, grid: np.ndarray, sd: np.ndarray, u: np.ndarray, split: int = 8):
    """Upper bounds (cells, dof) of |q̇_j| and |q̈_j| over each grid cell [s_i, s_{i+1}].

    In a cell w = ṡ² is linear in s (s̈ = u constant). Each cell is cut into ``split`` equal
    pieces [a, b], inside one cubic piece p_j(h) = c3 h³ + c2 h² + c1 h + c0 of the PCHIP curve
    (h = s − its knot; the grid holds every knot; p'' jumps at knots, so each piece uses its
    own cubic). On [a, b], with w = W0 + 2u h:

        |q̇_j| = |p'_j| ṡ ≤ max |p'_j| · max(ṡ(a), ṡ(b))        (p'_j: a quadratic in h)
        q̈_j = p''_j w + p'_j u = 15 u c3 h² + 6 (c3 W0 + u c2) h + 2 c2 W0 + u c1

    — a quadratic in h, so max |q̈_j| is exact (its ends and its vertex). Finer pieces make the
    velocity bound tighter, never unsafe.
    """
    cells = len(grid) - 1
    frac = np.linspace(0.0, 1.0, split + 1)
    s = grid[:-1, None] + frac[None] * np.diff(grid)[:, None]  # (cells, split + 1)
    w = np.maximum(sd[:-1, None] ** 2 + 2 * u[:, None] * (s - grid[:-1, None]), 0.0)
    cell_piece = np.searchsorted(curve.x, grid[:-1], side="right") - 1
    piece = np.repeat(np.clip(cell_piece, 0, len(curve.x) - 2), split)
    c3, c2, c1 = curve.c[0, piece], curve.c[1, piece], curve.c[2, piece]  # (cells·split, dof)
    h0 = (s[:, :-1].ravel() - curve.x[piece])[:, None]
    h1 = (s[:, 1:].ravel() - curve.x[piece])[:, None]
    uu = np.repeat(u, split)[:, None]
    w0 = w[:, :-1].ravel()[:, None] - 2 * uu * h0  # W0: w = W0 + 2u h on the piece
    top = np.sqrt(np.maximum(w[:, :-1], w[:, 1:]).ravel())[:, None]
    vel = max_abs_quadratic(3 * c3, 2 * c2, c1, h0, h1) * top
    acc = max_abs_quadratic(15 * uu * c3, 6 * (c3 * w0 + uu * c2), 2 * c2 * w0 + uu * c1, h0, h1)
    dof = c1.shape[1]
    return vel.reshape(cells, split, dof).max(1), acc.reshape(cells, split, dof).max(1)


__all__ = [
    "BEFORE_KNOT",
    "GRID_PER_SEGMENT",
    "MAX_GRID",
    "STRETCH_SLACK",
    "cell_bounds",
    "chord_knots",
    "max_abs_quadratic",
    "pchip_curve",
    "time_scale",
    "toppra_profile",
]
