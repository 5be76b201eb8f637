"""Seed paths: the kinds of initial guess the Ipopt optimiser refines, one function each.

A seed kind is a function ``source(request: SeedRequest) -> (T, dof) path or None`` (None:
no path found within ``request.time_limit``) registered by name in :data:`SEED_KINDS`
(:func:`register_seed_kind`); :class:`~gdnplan.trajopt.config.SeedConfig` ``kinds`` lists the
kinds drawn in turn. A seed need not be collision-free (the certificate judges the refined
path), but every shipped kind's edges are certified at ``request.clearance``.

Seed i of a call uses the random stream ``seed + i`` (``seed``: the plan's seed), so the seeds
of a call with more seeds begin with the seeds of a call with fewer.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from importlib.util import find_spec

import numpy as np

from ..errors import InputError
from ..exact import exact_distance
from ..path_metrics import resample_arc_length
from ..robot_checks import as_batch
from ..rrt import resample, rrt_connect, seed_path, shortcut
from .check_points import straight_line
from .config import MISSING_SEED_KINDS, SEED_KINDS
from .problem import Problem

log = logging.getLogger("gdnplan.trajopt")  # one logger for the package: the stage lines

VIA_DRAWS = 100  # random via points drawn until one clears the demanded clearance
SCREENED = 4  # RRT-Connect paths drawn per rrt seed; the cheapest is refined (decisions.md)
SCREEN_ITER_FACTOR = 4  # a later draw's RRT-Connect extensions: at most this × the first's …
SCREEN_MIN_ITER = 200  # … and at least this (a bound by work, not by the clock)
SCREEN_STRIDE = 100_003  # stream offset of draw j (far from the streams of other seeds)
OMPL_TIME = 1.0  # s: planning + simplification of one OMPL seed (docs/decisions.md)
HAS_OMPL = find_spec("ompl") is not None


@dataclass(frozen=True)
class SeedRequest:
    """What a seed kind is asked for.

    Attributes:
        problem: the problem (start, limits, waypoints T, scene).
        goal: (dof,) joint goal (rad).
        clearance: clearance (m) the seed's edges should keep.
        seed: the plan's seed; ``index``: the seed's index in the call; the random stream of
            seed ``index`` is ``seed + index``.
        time_limit: time (s) the kind may take.
        rrt_step: RRT-Connect extension (rad).
    """

    problem: Problem
    goal: np.ndarray
    clearance: float
    seed: int
    index: int
    time_limit: float
    rrt_step: float

    @property
    def stream(self) -> int:
        return self.seed + self.index


SeedSource = Callable[[SeedRequest], "np.ndarray | None"]


@dataclass(frozen=True)
class SeedInfo:
    """Which seed a plan's path was refined from: its ``kind`` (a :data:`SEED_KINDS` name, or
    "straight"), its ``index`` among the seeds tried (0-based) and its random ``stream``."""

    kind: str
    index: int
    stream: int

    def summary(self) -> dict:
        return {"kind": self.kind, "index": self.index, "stream": self.stream}


def rrt_seed(request: SeedRequest) -> np.ndarray | None:
    """The cheapest of up to ``SCREENED`` RRT-Connect + shortcut + resample paths
    (:func:`gdnplan.rrt.seed_path`; path j on stream ``request.stream + SCREEN_STRIDE · j``,
    path 0 on ``request.stream`` itself) by path cost Σ‖Δq‖²: RRT-Connect's paths fall into
    different homotopy classes, and refining the cheapest draw is far cheaper than refining
    each. A draw after the first may take at most ``SCREEN_ITER_FACTOR`` × the first's
    RRT-Connect extensions (at least ``SCREEN_MIN_ITER``): bounded by work, not by the clock,
    so the seed of a problem and stream is the same on any machine and at any load;
    ``request.time_limit`` bounds the whole (only a machine too slow to finish within it
    sees fewer draws)."""
    p = request.problem
    t0, best, best_cost = time.perf_counter(), None, math.inf
    cap = 5000  # rrt_connect's own cap for the first draw
    for j in range(SCREENED):
        left = request.time_limit - (time.perf_counter() - t0)
        if left <= 0:
            break
        path, res = seed_path(
            p.scene,
            p.start,
            request.goal,
            p.waypoints,
            request.clearance,
            seed=request.stream + SCREEN_STRIDE * j,
            time_limit=left,
            step=request.rrt_step,
            max_iterations=cap,
            lower=p.lower,  # the problem's limits, not the robot's (a narrowed box)
            upper=p.upper,
        )
        if j == 0:
            cap = min(cap, max(SCREEN_MIN_ITER, SCREEN_ITER_FACTOR * res.iterations))
        if path is not None and (cost := float(np.sum(np.diff(path, axis=0) ** 2))) < best_cost:
            best, best_cost = path, cost
    return best


def via_seed(request: SeedRequest) -> np.ndarray | None:
    """RRT-Connect start → v → goal through a uniformly drawn via point v that clears the
    clearance (often another homotopy class than the direct RRT-Connect path); each half is
    shortcut on its own (so v stays on the path), then the whole resampled to T waypoints."""
    p = request.problem
    rng = np.random.default_rng([request.stream, 1])  # not the stream of the rrt kind
    draws = rng.uniform(p.lower, p.upper, (VIA_DRAWS, p.scene.robot.dof))
    free = np.flatnonzero(exact_distance(p.scene, draws) > request.clearance)
    if free.size == 0:
        return None
    via = draws[free[0]]
    t0, halves = time.perf_counter(), []
    for a, b in ((p.start, via), (via, request.goal)):
        left = request.time_limit - (time.perf_counter() - t0)
        if left <= 0:
            return None
        res = rrt_connect(
            p.scene,
            a,
            b,
            request.clearance,
            step=request.rrt_step,
            seed=request.stream,
            time_limit=left,
            lower=p.lower,
            upper=p.upper,
        )
        if not res.success:
            return None
        halves.append(shortcut(p.scene, res.path, request.clearance, seed=request.stream))
    path = np.vstack([halves[0], halves[1][1:]])
    return resample(p.scene.robot, path, p.waypoints)


def straight_seed(request: SeedRequest) -> np.ndarray:
    """The straight line; seed i > 0 perturbs its interior waypoints by the i-th draw of
    N(0, 0.2 rad) from the plan's seed, clipped to the limits."""
    p = request.problem
    guess = straight_line(p.start, request.goal, p.waypoints)
    rng = np.random.default_rng(request.seed)
    noise = None
    for _ in range(request.index):
        noise = rng.normal(0, 0.2, guess[1:-1].shape)
    if noise is not None:
        guess[1:-1] += noise
        guess = np.clip(guess, p.lower, p.upper)
    return guess


