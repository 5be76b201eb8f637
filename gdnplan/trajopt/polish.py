"""Second solves from the planner's result: a polish of the certified path and a repair of an
uncertified one, each the refine loop (:func:`~gdnplan.trajopt.ipopt._solve_refined`) again from
that path with other settings; the result is kept only when the certificate proves it.

- polish: the seeds' solves stop early (``IpoptConfig.obj_change_tol``) with check points
  ``clearance_buffer`` above the certified clearance c. From the cheapest certified path the
  solves of :data:`POLISH_STAGES` in turn, each with a tighter stop, more check points per
  segment and a bound c + buffer closer to c, move the path towards the constrained optimum;
  each replaces the path when it is certified and cheaper (path cost Σ‖Δq‖²). A polish solve
  starts from a converged, certified path, so it gets at most ``POLISH_ITER_FACTOR`` times the
  seeds' mean iterations per solve (at least ``POLISH_MIN_ITER``, at most ``max_iter``): one
  that needs more is stalling at its tighter stop, not improving the path (docs/decisions.md,
  2026-12-03: a learned model's second stage ran to 150 iterations for a path no cheaper,
  where coal's took 13).
- repair: when no seed's path was certified (the refine rounds ran out with the path a little
  inside c between check points), one solve from the last path with ``REPAIR_EXTRA`` check
  points more per segment and the bound c + clearance_buffer + ``REPAIR_BUFFER``.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import replace

import numpy as np

from ..limits import MAX_REFINE_ROUNDS
from ..models import DistanceModel
from .config import PlanConfig, more_check_points
from .problem import Problem
from .result import _Run, path_cost

log = logging.getLogger("gdnplan.trajopt")  # one logger for the package: the stage lines

# the polish solves in turn: (check points' buffer above c (m), check points added per
# segment, obj_change_tol)
POLISH_STAGES = ((0.0005, 1, 1e-5), (0.0002, 2, 1e-6))
POLISH_ITER_FACTOR = 2  # a polish solve's iteration cap: this × the seeds' mean per solve
POLISH_MIN_ITER = 30  # … but never below this
EXTRA_ROUNDS = 3  # refine rounds a polish or repair solve gets beyond RefineConfig.rounds
REPAIR_EXTRA = 2  # check points per segment the repair adds
REPAIR_BUFFER = 0.003  # m: extra bound of the repair's check points


def _again(
    problem: Problem,
    model: DistanceModel,
    goal: np.ndarray,
    cfg: PlanConfig,
    run: _Run,
    deadline: float,
) -> tuple[np.ndarray, bool]:
    """The refine loop with ``cfg`` from ``run.q``: (path, certified); ``run`` keeps its own
    certificate unless the new path is certified (iterations and model calls add up)."""
    from .ipopt import _solve_refined  # ipopt imports nothing of this module's users

    trial = _Run(q=run.q, exact=run.exact)
    q, _, ok = _solve_refined(problem, model, goal, cfg, run.q, trial, deadline)
    run.iterations += trial.iterations
    run.model_calls += trial.model_calls
    if ok:
        run.verified, run.exact = trial.verified, trial.exact
    return q, ok


def polish_iterations(run: _Run, max_iter: int) -> int:
    """Iteration cap of each polish solve: ``POLISH_ITER_FACTOR`` × the mean iterations of
    ``run``'s solves so far (per seed attempt), within [``POLISH_MIN_ITER``, ``max_iter``]."""
    mean = math.ceil(run.iterations / max(run.attempts, 1))
    return min(max_iter, max(POLISH_MIN_ITER, POLISH_ITER_FACTOR * mean))


def polish(
    problem: Problem,
    model: DistanceModel,
    goal: np.ndarray,
    cfg: PlanConfig,
    run: _Run,
    deadline: float = math.inf,
) -> None:
    """Replace ``run``'s certified path by each :data:`POLISH_STAGES` solve's in turn when that
    is certified and cheaper (module docstring); nothing when ``run`` holds no certified seed
    path."""
    if run.seed is None or run.seed.kind == "straight":
        return
    opt, first = cfg.optimizer, path_cost(run.q)
    rounds = min(cfg.refine.rounds + EXTRA_ROUNDS, MAX_REFINE_ROUNDS)
    cap = polish_iterations(run, opt.max_iter)
    for buffer, extra, stop in POLISH_STAGES:
        if run.verified is None or not run.verified.ok or time.perf_counter() >= deadline:
            return
        tight = replace(
            cfg,
            refine=replace(cfg.refine, clearance_buffer=buffer, rounds=rounds),
            optimizer=replace(more_check_points(opt, extra), obj_change_tol=stop, max_iter=cap),
        )
        t0, before, cert = time.perf_counter(), path_cost(run.q), run.verified
        q, ok = _again(problem, model, goal, tight, run, deadline)
        after = path_cost(q)
        kept = ok and after < before
        log.info(
            "polish: %s, path cost %.4f → %.4f rad², %.2f s",
            "kept" if kept else ("not cheaper" if ok else "not certified"),
            before, after, time.perf_counter() - t0,
        )  # fmt: skip
        if kept:
            run.q = q
        else:
            run.verified = cert
    if path_cost(run.q) < first:
        run.reason = f"{run.reason}; polished (path cost {first:.4g} → {path_cost(run.q):.4g})"


def repair(
    problem: Problem,
    model: DistanceModel,
    goal: np.ndarray,
    cfg: PlanConfig,
    run: _Run,
    deadline: float = math.inf,
) -> None:
    """When ``run`` holds an uncertified solver path, the repair solve from it (module
    docstring); ``run`` takes its path when that is certified."""
    if not run.status or (run.verified is not None and run.verified.ok):
        return  # no solver path (no seed found), or one already certified
    if run.seed is not None and run.seed.kind == "straight":
        return  # the straight line, certified free at the margin: nothing to repair
    if time.perf_counter() >= deadline:
        return
    opt, ref = cfg.optimizer, cfg.refine
    rounds = min(ref.rounds + EXTRA_ROUNDS, MAX_REFINE_ROUNDS)
    wide = replace(
        cfg,
        refine=replace(ref, clearance_buffer=ref.clearance_buffer + REPAIR_BUFFER, rounds=rounds),
        optimizer=more_check_points(opt, REPAIR_EXTRA),
    )
    t0 = time.perf_counter()
    q, ok = _again(problem, model, goal, wide, run, deadline)
    log.info("repair: %s, %.2f s", "certified" if ok else "not certified", time.perf_counter() - t0)
    if ok:
        run.q, run.reason = q, f"{run.reason}; repaired from the last path"


__all__ = ["POLISH_STAGES", "REPAIR_BUFFER", "REPAIR_EXTRA", "polish", "repair"]
