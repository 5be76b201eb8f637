"""The Ipopt optimiser: the straight line when it is certified free, else seed paths
(:mod:`gdnplan.trajopt.seeds`), each solved, certified and refined in rounds
(:func:`_solve_refined`); the certified path of least path cost is returned."""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, replace

import numpy as np

from ..casadi_bridge import supports_per_link
from ..exact import certify, exact_distance
from ..limits import MAX_SEEDS
from ..models import DistanceModel
from .check_points import (
    _check_point_raise,
    _near_segments,
    constraint_margin,
    is_exact,
    model_overestimate,
    straight_line,
)
from .config import PlanConfig, more_check_points
from .problem import Problem
from .refine import underestimated_segments, with_exact_rows
from .result import _Run, path_cost, path_violation
from .seeds import SeedInfo, draw_seed
from .transcription import _Transcription

log = logging.getLogger("gdnplan.trajopt")  # one logger for the package: the stage lines

# statuses whose x is no solver iterate (or none of this problem): never accepted
SOLVER_ERRORS = {
    "Invalid_Number_Detected",
    "Unrecoverable_Exception",
    "Internal_Error",
    "NonIpopt_Exception_Thrown",
    "Insufficient_Memory",
    "Invalid_Option",
    "Invalid_Problem_Definition",
}


def _line_free(problem: Problem, line: np.ndarray) -> bool:
    """The straight line (T, dof) respects the step bound and is certified at the margin."""
    if np.max(np.abs(np.diff(line, axis=0))) > problem.max_step:
        return False
    return certify(problem.scene, line, problem.margin, tol=np.inf, stop_early=True).ok


def _seed_clearance(problem: Problem, goal: np.ndarray, extra: float) -> float:
    """Seed edges clear margin + extra, but never more than half the ends' own spare room."""
    ends = float(np.min(exact_distance(problem.scene, np.stack([problem.start, goal]))))
    return problem.margin + min(extra, (ends - problem.margin) / 2)


@dataclass
class _Best:
    """The certified path of least path cost so far."""

    q: np.ndarray | None = None
    cost: float = math.inf
    label: str = ""
    status: str = ""
    info: SeedInfo | None = None
    cert: object = None
    exact: np.ndarray | None = None
    certified: int = 0


def _plan_ipopt(
    problem: Problem,
    model: DistanceModel,
    goal: np.ndarray,
    cfg: PlanConfig,
    seed: int,
    deadline: float = math.inf,
) -> _Run:
    """Straight line when certified free, else Ipopt from each seed; the cheapest certified.

    Seeds i = 0, 1, … (kind ``kinds[i % len(kinds)]``, stream seed + i) are refined until
    ``seed_count`` are certified, ``starts`` have ended uncertified (without a time budget;
    within one, a failed seed draws the next until the budget ends), or the clock passes
    ``deadline``. An attempt that ends uncertified suggests check points too sparse for the
    problem, so after f such attempts a seed starts with ``interpolated + min(f, starts − 1)``
    check points per segment, at most ``MAX_INTERPOLATED`` (on one (d) problem, #14, all three
    attempts with 2 check points ended uncertified, the path slipping through an obstacle
    between them; with 3 it succeeded).
    """
    sc = cfg.seed
    line = straight_line(problem.start, goal, problem.waypoints)
    if sc.initial == "auto" and _line_free(problem, line):
        status = "straight line certified free (optimal path cost, no solve needed)"
        log.info("seed: %s", status)
        return _Run(q=line, status=status, reason=status, seed=SeedInfo("straight", 0, seed))
    clearance = _seed_clearance(problem, goal, sc.rrt_clearance)
    run, best, failures = _Run(q=line), _Best(), 0
    wanted = sc.seed_count
    budgeted = math.isfinite(deadline)
    for index in range(wanted + (MAX_SEEDS if budgeted else sc.starts - 1)):
        if best.certified == wanted or (failures == sc.starts and not budgeted):
            break
        if time.perf_counter() >= deadline:
            run.reason = f"{run.reason}; time budget ended".lstrip("; ")
            break
        kind = "straight" if sc.initial == "straight" else sc.kinds[index % len(sc.kinds)]
        rrt = (sc.rrt_time, sc.rrt_step)
        guess, label = draw_seed(kind, problem, goal, clearance, seed, index, rrt, deadline)
        run.attempts += 1
        if guess is None:
            run.reason = f"{run.reason}; {label}: no seed path".lstrip("; ")
            failures += 1
            continue
        extra = min(failures, sc.starts - 1)
        attempt = replace(cfg, optimizer=more_check_points(cfg.optimizer, extra))
        if extra:
            label = f"{label}, {attempt.optimizer.interpolated} check points per segment"
        run.exact = None  # a new seed path: the last attempt's coal rows say nothing of it
        q, stats, ok = _solve_refined(problem, model, goal, attempt, guess, run, deadline)
        status = stats.get("return_status", "exception")
        if not ok:
            failures += 1
            run.q, run.status = q, status
            why = run.violation or "path not certified"
            run.reason = f"{run.reason}; {label}: {status}, {why}".lstrip("; ")
            continue
        best.certified += 1
        cost = path_cost(q)
        log.info("seed: %s certified, path cost %.4f rad²", label, cost)
        if cost < best.cost:
            info = SeedInfo(kind, index, seed + index)
            best = replace(best, q=q, cost=cost, label=label, status=status, info=info)
            best.cert, best.exact = run.verified, run.exact
    if best.q is not None:
        run.q, run.status, run.verified, run.seed = best.q, best.status, best.cert, best.info
        run.exact = best.exact
        of = f" (least path cost of {best.certified} certified)" if best.certified > 1 else ""
        run.reason = f"{best.label}: {best.status}{of}"
    return run


