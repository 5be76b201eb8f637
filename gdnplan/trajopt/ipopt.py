"""The Ipopt solver: the straight line when it is certified free, else one seed per attempt
(RRT-Connect or a perturbed straight line), each solved, certified and refined in rounds
(:func:`_solve_refined`)."""

from __future__ import annotations

import logging
import time
from dataclasses import replace

import numpy as np

from ..casadi_bridge import supports_per_link
from ..ccd import certify_path
from ..distance import signed_distance
from ..models import CoalModel, DistanceModel
from ..rrt import seed_path
from .check_points import (
    _check_point_raise,
    _near_segments,
    constraint_margin,
    model_overestimate,
    straight_line,
)
from .options import IPOPT_INTERPOLATED, TrajoptOptions, _count, _interpolated
from .problem import Problem
from .result import _Run
from .transcription import _Transcription

log = logging.getLogger("gdnplan.trajopt")  # one logger for the package: the stage lines

SOLVER_ERRORS = {"Invalid_Number_Detected", "Unrecoverable_Exception", "Internal_Error"}


def _seeds(problem: Problem, goal: np.ndarray, opts: TrajoptOptions, seed: int):
    """Yield (label, initial guess (T, dof) or None when RRT-Connect failed) per attempt."""
    line = straight_line(problem.start, goal, problem.waypoints)
    use_line = opts.initial == "straight"
    rng = np.random.default_rng(seed)
    # seed edges must clear margin + rrt_clearance, but never more than the ends allow
    ends = float(np.min(signed_distance(problem.scene, np.stack([problem.start, goal]))))
    clearance = problem.margin + min(opts.rrt_clearance, (ends - problem.margin) / 2)
    for attempt in range(opts.starts):
        if use_line:
            guess = line.copy()
            if attempt:  # restarts perturb the interior waypoints by N(0, 0.2 rad)
                guess[1:-1] += rng.normal(0, 0.2, guess[1:-1].shape)
                guess = np.clip(guess, problem.lower, problem.upper)
            yield "straight line" + (f" (perturbed {attempt})" if attempt else ""), guess
            continue
        label = f"RRT-Connect seed {seed + attempt}"
        t0 = time.perf_counter()
        for demand in dict.fromkeys((clearance, problem.margin)):  # narrow passage: margin only
            guess, _ = seed_path(
                problem.scene,
                problem.start,
                goal,
                problem.waypoints,
                demand,
                seed=seed + attempt,
                time_limit=opts.rrt_time,
                step=opts.rrt_step,
            )
            if guess is not None:
                break
        found = "path found" if guess is not None else "no path"
        log.info("seed: %s: %s, %.2f s", label, found, time.perf_counter() - t0)
        yield label + (" (clearance = margin)" if demand < clearance else ""), guess


def _line_free(problem: Problem, line: np.ndarray) -> bool:
    """The straight line (T, dof) respects the step bound and is certified at the margin."""
    if np.max(np.abs(np.diff(line, axis=0))) > problem.max_step:
        return False
    return certify_path(problem.scene, line, problem.margin, tol=np.inf, stop_early=True).ok


def _plan_ipopt(problem: Problem, model: DistanceModel, goal: np.ndarray, opts, seed: int) -> _Run:
    """Straight line when certified free, else Ipopt from one seed per attempt.

    An attempt that ends uncertified suggests check points too sparse for the problem, so
    attempt a (0-based) starts with ``interpolated + a`` check points per segment: on one (d)
    problem (#14, two torch threads) all three attempts with 2 check points ended uncertified
    (the path slipped through an obstacle between them), a second attempt with 3 succeeded.
    """
    first = _interpolated(opts, IPOPT_INTERPOLATED)  # bad input fails even on a free line
    if opts.raise_window is not None:
        _count(opts.raise_window, "raise_window")
    line = straight_line(problem.start, goal, problem.waypoints)
    if opts.initial == "auto" and _line_free(problem, line):
        status = "straight line certified free (optimal path cost, no solve needed)"
        log.info("seed: %s", status)
        return _Run(q=line, status=status, reason=status)
    run = _Run(q=line)
    for attempt, (label, guess) in enumerate(_seeds(problem, goal, opts, seed)):
        run.attempts += 1
        if guess is None:
            run.reason = f"{run.reason}; {label}: RRT-Connect found no path".lstrip("; ")
            continue
        if attempt:
            label = f"{label}, {first + attempt} check points per segment"
        attempt_opts = replace(opts, interpolated=first + attempt)
        q, stats, ok = _solve_refined(problem, model, goal, attempt_opts, guess, run)
        run.q, run.status = q, stats.get("return_status", "exception")
        if ok:
            run.reason = f"{label}: {run.status}"
            break
        run.reason = f"{run.reason}; {label}: {run.status}, path not certified".lstrip("; ")
    return run


