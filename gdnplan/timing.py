"""Time parametrisation of a certified joint path under velocity and acceleration limits.

The planner certifies the piecewise-linear path through its waypoints q_0 … q_{T−1} (rad)
(:func:`gdnplan.ccd.certify_path`; 3-D: :func:`gdnplan.arm3d.certify_path3d`).
:func:`time_path` gives it times 0 = t_0 ≤ … ≤ t_{T−1} (s) in one of three ways, each of them
along a path that is certified collision-free:

``linear`` (velocity limits v only, the default): the exact waypoint polygon at constant speed,
    segment k taking τ_k = max_j |Δq_{k,j}| / v_j. The fastest motion along the polygon under
    |q̇_j| ≤ v_j; the velocity jumps at the waypoints (unbounded acceleration there).
``smooth`` (acceleration limits a given, and a scene): the shape-preserving cubic (PCHIP) p(s)
    through the waypoints, s the cumulative chord length (rad), time-parametrised by toppra
    (time-optimal, reachability analysis) under |p'_j(s) ṡ| ≤ v_j and
    |p''_j(s) ṡ² + p'_j(s) s̈| ≤ a_j, at rest at both ends. toppra enforces the limits at its grid
    points (:data:`GRID_PER_SEGMENT` per segment, plus one just before every waypoint, where p''
    jumps); the time axis is then stretched by c ≥ 1 so that proven bounds of |q̇_j| and |q̈_j|
    over every grid cell (:func:`cell_bounds`) hold with ``STRETCH_SLACK`` to spare
    (velocities scale by 1/c, accelerations by 1/c²).
    The curve leaves the polygon, so it gets its own certificate (:mod:`gdnplan.ccd_curve`).
``stop`` (acceleration limits, no scene or the smooth curve not certified): the exact polygon,
    at rest at every waypoint, each segment the time-optimal trapezoidal (or triangular) profile
    of σ ∈ [0, 1] under σ̇ ≤ min_j v_j / |Δq_j| and |σ̈| ≤ min_j a_j / |Δq_j|. A polygon
    with corners cannot be followed exactly at bounded acceleration without stopping at them.

The curve certificate (:mod:`gdnplan.ccd_curve`) is the planner's (bound (1) of
:mod:`gdnplan.ccd`, or of :mod:`gdnplan.arm3d.ccd3d` for a 3-D scene, self-collision included)
with each joint's straight travel |Δq_j| replaced by the cubic's exact total variation over the
piece. Velocity limits default to the URDF's (Pinocchio's ``model.velocityLimit``), planar and
3-D robots alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .arm3d.robot3d import Robot3D
from .arm3d.scene3d import Scene3D
from .ccd_curve import certify_curve
from .errors import InputError
from .limits import MAX_TIMED_SAMPLES, check_number, is_number
from .robot import Robot
from .scene import Scene

GRID_PER_SEGMENT = 8  # toppra grid cells per waypoint segment (fewer above MAX_GRID)
MAX_GRID = 4000  # toppra grid points at most
BEFORE_KNOT = (1e-6, 1e-3, 1e-2, 0.0)  # grid points this share of a segment before inner knots
STRETCH_SLACK = 1e-9  # c is raised by this fraction (rounding of the cell bounds)
LIMIT_RANGE = (1e-6, 1e9)  # max_velocity (rad/s) and max_acceleration (rad/s²) allowed
MAX_ANGLE = 1e6  # rad, |q| of a waypoint: beyond it the times' squares could overflow
KINDS = ("linear", "smooth", "stop")


def limit_vector(value, dof: int, name: str, unit: str) -> np.ndarray:
    """(dof,) limits from one number or dof numbers, each in :data:`LIMIT_RANGE` (10⁻⁶ … 10⁹
    ``unit``; beyond it a path's times or their squares leave float64), else InputError."""
    if is_number(value):
        value = [value] * dof
    items = list(value) if isinstance(value, (list, tuple, np.ndarray)) else None
    if items is None or len(items) != dof or not all(is_number(x) for x in items):
        raise InputError(f"{name}: expected a number or {dof} numbers ({unit}), got {value!r}")
    out = np.asarray(items, float)
    if not np.all(np.isfinite(out) & (out > 0)):
        raise InputError(f"{name}: expected finite limits > 0 ({unit}), got {out.tolist()}")
    low, high = LIMIT_RANGE
    if not np.all((out >= low) & (out <= high)):
        raise InputError(
            f"{name}: expected limits in [{low:g}, {high:g}] {unit}, got {out.tolist()}"
        )
    return out


def check_waypoints(q) -> np.ndarray:
    """q as float64 (T, dof) waypoints, T ≥ 1, dof ≥ 1, real and finite with |q| ≤
    :data:`MAX_ANGLE` rad, else InputError naming ``q``."""
    try:
        arr = np.asarray(q)
    except (TypeError, ValueError) as e:
        raise InputError(f"q: expected (T, dof) waypoints (rad), got {type(q).__name__}") from e
    if arr.dtype.kind not in "iuf":
        raise InputError(f"q: expected real numbers (rad), got an array of {arr.dtype}")
    if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise InputError(f"q: expected (T, dof) waypoints with T, dof ≥ 1, got shape {arr.shape}")
    arr = arr.astype(float)
    if not np.all(np.isfinite(arr)):
        raise InputError(f"q: expected finite (T, dof) waypoints (rad), got shape {arr.shape}")
    if np.max(np.abs(arr)) > MAX_ANGLE:
        raise InputError(f"q: waypoints beyond ±{MAX_ANGLE:g} rad are no joint angles")
    return arr


def urdf_velocity(robot: Robot | Robot3D) -> np.ndarray:
    """(dof,) velocity limits of the robot's URDF (rad/s); InputError naming the first joint
    whose limit is missing (URDF velocity="0"; a continuous joint without <limit> gives inf)."""
    v = np.asarray(robot.model.velocityLimit, float)
    bad = np.flatnonzero(~(np.isfinite(v) & (v > 0)))
    if len(bad):
        j = int(bad[0])
        raise InputError(
            f"max_velocity: joint {robot.joint_names[j]!r} of robot {robot.name!r} has velocity "
            f"limit {v[j]:g} in its URDF; set <limit velocity=...> (rad/s) there or pass "
            "max_velocity"
        )
    return v


@dataclass(frozen=True, eq=False)
class TimedTrajectory:
    """A path q(t), t ∈ [0, duration] (s), through the waypoints at ``times``; see the module.

    Attributes:
        kind: "linear", "smooth" or "stop" (the module docstring says which path each follows).
        times: (T,) time of each waypoint (s), times[0] = 0, non-decreasing.
        waypoints: (T, dof) the waypoints (rad).
        max_velocity: (dof,) velocity limits (rad/s).
        max_acceleration: (dof,) acceleration limits (rad/s²), None for ``linear``.
        min_distance: ``smooth``: proven lower bound on the coal distance along the curve (m);
            None: the path is the waypoint polygon, whose certificate the planner made.
    """

    kind: str
    times: np.ndarray
    waypoints: np.ndarray
    max_velocity: np.ndarray
    max_acceleration: np.ndarray | None
    min_distance: float | None = None
    _profile: object = field(default=None, repr=False)

    @property
    def duration(self) -> float:
        """Total time (s)."""
        return float(self.times[-1])

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q (N, dof) rad, q̇ rad/s, q̈ rad/s² at times t (N,) s, clipped to [0, duration].

        ``linear``: q̇ is the velocity of the segment t lies in (0 at the end), q̈ = 0 (the
        velocity jumps at waypoints). ``stop``/``smooth``: q̈ is the one-sided value at the
        switching times of the profile.
        """
        t = np.atleast_1d(np.asarray(t, float))
        if t.ndim != 1 or not np.all(np.isfinite(t)):
            raise InputError("t: expected finite times (s) in a 1-D array")
        return self._profile.state(np.clip(t, 0.0, self.duration))

    def sample(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Times (N,) 0, dt, 2 dt, …, duration (s; the last step may be shorter) and q (N, dof).

        ``dt`` must be finite and > 0, and give at most ``MAX_TIMED_SAMPLES`` samples.
        """
        check_number(dt, "dt", strict=True)
        ratio = self.duration / dt
        n = math.floor(ratio) + 2 if ratio < MAX_TIMED_SAMPLES else MAX_TIMED_SAMPLES + 1
        if n > MAX_TIMED_SAMPLES:
            raise InputError(
                f"dt: {dt:g} s gives {n} samples of a {self.duration:.3f} s trajectory, the limit "
                f"is {MAX_TIMED_SAMPLES}; use dt ≥ {self.duration / (MAX_TIMED_SAMPLES - 2):.3g}"
            )
        t = np.arange(n - 1) * float(dt)
        t = np.append(t[t < self.duration - 1e-9 * dt], self.duration)
        return t, self.evaluate(t)[0]


def _segment_of(times: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.clip(np.searchsorted(times, t, side="right") - 1, 0, max(len(times) - 2, 0))


class _Linear:
    def __init__(self, q: np.ndarray, v: np.ndarray):
        self.q, self.step = q, np.diff(q, axis=0)
        tau = np.max(np.abs(self.step) / v, axis=1) if len(q) > 1 else np.zeros(0)
        self.times = np.concatenate([[0.0], np.cumsum(tau)])
        self.tau = tau

    def state(self, t):
        if len(self.q) == 1:
            z = np.zeros((len(t), self.q.shape[1]))
            return self.q[[0] * len(t)], z, z
        k = _segment_of(self.times, t)
        tau = self.tau[k][:, None]
        # divided, not multiplied by 1/τ: a denormal τ (a step of ~1e-300 rad) has no finite
        # reciprocal, while Δq/τ stays within the velocity limit
        elapsed = (t - self.times[k])[:, None]
        with np.errstate(over="ignore"):
            frac = np.divide(elapsed, tau, out=np.zeros_like(elapsed), where=tau > 0)
        frac = np.clip(frac, 0.0, 1.0)
        moving = (tau > 0) & (t < self.times[-1])[:, None]
        qd = np.divide(self.step[k], tau, out=np.zeros_like(self.step[k]), where=moving)
        return self.q[k] + frac * self.step[k], qd, np.zeros_like(qd)


class _Stops:
    """Rest-to-rest trapezoidal profile σ(t) on every segment q_k + σ Δq_k."""

    def __init__(self, q: np.ndarray, v: np.ndarray, a: np.ndarray):
        self.q, self.step = q, np.diff(q, axis=0)
        size = np.abs(self.step)
        with np.errstate(divide="ignore", over="ignore"):  # a tiny step: no motion
            vs = np.min(v / size, axis=1, initial=np.inf) if len(size) else np.zeros(0)
            acc = np.min(a / size, axis=1, initial=np.inf) if len(size) else np.zeros(0)
        moving = np.isfinite(vs)
        vs, acc = np.where(moving, vs, 1.0), np.where(moving, acc, 1.0)
        triangle = vs**2 >= acc
        self.peak = np.where(triangle, np.sqrt(acc), vs)
        self.acc, self.ramp = acc, self.peak / acc
        self.tau = np.where(moving, np.where(triangle, 2 * self.ramp, 1 / vs + vs / acc), 0.0)
        self.times = np.concatenate([[0.0], np.cumsum(self.tau)])

    def state(self, t):
        if len(self.q) == 1:
            z = np.zeros((len(t), self.q.shape[1]))
            return self.q[[0] * len(t)], z, z
        k = _segment_of(self.times, t)
        x = np.clip(t - self.times[k], 0.0, self.tau[k])
        acc, peak, ramp, tau = self.acc[k], self.peak[k], self.ramp[k], self.tau[k]
        rest = tau - x
        up, down = x < ramp, rest < ramp
        sig = np.where(up, 0.5 * acc * x**2, 0.5 * acc * ramp**2 + peak * (x - ramp))
        sig = np.where(down & ~up, 1.0 - 0.5 * acc * rest**2, sig)
        sd = np.where(up, acc * x, np.where(down, acc * rest, peak))
        sdd = np.where(up, acc, np.where(down, -acc, 0.0))
        sig, sd, sdd = (np.where(tau > 0, y, 0.0)[:, None] for y in (sig, sd, sdd))
        return self.q[k] + sig * self.step[k], sd * self.step[k], sdd * self.step[k]


class _Smooth:
    """PCHIP path p(s) with toppra's s(t): ṡ² linear in s on each grid cell, time stretch c."""

    def __init__(self, curve, grid, sd, stretch: float = 1.0):
        self.p, self.dp, self.ddp = curve, curve.derivative(), curve.derivative(2)
        self.grid, self.sd, self.c = grid, sd, stretch
        dg = np.diff(grid)
        self.u = (sd[1:] ** 2 - sd[:-1] ** 2) / (2 * dg)
        self.ts = np.concatenate([[0.0], np.cumsum(2 * dg / (sd[1:] + sd[:-1]))])

    def at_grid(self, cell: np.ndarray, x: np.ndarray):
        """(s, ṡ, s̈) at time x after the start of grid cell ``cell`` (toppra's time)."""
        sd, u = self.sd[cell], self.u[cell]
        s = np.minimum(self.grid[cell] + sd * x + 0.5 * u * x**2, self.grid[cell + 1])
        return s, sd + u * x, u

    def derivatives(self, s, sd, sdd):
        dp = self.dp(s)
        return self.p(s), dp * sd[:, None], self.ddp(s) * (sd**2)[:, None] + dp * sdd[:, None]

    def state(self, t):
        tt = t / self.c
        cell = _segment_of(self.ts, tt)
        q, qd, qdd = self.derivatives(*self.at_grid(cell, tt - self.ts[cell]))
        return q, qd / self.c, qdd / self.c**2


def _chord_knots(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cumulative chord length of the distinct waypoints (K,) and each waypoint's knot (T,)."""
    keep = np.concatenate([[True], np.any(np.diff(q, axis=0) != 0, axis=1)])
    index = np.cumsum(keep) - 1
    distinct = q[keep]
    knots = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(distinct, axis=0), axis=1))])
    return knots, index


