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
    points (:data:`~gdnplan.timing_toppra.GRID_PER_SEGMENT` per segment, plus one just before
    every waypoint, where p'' jumps); the time axis is then stretched by c ≥ 1 so that proven
    bounds of |q̇_j| and |q̈_j| over every grid cell (:func:`~gdnplan.timing_toppra.cell_bounds`)
    hold with ``STRETCH_SLACK`` to spare (velocities scale by 1/c, accelerations by 1/c²).
    The curve leaves the polygon, so it gets its own certificate (:mod:`gdnplan.ccd_curve`).
``stop`` (acceleration limits, no scene, the smooth curve not certified or not representable:
    a waypoint step too short for float64 cubics, ≲ 1e-154 rad): the exact polygon,
    at rest at every waypoint, each segment the time-optimal trapezoidal (or triangular) profile
    of σ ∈ [0, 1] under σ̇ ≤ min_j v_j / |Δq_j| and |σ̈| ≤ min_j a_j / |Δq_j|. A polygon
    with corners cannot be followed exactly at bounded acceleration without stopping at them.

The curve certificate (:mod:`gdnplan.ccd_curve`) is the planner's (bound (1) of
:mod:`gdnplan.ccd`, or of :mod:`gdnplan.arm3d.ccd3d` for a 3-D scene, self-collision included)
with each joint's straight travel |Δq_j| replaced by the cubic's exact total variation over the
piece. Velocity limits default to the URDF's (Pinocchio's ``model.velocityLimit``), planar and
3-D robots alike.

Modules: the input checks (limits, waypoints, URDF velocities) in :mod:`gdnplan.timing_checks`,
the three profiles' q(t) in :mod:`gdnplan.timing_profiles`, toppra and the cell bounds of
``smooth`` in :mod:`gdnplan.timing_toppra`; this module re-exports the checks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .arm3d.scene3d import Scene3D
from .ccd_curve import certify_curve
from .errors import InputError
from .limits import MAX_TIMED_SAMPLES, check_number
from .scene import Scene
from .timing_checks import (
    LIMIT_RANGE,
    MAX_ANGLE,
    check_scene_dof,
    check_waypoints,
    limit_vector,
    urdf_velocity,
)
from .timing_profiles import LinearProfile, StopProfile
from .timing_toppra import cell_bounds, chord_knots, pchip_curve, toppra_profile

KINDS = ("linear", "smooth", "stop")


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
            ``Scene`` or a ``Scene3D``); None (or a curve whose certificate fails, toppra
            finding no solution, or a waypoint step too short for a float64 cubic,
            :func:`~gdnplan.timing_toppra.pchip_curve`): ``stop``.
        clearance: the ``smooth`` curve must be proven to keep the exact distance above this
            (m, finite, ≥ 0): the certified plan's clearance, so that the curve the robot
            follows keeps what the plan promised; else ``stop`` (the certified polygon).
    """
    check_number(clearance, "clearance")
    q = check_waypoints(q)
    if scene is not None:
        check_scene_dof(scene, q.shape[1])
    v = limit_vector(max_velocity, q.shape[1], "max_velocity", "rad/s")
    if max_acceleration is None:
        prof = LinearProfile(q, v)
        return TimedTrajectory("linear", prof.times, q, v, None, None, prof)
    a = limit_vector(max_acceleration, q.shape[1], "max_acceleration", "rad/s²")
    knots, index = chord_knots(q)
    curve = None if scene is None else pchip_curve(knots, q[np.unique(index, return_index=True)[1]])
    if curve is not None:
        cert = certify_curve(scene, curve, margin=clearance)
        prof = toppra_profile(curve, knots, v, a) if cert.ok else None
        if prof is not None and math.isfinite(prof.c * prof.ts[-1]):
            at_knots = prof.c * prof.ts[np.searchsorted(prof.grid, knots)]
            times = at_knots[index]
            return TimedTrajectory("smooth", times, q, v, a, cert.lower_bound, prof)
    prof = StopProfile(q, v, a)
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


__all__ = [  # re-exported too: timing_checks (LIMIT_RANGE … urdf_velocity), cell_bounds
    "LIMIT_RANGE",
    "MAX_ANGLE",
    "TimedTrajectory",
    "cell_bounds",
    "check_waypoints",
    "limit_vector",
    "plan_timing",
    "time_path",
    "urdf_velocity",
]
