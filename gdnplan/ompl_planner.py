"""Sampling-based planners of OMPL (optional: ``pip install gdnplan[bench]``) on gdnplan's
validity rule: joint-space paths whose whole continuous motion is certified above a clearance.

The state space is ℝ^dof bounded by the joint limits (lower, upper); a state q is valid when
coal's proven distance lower bound d̲(q) = d_coal(q) − COAL_SLACK (1 + |d_coal(q)|)
(:func:`gdnplan.ccd.proven_distance`) is > ``clearance`` (m), and a motion qa → qb is valid when
:func:`gdnplan.rrt.edge_free` certifies the straight segment above ``clearance`` by conservative
advancement — the certificate that accepts gdnplan's own RRT-Connect edges and judges every
:func:`gdnplan.plan`. OMPL's path simplifier checks its shortcuts with the same motion validator,
so an OMPL path is certified segment by segment as it is built; :func:`plan_ompl` still certifies
the returned path once more with :func:`gdnplan.ccd.certify_path` (its proven lower bound is
``OmplResult.clearance``) and reports failure if that certificate does not hold.

Planners by name (:data:`PLANNERS`): ``rrtconnect`` (feasible, returns at the first path),
and the asymptotically optimal ``bitstar``, ``aorrtc``, ``rrtstar`` (under OMPL's path-length
objective Σ_k ‖q_{k+1} − q_k‖, they use the whole time budget). OMPL is imported when first used.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from .ccd import Certificate, proven_distance
from .errors import InputError
from .exact import certify, exact_distance, swept_radius_of
from .flags import check_flag
from .limits import check_int, check_number
from .robot import as_batch, first_outside
from .rrt import edge_free
from .scene import Scene

PLANNERS = {  # name -> OMPL geometric planner class
    "rrtconnect": "RRTConnect",
    "bitstar": "BITstar",
    "aorrtc": "AORRTC",
    "rrtstar": "RRTstar",
}
MAX_TIME = 600.0  # s, one planning call
MAX_OMPL_SEED = 2**32 - 1  # OMPL seeds its generators with an unsigned 32-bit integer
SIMPLIFY_SHARE = 0.2  # share of the time limit kept for path simplification
_SEEDED: list[int] = []  # OMPL's global seed can be set once per process, before any planner


def _ompl():
    """(ompl.base, ompl.geometric, ompl.util), or InputError saying how to install OMPL."""
    try:
        from ompl import base as ob
        from ompl import geometric as og
        from ompl import util as ou
    except ImportError as e:
        raise InputError(
            f"OMPL is not installed ({e}); install gdnplan[bench] (pip install 'ompl>=2.0')"
        ) from e
    return ob, og, ou


@dataclass(frozen=True)
class OmplResult:
    """Result of :func:`plan_ompl`.

    Attributes:
        success: OMPL found an exact solution and :func:`gdnplan.ccd.certify_path` proves the
            returned continuous path keeps the proven distance > the clearance.
        path: (K, dof) waypoints (rad), start first, goal last; (0, dof) when OMPL found none.
        time: wall time of set-up, planning, simplification and the final certificate (s).
        planner: the planner's name (a key of :data:`PLANNERS`).
        status: OMPL's planner status ("Exact solution", "Timeout", …).
        clearance: proven lower bound on the signed distance along the whole path (m, the
            certificate's); −inf when not proven or no path.
        certificate: the final certificate (None without a path).
    """

    success: bool
    path: np.ndarray
    time: float
    planner: str
    status: str
    clearance: float
    certificate: Certificate | None


def _seed(ou, seed: int) -> None:
    """Seed OMPL's random generators once per process (OMPL ignores later seeds with a warning)."""
    if not _SEEDED:
        ou.RNG.setSeed(int(seed))
        _SEEDED.append(int(seed))


def _setup(
    ob,
    scene: Scene,
    lower: np.ndarray,
    upper: np.ndarray,
    clearance: float,
    deadline: float = math.inf,
):
    """SpaceInformation over the joint box with the certified state and motion checks; a
    motion checked after ``deadline`` (``time.perf_counter()`` s) is refused unchecked.

    OMPL's path simplifier runs every step once whatever its time limit, each with many
    motion checks (a 3-D certificate each): a 1 s plan took 4 s. Refusing motions past the
    deadline ends them at once, and leaves the path unchanged (a refused motion is never
    taken), so it stays as certified as it was."""
    dof = scene.robot.dof
    space = ob.RealVectorStateSpace(dof)
    bounds = ob.RealVectorBounds(dof)
    for j in range(dof):
        bounds.setLow(j, float(lower[j]))
        bounds.setHigh(j, float(upper[j]))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    swept = swept_radius_of(scene)

    def vector(state) -> np.ndarray:
        return np.array([state[j] for j in range(dof)])

    def valid(state) -> bool:
        q = vector(state)
        if np.any(q < lower) or np.any(q > upper):
            return False
        d = exact_distance(scene, q, margin=clearance)  # 3-D contact-only pairs: d + clearance
        return bool(proven_distance(d, swept)[0] > clearance)

    class CertifiedMotion(ob.MotionValidator):
        def checkMotion(self, a, b) -> bool:  # OMPL's name
            if time.perf_counter() > deadline:
                return False
            return edge_free(scene, vector(a), vector(b), clearance)

    si.setStateValidityChecker(valid)
    motion = CertifiedMotion(si)
    si.setMotionValidator(motion)
    si.setup()
    return si, motion, vector


def _check(scene: Scene, start, goal, lower, upper, clearance, time_limit, planner):
    robot = scene.robot
    if planner not in PLANNERS:
        raise InputError(f"planner: unknown {planner!r}; choose from {sorted(PLANNERS)}")
    check_number(clearance, "clearance")
    if check_number(time_limit, "time_limit", strict=True) > MAX_TIME:
        raise InputError(f"time_limit: {time_limit} s is over the limit {MAX_TIME} s")
    lower, upper = _check_box(robot, lower, upper)
    start, goal = (
        _check_state(robot, q, n, lower, upper) for q, n in ((start, "start"), (goal, "goal"))
    )
    return start, goal, lower, upper


def _vector(robot, value, name: str) -> np.ndarray:
    """One configuration (dof,) of finite real numbers (rad), else InputError naming ``name``."""
    try:
        shape = np.shape(value)
    except ValueError:  # ragged nesting
        shape = "a ragged list"
    if shape != (robot.dof,):
        raise InputError(f"{name}: expected shape ({robot.dof},) (rad), got {shape}")
    return as_batch(value, robot.dof, name)[0]


def _check_box(robot, lower, upper) -> tuple[np.ndarray, np.ndarray]:
    """The joint box: (dof,) finite bounds (rad) within the robot's joint limits and
    lower < upper on every joint (the robot's limits when None), else InputError naming them."""
    lower = _vector(robot, robot.lower if lower is None else lower, "lower")
    upper = _vector(robot, robot.upper if upper is None else upper, "upper")
    for name, value in (("lower", lower), ("upper", upper)):
        j = first_outside(value, robot.lower, robot.upper)
        if j is not None:
            raise InputError(
                f"{name}[{j}] = {value[j]:.4g} rad is outside the robot's joint range "
                f"[{robot.lower[j]:.4g}, {robot.upper[j]:.4g}]; narrow it"
            )
    flat = np.flatnonzero(lower >= upper)
    if flat.size:
        j = int(flat[0])
        raise InputError(
            f"lower[{j}] = {lower[j]:.4g} rad must be below upper[{j}] = {upper[j]:.4g} rad"
        )
    return lower, upper


def _check_state(robot, q, name: str, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """start or goal (dof,) rad inside the joint box, else InputError naming it."""
    q = _vector(robot, q, name)
    j = first_outside(q, lower, upper)
    if j is not None:
        raise InputError(
            f"{name}[{j}] = {q[j]:.4g} rad is outside the joint box "
            f"[{lower[j]:.4g}, {upper[j]:.4g}] (lower, upper)"
        )
    return q


def plan_ompl(
    scene: Scene,
    start: np.ndarray,
    goal: np.ndarray,
    clearance: float,
    planner: str = "rrtconnect",
    time_limit: float = 1.0,
    simplify: bool = True,
    seed: int = 0,
    lower: np.ndarray | None = None,
    upper: np.ndarray | None = None,
) -> OmplResult:
    """Plan start → goal (dof,) with OMPL's ``planner`` within ``time_limit`` (s of wall time:
    set-up, planning and simplification together, up to the motion check under way; no
    motion is checked, so none is added to the path, after it).

    ``simplify``: OMPL's ``PathSimplifier`` (vertex reduction, shortcuts, B-spline smoothing,
    every change checked by the certified motion validator) runs afterwards in the time left;
    the planner then gets (1 − ``SIMPLIFY_SHARE``) of ``time_limit`` (an anytime planner uses
    all of it, RRT-Connect stops at its first path and leaves the rest to simplification).
    ``OmplResult.time`` is the whole wall time (the final certificate included).
    ``lower``/``upper`` (dof,) rad: the joint box, finite, within the robot's joint limits
    (1e-9 rad of slack), lower < upper on every joint, start and goal inside it (the robot's
    limits when None; InputError naming ``lower``, ``upper``, ``start`` or ``goal`` otherwise,
    before OMPL is imported). ``seed`` (an integer in [0, 2³² − 1]) seeds
    OMPL's generators the first time any planner runs in this process (OMPL allows one global
    seed); a run is reproducible for the same seed and sequence of calls up to time limits (an
    anytime planner's result depends on how far it got in its time). Raises InputError on bad
    input or without OMPL.
    """
    simplify = check_flag(simplify, "simplify")
    check_int(seed, "seed", 0, MAX_OMPL_SEED)  # OMPL's binding raised TypeError for −1
    start, goal, lower, upper = _check(
        scene, start, goal, lower, upper, clearance, time_limit, planner
    )
    ob, og, ou = _ompl()
    ou.setLogLevel(ou.LOG_ERROR)
    _seed(ou, seed)
    t0 = time.perf_counter()
    si, _, vector = _setup(ob, scene, lower, upper, clearance, t0 + float(time_limit))
    ss = og.SimpleSetup(si)
    a, b = si.allocState(), si.allocState()
    for j in range(scene.robot.dof):
        a[j], b[j] = float(start[j]), float(goal[j])
    ss.setStartAndGoalStates(a, b)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    ss.setPlanner(getattr(og, PLANNERS[planner])(si))
    share = 1.0 - SIMPLIFY_SHARE if simplify else 1.0
    status = str(ss.solve(max(share * float(time_limit) - (time.perf_counter() - t0), 1e-3)))
    dof = scene.robot.dof
    if not ss.haveExactSolutionPath():
        return OmplResult(
            False, np.zeros((0, dof)), time.perf_counter() - t0, planner, status, -math.inf, None
        )
    if simplify:
        ss.simplifySolution(max(float(time_limit) - (time.perf_counter() - t0), 1e-3))
    sol = ss.getSolutionPath()
    path = np.array([vector(sol.getState(i)) for i in range(sol.getStateCount())])
    path[0], path[-1] = start, goal  # OMPL's goal test is exact for a state goal
    cert = certify(scene, path, margin=clearance)
    elapsed = time.perf_counter() - t0
    return OmplResult(cert.ok, path, elapsed, planner, status, cert.lower_bound, cert)


__all__ = ["PLANNERS", "OmplResult", "plan_ompl"]