def _solve_refined(problem: Problem, model, goal, opts, guess: np.ndarray, run: _Run):
    """Solve, certify, refine, re-solve: (q, last stats, certified).

    The check points demand d ≥ :func:`constraint_margin` (the margin, or the certified
    clearance + ``opts.clearance_buffer`` if that is more); the certificate must prove
    d > ``problem.certified_clearance`` on the whole continuous path.
    Each round that the coal certificate rejects doubles the check points of the rejected
    segments and, for a learned model, raises the constraint margin to the model's observed
    overestimate there (:func:`model_overestimate`) on the rejected segments and
    ``opts.raise_window`` segments either side: the learned constraint then keeps the path
    away from the contact coal found, whatever the model's error. (On the rejected segments
    alone, the contact moved to the neighbouring segments of the (d) problems and 2 of 6
    needed a second seed; on the whole path, a narrow passage elsewhere closed: the fetch
    bring-out's entrance.)
    With ``warm_start`` a refine round starts from the last round's multipliers
    (:meth:`_Transcription.duals_on`): on three (d) problems with one-way GraphDistNet weights
    the second rounds took 36, 61 and 13 Ipopt iterations instead of 53, 130 and 85.
    """
    splits = np.full(problem.waypoints - 1, opts.interpolated + 1)  # set by _plan_ipopt
    per_link = supports_per_link(model) if opts.per_link is None else opts.per_link
    learned = not isinstance(model, CoalModel)
    base = constraint_margin(problem, opts.clearance_buffer)  # above the certified clearance
    margin = base + (opts.learned_margin if learned else 0.0)
    raised = np.zeros(len(splits))  # margin raise of each segment (m)
    q, duals = guess, None
    for round_ in range(1 + (opts.refine_rounds if opts.ccd else 0)):
        t0 = time.perf_counter()
        nlp = _Transcription(
            problem,
            model,
            goal,
            replace(opts, per_link=per_link),
            splits,
            margin + _check_point_raise(splits, raised),
            duals is not None,
        )
        q, stats = nlp.solve(q, duals)
        run.iterations += stats.get("iter_count", 0)
        run.model_calls += nlp.callback.model_calls
        status = stats["return_status"]
        took, its = time.perf_counter() - t0, stats.get("iter_count", 0)
        log.info("solve: Ipopt round %d: %s, %d iterations, %.2f s", round_ + 1, status, its, took)
        if status in SOLVER_ERRORS or status.startswith("exception"):
            run.verified = None  # q is not a solver iterate: never accept it
            return q, stats, False
        cert = certify_path(problem.scene, q, margin=problem.certified_clearance)
        run.verified = cert
        if cert.ok:
            return q, stats, True
        bad = list(cert.bad_segments)
        log.info("certify: %d segment(s) not proven clear (more check points there)", len(bad))
        refined = splits.copy()
        refined[bad] *= 2
        duals = nlp.duals_on(refined) if opts.warm_start else None
        splits = refined
        if learned:
            over = model_overestimate(problem.scene, model, q, bad, base)
            near = _near_segments(bad, len(splits), opts.raise_window)  # active rows sit at
            raised[near] = np.maximum(raised[near], over)  # d̂ = bound: raise to the error, no sum
    return q, stats, False