def aorrtc_seed(request: SeedRequest) -> np.ndarray | None:
    """OMPL's asymptotically optimal AORRTC under the path-length objective, simplified
    (:func:`gdnplan.ompl_planner.plan_ompl`), its states and motions certified above the
    smaller of ``request.clearance`` and the margin (the shortest way may pass where only the
    margin fits), within ``OMPL_TIME`` s of planning and simplification; resampled to T
    waypoints equally spaced in joint-space arc length
    (:func:`gdnplan.path_metrics.resample_arc_length`: on a fixed polyline, the spacing of
    least Σ‖Δq‖²). OMPL seeds its generator once per process, so ``request.stream`` does not
    pick its run (not reproducible). Needs OMPL (``pip install 'gdnplan[bench]'``)."""

    from ..ompl_planner import MAX_OMPL_SEED, plan_ompl

    p = request.problem
    budget = min(request.time_limit, OMPL_TIME)
    clearance = min(request.clearance, p.margin)  # not more: the short way may be narrow
    r = plan_ompl(
        p.scene, p.start, request.goal, clearance, "aorrtc", budget,
        seed=request.stream % (MAX_OMPL_SEED + 1), lower=p.lower, upper=p.upper,
    )  # fmt: skip
    if not r.success:
        return None
    return resample_arc_length(r.path, p.waypoints)