def _solve_refined(
    problem: Problem,
    model,
    goal,
    cfg: PlanConfig,
    guess: np.ndarray,
    run: _Run,
    deadline: float = math.inf,
):
    """Solve, certify, refine, re-solve: (q, last stats, certified).

    The check points demand d ≥ :func:`constraint_margin` (the margin, or the certified
    clearance + ``clearance_buffer`` if that is more); the certificate must prove
    d > ``problem.certified_clearance`` on the whole continuous path.
    Each round that the coal certificate rejects doubles the check points of the rejected
    segments and, for a learned model, gives the check points of the rejected segments and
    ``raise_window`` segments either side coal rows (``RefineConfig.exact_rows``,
    :mod:`gdnplan.trajopt.refine`), and before the first round so do the segments where the
    model alone violates the bound at ``guess`` (:func:`~.refine.underestimated_segments`)
    and those that had coal rows in the solve that made ``guess`` (``run.exact``: a polish or
    repair starts from a path whose own refine rounds found where the model errs; the final
    mask is left in ``run.exact``);
    without exact rows it raises the constraint margin to the
    model's observed overestimate there (:func:`model_overestimate`) on the rejected segments and
    ``raise_window`` segments either side: the learned constraint then keeps the path away
    from the contact coal found, whatever the model's error (on the rejected segments alone
    the contact moved to the neighbouring segments; on the whole path a narrow passage
    elsewhere closed). With ``warm_start`` a refine round starts from the last round's
    multipliers (:meth:`_Transcription.duals_on`). Before ``deadline`` (a
    :func:`time.perf_counter` value) Ipopt gets the time left as ``max_wall_time``; no round
    starts after it.
    """
    ipopt, refine = cfg.optimizer, cfg.refine
    splits = np.full(problem.waypoints - 1, ipopt.interpolated + 1)
    per_link = supports_per_link(model) if ipopt.per_link is None else ipopt.per_link
    ipopt = replace(ipopt, per_link=per_link)
    learned = not is_exact(model)
    exact_rows = learned and refine.exact_rows and not per_link
    margin = constraint_margin(problem, refine.clearance_buffer)  # above the certified clearance
    raised = np.zeros(len(splits))  # margin raise of each segment (m)
    exact = np.zeros(len(splits), bool)  # segments whose check points have coal rows
    if exact_rows:  # coal rows where the model alone violates the bound (refine.py), and
        exact = underestimated_segments(  # where the solve that made guess had them
            problem.scene, model, guess, splits, margin, refine.raise_window, problem.margin
        )
        if run.exact is not None and len(run.exact) == len(exact):
            exact |= run.exact
    q, duals, stats = guess, None, {"return_status": "time budget ended"}
    for round_ in range(1 + (refine.rounds if refine.ccd else 0)):
        t0 = time.perf_counter()
        if t0 >= deadline:
            break
        if math.isfinite(deadline):
            left = min(max(deadline - t0, 1e-3), ipopt.options.get("max_wall_time", math.inf))
            ipopt = replace(ipopt, options={**ipopt.options, "max_wall_time": left})
        nlp = _Transcription(
            problem, with_exact_rows(model, splits, exact, problem.margin), goal, ipopt, splits,
            margin + _check_point_raise(splits, raised), duals is not None,
        )  # fmt: skip
        q, stats = nlp.solve(q, duals)
        run.iterations += stats.get("iter_count", 0)
        run.model_calls += nlp.callback.model_calls
        status = stats["return_status"]
        took, its = time.perf_counter() - t0, stats.get("iter_count", 0)
        log.info("solve: Ipopt round %d: %s, %d iterations, %.2f s", round_ + 1, status, its, took)
        run.exact = exact.copy() if exact_rows else None
        if status in SOLVER_ERRORS or status.startswith("exception"):
            run.verified, run.violation = None, None  # q is not a solver iterate: never accept it
            return q, stats, False
        cert = certify(problem.scene, q, margin=problem.certified_clearance)
        run.verified, run.violation = cert, None
        if cert.ok:
            run.violation = path_violation(problem, q)  # max_step, joint limits
            if run.violation is None:
                return q, stats, True
            log.info("check: %s", run.violation)
            run.verified = None  # certified, but not a path of the problem: never accept it
            return q, stats, False
        bad = list(cert.bad_segments)
        log.info("certify: %d segment(s) not proven clear (more check points there)", len(bad))
        refined = splits.copy()
        refined[bad] *= 2
        duals = nlp.duals_on(refined) if refine.warm_start else None
        splits = refined
        near = _near_segments(bad, len(splits), refine.raise_window)
        if exact_rows:  # coal rows there (gdnplan.trajopt.refine): the true distance, no raise
            exact[near] = True
        elif learned:
            over = model_overestimate(problem.scene, model, q, bad, margin)  # active rows sit at
            raised[near] = np.maximum(raised[near], over)  # d̂ = bound: raise to the error, no sum
    return q, stats, False
