"""What a plan hands back: :class:`Plan`, the path cost, and the final coal certificate
that judges a solver's path (:func:`_finish`)."""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from ..ccd import Certificate
from ..errors import InputError
from ..exact import certify
from ..limits import floor_text
from ..timing import TimedTrajectory
from .ik import tip_position
from .problem import Problem
from .seeds import SeedInfo

log = logging.getLogger("gdnplan.trajopt")  # one logger for the package: the stage lines

STEP_TOL = 1e-6  # rad: a path keeps max_step and the joint limits within this (Ipopt's
# interior point ends a hair outside a bound: it relaxes bounds by 1e-8 of their size)
IPOPT_SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


@dataclass(frozen=True, eq=False)
class Plan:
    """Result of :func:`plan`.

    Attributes:
        success: the goal is reached, the coal certificate proves that the whole continuous
            path keeps a signed distance > ``clearance`` (the problem's certified clearance:
            its margin unless ``Problem.clearance`` asks for less), not only at check points,
            and the path keeps the problem's joint limits and ``max_step`` (within
            :data:`STEP_TOL`, :func:`path_violation`), whatever the solver's status said.
        q: (T, dof) waypoints (rad).
        min_distance: proven lower bound on the coal signed distance over the whole continuous
            path (m; the certificate of :func:`gdnplan.ccd.certify_path`, within 1 mm of the
            path's true minimum); −inf when the certificate could not prove the path free.
            3-D: the bound of obstacle and ordinary self pairs; a contact-only self pair is
            only proven ≥ min_distance − clearance (:mod:`gdnplan.arm3d.ccd3d`: the shipped
            UR5e's forearm–wrist pairs stay closer than any useful margin), so
            ``signed_distance3d``, which counts those pairs too, can be smaller.
        sampled_min_distance: smallest coal distance over the configurations the certificate
            checked (m): an upper bound on the path's minimum (the true minimum lies in
            [min_distance, sampled_min_distance]).
        solve_time: wall time of the whole call: seeds, solves, verification (s); the time
            parametrisation after them is not included.
        iterations: solver iterations summed over attempts.
        status: the solver's last return status (Ipopt's, or "adam: …"); an Ipopt status
            other than Solve_Succeeded / Solved_To_Acceptable_Level on a successful plan is
            explained in ``reason`` (the path passed every check anyway).
        reason: why the plan failed (or which attempt succeeded).
        path_cost: Σ_t ‖q_{t+1} − q_t‖² (rad²).
        model_calls: batched distance-model calls made by the solver.
        attempts: seeds tried (each refined unless its seed kind found no path); 0 when the
            straight line was certified free.
        seed: the seed the returned path was refined from (kind, index among the seeds
            tried, random stream); the straight line's when it was certified free, or for
            Adam; None when no seed's refined path was certified.
        clearance: the clearance the certificate was asked to prove (m,
            ``Problem.certified_clearance``); on success min_distance > clearance.
        trajectory: the time parametrisation of the certified path
            (:class:`~gdnplan.timing.TimedTrajectory`) under the robot's URDF velocity limits (or
            ``plan(max_velocity=…)``) and ``plan(max_acceleration=…)``; None for a failed plan
            and for a robot without velocity limits (``reason`` says which joint).
    """

    success: bool
    q: np.ndarray
    min_distance: float
    solve_time: float
    iterations: int
    status: str
    reason: str
    path_cost: float
    model_calls: int
    attempts: int
    sampled_min_distance: float
    clearance: float = 0.0
    trajectory: TimedTrajectory | None = None
    seed: SeedInfo | None = None

    @property
    def times(self) -> np.ndarray | None:
        """(T,) time of each waypoint of q (s), 0 first; None without a trajectory."""
        return None if self.trajectory is None else self.trajectory.times

    @property
    def duration(self) -> float | None:
        """Duration of the trajectory (s); None without one."""
        return None if self.trajectory is None else self.trajectory.duration

    def sample(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Times (N,) 0, dt, …, duration (s) and configurations q (N, dof) rad on the
        trajectory (:meth:`gdnplan.timing.TimedTrajectory.sample`)."""
        if self.trajectory is None:
            raise InputError(
                "sample: this plan has no trajectory (it failed, or the robot has no velocity "
                "limits: see its reason)"
            )
        return self.trajectory.sample(dt)


def path_cost(q: np.ndarray) -> float:
    """Σ_t ‖q_{t+1} − q_t‖² of a (T, dof) path (rad²)."""
    return float(np.sum(np.diff(q, axis=0) ** 2))


@dataclass
class _Run:
    """What a solver hands back before verification."""

    q: np.ndarray
    iterations: int = 0
    status: str = ""
    reason: str = ""
    model_calls: int = 0
    attempts: int = 0
    verified: Certificate | None = None  # q's certificate at the certified clearance, if made
    violation: str | None = None  # the constraint q breaks (path_violation), when checked
    seed: SeedInfo | None = None  # the seed q was refined from, when certified
    exact: np.ndarray | None = None  # (T − 1,) segments whose check points q's solve gave coal rows


def path_violation(problem: Problem, q: np.ndarray) -> str | None:
    """Which constraint of ``problem`` other than clearance and goal the path q (T, dof)
    breaks, beyond :data:`STEP_TOL`: finite values, the fixed start, the joint limits
    (``lower``/``upper``) and ``max_step``; None when it keeps them all."""
    if not np.all(np.isfinite(q)):
        return "the path holds NaN or infinite joint values"
    if np.max(np.abs(q[0] - problem.start)) > STEP_TOL:
        return "the path does not begin at start.q"
    below, above = problem.lower - q, q - problem.upper
    for name, excess in (("options.lower", below), ("options.upper", above)):
        if np.max(excess) > STEP_TOL:
            t, j = np.unravel_index(np.argmax(excess), excess.shape)
            return (
                f"{name}: waypoint {t} has joint {j} = {q[t, j]:.6g} rad, "
                f"{excess[t, j]:.3g} rad beyond the limit (tolerance {STEP_TOL:g} rad)"
            )
    steps = np.abs(np.diff(q, axis=0))
    if np.max(steps) > problem.max_step + STEP_TOL:
        t, j = np.unravel_index(np.argmax(steps), steps.shape)
        return (
            f"options.max_step: joint {j} moves {steps[t, j]:.6g} rad between waypoints {t} and "
            f"{t + 1}, over max_step = {problem.max_step:g} rad (tolerance {STEP_TOL:g} rad)"
        )
    return None


def _finish(problem: Problem, run: _Run, t0: float) -> Plan:
    """Certify the path with coal, check the goal and every other constraint of the problem
    (:func:`path_violation`), package the Plan: ``success`` only when all hold, else
    ``reason`` names the first that failed."""
    clearance = problem.certified_clearance
    broken = path_violation(problem, run.q)
    finite = broken is None or np.all(np.isfinite(run.q))
    cert = None
    if finite:
        cert = run.verified or certify(problem.scene, run.q, margin=clearance)
    reached = finite and _goal_error(problem, run.q[-1]) <= problem.goal_tolerance
    reason = run.reason
    if cert is None:
        reason = f"{reason}; {broken}"
    elif not cert.ok:
        reason = (
            f"{reason}; coal certificate of clearance > {clearance:g} m failed: {cert.reason} "
            f"(smallest checked distance {cert.min_distance:+.4f} m)"
        )
    elif not reached:
        reason = f"{reason}; goal not reached"
    elif broken is not None:
        reason = f"{reason}; {broken}"
    success = bool(cert is not None and cert.ok and reached and broken is None)
    if success and _is_ipopt_failure(run.status):
        reason = (
            f"{reason}; Ipopt did not report success ({run.status}), but its path was checked "
            "and keeps every constraint (certified clearance, goal, joint limits, max_step)"
        )
    ok = cert is not None and cert.ok
    verdict = f"ok, clearance ≥ {floor_text(cert.lower_bound)} m" if ok else "not proven"
    why = "" if not ok or success else ("; goal not reached" if not reached else f"; {broken}")
    log.info("certify: coal certificate %s%s", verdict, why)
    return Plan(
        success=success,
        q=run.q,
        min_distance=-np.inf if cert is None else cert.lower_bound,
        solve_time=time.perf_counter() - t0,
        iterations=run.iterations,
        status=run.status,
        reason=reason.lstrip("; "),
        path_cost=path_cost(run.q) if finite else np.inf,
        model_calls=run.model_calls,
        attempts=run.attempts,
        sampled_min_distance=-np.inf if cert is None else cert.min_distance,
        clearance=clearance,
        seed=run.seed,
    )


def _is_ipopt_failure(status: str) -> bool:
    """An Ipopt return status (one word, e.g. Infeasible_Problem_Detected) other than
    :data:`IPOPT_SUCCESS`; gdnplan's own statuses ("adam: …", "straight line …") are not."""
    return bool(status) and " " not in status and status not in IPOPT_SUCCESS


def _goal_error(problem: Problem, q: np.ndarray) -> float:
    """Joint-space (rad, ∞-norm) or end-effector (m) distance of q to the goal."""
    if problem.goal is not None:
        return float(np.max(np.abs(q - problem.goal)))
    return float(np.linalg.norm(tip_position(problem.scene.robot, q)[0] - problem.goal_position))