SEED_KINDS.update(rrt=rrt_seed, via=via_seed, straight=straight_seed)
if HAS_OMPL:
    SEED_KINDS["aorrtc"] = aorrtc_seed
else:
    MISSING_SEED_KINDS["aorrtc"] = (
        "needs OMPL, which is not installed (pip install 'gdnplan[bench]')"
    )


def register_seed_kind(name: str, source: SeedSource) -> None:
    """Add a seed kind (e.g. another planner's path) under ``name`` for ``SeedConfig.kinds``."""
    if not isinstance(name, str) or not name.isidentifier():
        raise InputError(f"seed kind name: expected an identifier, got {name!r}")
    if not callable(source):
        raise InputError(f"seed kind {name!r}: expected a function SeedRequest -> path or None")
    SEED_KINDS[name] = source


def checked_guess(kind: str, guess, problem: Problem) -> np.ndarray:
    """A seed kind's path as float64 (T, dof) rad: real finite numbers of the problem's shape,
    else InputError naming the kind (the joint-angle checks of
    :func:`gdnplan.robot_checks.as_batch`: strings, ragged lists or a dict raised numpy's
    ValueError or TypeError; a complex path lost its imaginary part, bools passed as 0/1 rad,
    NaN reached Ipopt or a learned model). Waypoints outside the joint limits are clipped by
    the solve, and the ends are the problem's start and goal whatever the path holds there."""
    shape = (problem.waypoints, problem.scene.robot.dof)
    arr = as_batch(guess, shape[1], f"seed kind {kind!r}: its path")
    if arr.shape != shape or np.ndim(guess) != 2:
        raise InputError(
            f"seed kind {kind!r}: returned shape {np.shape(guess)}, expected {shape} "
            "(T, dof) joint angles (rad), or None when it finds no path"
        )
    return arr


def draw_seed(
    kind: str,
    problem: Problem,
    goal: np.ndarray,
    clearance: float,
    seed: int,
    index: int,
    rrt: tuple[float, float],
    deadline: float = math.inf,
) -> tuple[np.ndarray | None, str]:
    """Seed ``index`` of ``kind`` demanding ``clearance`` (m), retried at the margin alone when
    none is found (narrow passages); ``rrt``: (time limit of one run (s), step (rad)), the time
    limit cut at ``deadline`` (a :func:`time.perf_counter` value). Returns (path (T, dof) or
    None, a label for the plan's reason)."""
    if kind == "straight":
        request = SeedRequest(problem, goal, clearance, seed, index, rrt[0], rrt[1])
        return straight_seed(request), "straight line" + (f" (perturbed {index})" if index else "")
    label = f"{kind} seed {index} (stream {seed + index})"
    t0, guess, demand = time.perf_counter(), None, clearance
    for demand in dict.fromkeys((clearance, problem.margin)):
        left = min(rrt[0], deadline - time.perf_counter())
        if left <= 0:
            break
        guess = SEED_KINDS[kind](SeedRequest(problem, goal, demand, seed, index, left, rrt[1]))
        if guess is not None:
            break
    if guess is not None:
        guess = checked_guess(kind, guess, problem)
    found = "path found" if guess is not None else "no path"
    log.info("seed: %s: %s, %.2f s", label, found, time.perf_counter() - t0)
    return guess, label + (" (clearance = margin)" if demand < clearance else "")


__all__ = [
    "SEED_KINDS",
    "SeedInfo",
    "SeedRequest",
    "SeedSource",
    "aorrtc_seed",
    "checked_guess",
    "draw_seed",
    "register_seed_kind",
    "rrt_seed",
    "straight_seed",
    "via_seed",
]