def _toppra(curve, knots: np.ndarray, v: np.ndarray, a: np.ndarray) -> _Smooth | None:
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
    segments = len(knots) - 1
    m = max(2, min(GRID_PER_SEGMENT, MAX_GRID // (2 * segments)))
    cells = np.linspace(0.0, 1.0, m + 1)[:-1]
    cells = (knots[:-1, None] + cells[None] * np.diff(knots)[:, None]).ravel()
    for offset in BEFORE_KNOT:  # the closest first; toppra may call a grid uncontrollable
        before = knots[1:-1] - offset * np.diff(knots)[:-1]  # p'' jumps at every knot
        grid = np.unique(np.concatenate([cells, before if offset else [], knots[-1:]]))
        prof = _toppra_on_grid(curve, knots, grid, v, a)
        if prof is not None:
            return prof
    return None


def _toppra_on_grid(curve, knots, grid, v, a) -> _Smooth | None:
    """toppra on one grid (None when it finds no parametrisation); the time stretch c makes
    the limits hold on every cell whatever the grid (:func:`cell_bounds`)."""
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
        tc.JointVelocityConstraint(np.column_stack([-v, v])),
        tc.JointAccelerationConstraint(
            np.column_stack([-a, a]), discretization_scheme=tc.DiscretizationType.Interpolation
        ),
    ]
    algo = toppra.algorithm.TOPPRA(constraints, Path(), gridpoints=grid)
    algo.compute_parameterization(0.0, 0.0)
    data = algo.problem_data
    sd = data.sd_vec
    if data.return_code != ParameterizationReturnCode.Ok or sd is None:
        return None
    sd = np.maximum(np.asarray(sd, float), 0.0)
    if not np.all(np.isfinite(sd)) or np.any(sd[1:] + sd[:-1] <= 0):
        return None
    prof = _Smooth(curve, grid, sd)
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


def time_path(
    q: np.ndarray,
    max_velocity,
    max_acceleration=None,
    scene: Scene | Scene3D | None = None,
    clearance: float = 0.0,
) -> TimedTrajectory:
    """Time-parametrise the certified waypoint path q (T, dof) rad; see the module docstring.

    Args:
        q: (T, dof) finite waypoints (rad), T ≥ 1, dof ≥ 1, |q| ≤ :data:`MAX_ANGLE`.
        max_velocity: velocity limit (rad/s), one number or dof numbers, each in
            :data:`LIMIT_RANGE` (10⁻⁶ … 10⁹), so the duration and every time stay finite.
        max_acceleration: acceleration limit (rad/s²) likewise; None: ``linear``.
        scene: with max_acceleration, try the ``smooth`` curve and certify it here (a planar
            ``Scene`` or a ``Scene3D``); None (or a curve whose certificate fails, or toppra
            finding no solution): ``stop``.
        clearance: the ``smooth`` curve must be proven to keep the exact distance above this
            (m, finite, ≥ 0): the certified plan's clearance, so that the curve the robot
            follows keeps what the plan promised; else ``stop`` (the certified polygon).
    """
    check_number(clearance, "clearance")
    q = check_waypoints(q)
    v = limit_vector(max_velocity, q.shape[1], "max_velocity", "rad/s")
    if max_acceleration is None:
        prof = _Linear(q, v)
        return TimedTrajectory("linear", prof.times, q, v, None, None, prof)
    a = limit_vector(max_acceleration, q.shape[1], "max_acceleration", "rad/s²")
    knots, index = _chord_knots(q)
    if scene is not None and len(knots) > 1:
        # imported here: a slow import (docs/decisions.md#lazy-imports)
        from scipy.interpolate import PchipInterpolator

        curve = PchipInterpolator(knots, q[np.unique(index, return_index=True)[1]], axis=0)
        cert = certify_curve(scene, curve, margin=clearance)
        prof = _toppra(curve, knots, v, a) if cert.ok else None
        if prof is not None and math.isfinite(prof.c * prof.ts[-1]):
            at_knots = prof.c * prof.ts[np.searchsorted(prof.grid, knots)]
            times = at_knots[index]
            return TimedTrajectory("smooth", times, q, v, a, cert.lower_bound, prof)
    prof = _Stops(q, v, a)
    return TimedTrajectory("stop", prof.times, q, v, a, None, prof)


def plan_timing(
    scene: Scene | Scene3D,
    q: np.ndarray,
    success: bool,
    max_velocity=None,
    max_acceleration=None,
    clearance: float = 0.0,
) -> tuple[TimedTrajectory | None, str]:
    """The timing of a plan's path q (T, dof) and a note on why there is none ("" if there is).

    None for a failed plan, and for a robot whose URDF lacks velocity limits when no
    ``max_velocity`` is given (the note says which joint). ``max_acceleration`` selects the
    ``smooth`` curve certified in ``scene`` (or ``stop``), see :func:`time_path`, for planar
    and 3-D scenes alike (:mod:`gdnplan.ccd_curve` certifies the curve with the scene kind's
    exact distance and motion bound; in 3-D self-collision included) to keep ``clearance``
    (m): the plan's certified clearance.
    """
    if not success:
        return None, ""
    try:
        v = urdf_velocity(scene.robot) if max_velocity is None else max_velocity
    except InputError as e:
        return None, f"no timing: {e}"
    curve_scene = scene if max_acceleration is not None else None
    return time_path(q, v, max_acceleration, curve_scene, clearance), ""


__all__ = [
    "TimedTrajectory",
    "limit_vector",
    "plan_timing",
    "time_path",
    "urdf_velocity",
]
