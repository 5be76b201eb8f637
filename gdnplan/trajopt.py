"""Trajectory optimisation: Problem, Plan, Ipopt direct transcription, the paper's Adam baseline.

Direct transcription over T waypoints Q = (q_0, …, q_{T−1}), q_0 = start, q_{T−1} = goal:

    minimise    Σ_t ‖q_{t+1} − q_t‖²                                   (the paper's path cost)
    subject to  lower ≤ q_t ≤ upper,   |q_{t+1} − q_t| ≤ max_step      (joint, step limits)
                d(p_k) ≥ margin           at the check points p = q_t + i/n_t (q_{t+1} − q_t),
                                          i = 0 … n_t − 1, of every segment t (n_t = M + 1 first),
                                          except the fixed start and goal themselves

with d the overall or per-link distance of any DistanceModel (one batched call through
:class:`~gdnplan.casadi_bridge.DistanceCallback`). The start and goal rows would be constants:
coal checks both when the problem is made, and a learned model that rates one of them below
the margin (the held stick 1.75 cm above its shelf) would only make the NLP infeasible.
Continuous collision (the CCD certificate): after each solve, :func:`gdnplan.ccd.certify_path`
checks the continuous motion with coal by conservative advancement; every waypoint segment it
cannot certify gets twice as many check points (n_t ← 2 n_t) — and, for a learned model, the
margin there and on ``raise_window`` segments either side is raised by the model's
overestimate — and Ipopt re-solves from the current path, for ``refine_rounds`` rounds.
(The certificate as NLP rows, d(p_k) + d(p_{k+1}) ≥ δ(p_k, p_{k+1}) + 2·margin, was tried and
dropped: at 3 check points per segment δ reaches ~1 m on seed paths, the rows are infeasible
and Ipopt runs to its iteration cap.) Ipopt uses a limited-memory Hessian and starts from the
straight line when it is certified free (then it is already optimal and returned as is) or
from RRT-Connect seeds, restarting from a new seed on failure. A plan succeeds only when
:func:`gdnplan.ccd.verify_path` certifies the returned path with coal and the goal is reached —
never on the solver's word alone.
"""

from __future__ import annotations

import logging
import math
import time
import tomllib
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import casadi
import numpy as np
import pinocchio as pin

from .assets import default_weights, problem_file
from .casadi_bridge import DistanceCallback, supports_per_link
from .ccd import Certificate, certify_path, verify_path
from .distance import signed_distance
from .errors import InfeasibleProblemError, InputError, ProblemFileError
from .limits import (
    IPOPT_OPTIONS,
    MAX_ADAM_ITERATIONS,
    MAX_CHECK_POINTS,
    MAX_INTERPOLATED,
    MAX_ITER,
    MAX_REFINE_ROUNDS,
    MAX_RRT_TIME,
    MAX_STARTS,
    MAX_WAYPOINTS,
    check_int,
    check_ipopt,
    check_number,
    is_number,
)
from .models import CoalModel, DistanceModel, load_model
from .robot import Robot, first_outside
from .rrt import seed_path
from .scene import Scene, no_unknown_keys, scene_from_config
from .timing import TimedTrajectory, limit_vector, plan_timing

log = logging.getLogger(__name__)  # stage lines at INFO (the CLI shows them on stderr)

# problem-file keys (docs/problem_file.md documents each; tests/test_problem_file_docs.py checks);
# [robot], [scene], [[obstacles]]: scene.ROBOT_KEYS etc.; [solver]: SOLVER_KEYS
TOP_KEYS = frozenset({"robot", "scene", "obstacles", "start", "goal", "options", "solver"})
START_KEYS = frozenset({"q"})
GOAL_KEYS = frozenset({"q", "position"})  # exactly one of them
INITIAL_GUESSES = ("auto", "straight", "rrt")
SOLVER_ERRORS = {"Invalid_Number_Detected", "Unrecoverable_Exception", "Internal_Error"}
WARM_START_OPTIONS = {  # Ipopt options of refine rounds started from the last primal-dual point
    "warm_start_init_point": "yes",
    "mu_init": 1e-4,
    "warm_start_bound_push": 1e-6,
    "warm_start_slack_bound_push": 1e-6,
    "warm_start_mult_bound_push": 1e-6,
}
IPOPT_INTERPOLATED, ADAM_INTERPOLATED = 2, 3  # TrajoptOptions.interpolated=None per solver
OPTION_KEYS = frozenset({"waypoints", "margin", "max_step", "goal_tolerance", "lower", "upper"})


# -------------------------------------------------------------------- end effector
def tip_point(robot: Robot) -> np.ndarray:
    """(2,) plane position at q = 0 of the robot's last frame (its tip / end effector)."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, np.zeros(robot.dof))
    return robot.plane.project(data.oMf[robot.model.nframes - 1].translation)


def tip_position(robot: Robot, q: np.ndarray) -> np.ndarray:
    """(B, 2) end-effector positions (m) at q (B, dof)."""
    q = robot.check_q(q)
    return robot.chain.transform(tip_point(robot)[None], np.array([robot.dof]), q)[:, 0]


def tip_reach(robot: Robot) -> float:
    """Largest possible distance of the tip from joint 1 (m), chained over joint distances."""
    o = robot.chain.joint_origins
    hops = np.sum(np.linalg.norm(np.diff(o, axis=0), axis=1))
    return float(hops + np.linalg.norm(tip_point(robot) - o[-1]))


# -------------------------------------------------------------------- problem
@dataclass(frozen=True, eq=False)
class Problem:
    """A planning problem: move the robot of ``scene`` from ``start`` to a goal.

    Attributes:
        scene: robot and obstacles.
        start: (dof,) start joint angles (rad).
        goal: (dof,) goal joint angles (rad), or None when ``goal_position`` is given.
        goal_position: (2,) end-effector goal in the plane (m), or None.
        waypoints: 3 ≤ T ≤ ``limits.MAX_WAYPOINTS`` (500), waypoints including start and goal.
        margin: required clearance d ≥ margin (m).
        max_step: largest change of any joint between consecutive waypoints (rad).
        goal_tolerance: end-effector position error accepted for ``goal_position`` (m).
        lower: (dof,) lower joint limits (rad), within the robot's; the robot's when None.
        upper: (dof,) upper joint limits (rad), within the robot's; the robot's when None.
        solver: the solver settings this problem needs (a problem file's ``[solver]`` table,
            e.g. short RRT-Connect steps for a narrow passage); :func:`plan` uses them unless
            it is given ``options``. None: the defaults.
    """

    scene: Scene
    start: np.ndarray
    goal: np.ndarray | None = None
    goal_position: np.ndarray | None = None
    waypoints: int = 20
    margin: float = 0.02
    max_step: float = 1.0
    goal_tolerance: float = 1e-3
    lower: np.ndarray = field(default=None)  # type: ignore[assignment]
    upper: np.ndarray = field(default=None)  # type: ignore[assignment]
    solver: TrajoptOptions | None = None

    def __post_init__(self) -> None:
        robot = self.scene.robot
        set_ = object.__setattr__
        set_(
            self,
            "lower",
            _vector(robot.lower if self.lower is None else self.lower, robot.dof, "options.lower"),
        )
        set_(
            self,
            "upper",
            _vector(robot.upper if self.upper is None else self.upper, robot.dof, "options.upper"),
        )
        set_(self, "start", _vector(self.start, robot.dof, "start.q"))
        if (self.goal is None) == (self.goal_position is None):
            raise InputError("goal: give exactly one of q (joint angles) or position ([x, y])")
        if self.goal is not None:
            set_(self, "goal", _vector(self.goal, robot.dof, "goal.q"))
        else:
            set_(self, "goal_position", _vector(self.goal_position, 2, "goal.position"))
        check_int(self.waypoints, "options.waypoints", 3, MAX_WAYPOINTS)
        check_number(self.margin, "options.margin")
        check_number(self.max_step, "options.max_step", strict=True)
        check_number(self.goal_tolerance, "options.goal_tolerance", strict=True)
        self._check_limits()
        if self.solver is not None and not isinstance(self.solver, TrajoptOptions):
            raise InputError(f"solver: expected TrajoptOptions, got {type(self.solver).__name__}")
        self._check_feasible()

    def _check_limits(self) -> None:
        """lower < upper, both within the robot's own joint limits."""
        robot = self.scene.robot
        for name, value in (("lower", self.lower), ("upper", self.upper)):
            j = first_outside(value, robot.lower, robot.upper)
            if j is not None:
                raise InputError(
                    f"options.{name}[{j}] = {value[j]:.4g} is outside the robot's joint range "
                    f"[{robot.lower[j]:.4g}, {robot.upper[j]:.4g}]; narrow it"
                )
        flat = np.flatnonzero(self.lower >= self.upper)
        if flat.size:
            j = int(flat[0])
            raise InputError(f"options.lower[{j}] must be below options.upper[{j}]")

    def _check_feasible(self) -> None:
        """Start and goal inside the limits and clear of obstacles, goal position in reach."""
        named = [("start.q", self.start)] + (
            [("goal.q", self.goal)] if self.goal is not None else []
        )
        for name, q in named:
            j = first_outside(q, self.lower, self.upper)
            if j is not None:
                raise InfeasibleProblemError(
                    f"{name}[{j}] = {q[j]:.4g} is outside the joint limits "
                    f"[{self.lower[j]:.4g}, {self.upper[j]:.4g}]"
                )
            d = float(signed_distance(self.scene, q)[0])
            if d <= self.margin:
                raise InfeasibleProblemError(
                    f"{name} is in collision: distance {d:.4f} m ≤ margin {self.margin} m; "
                    "move it away from the obstacles or lower options.margin"
                )
        if self.goal is not None:
            blocked = first_joint_barrier(self.scene, self.start[0], self.goal[0])
            if blocked is not None:
                raise InfeasibleProblemError(
                    f"start.q[0] -> goal.q[0]: the first link collides at joint 1 = {blocked:.3f} "
                    "rad, which every motion between them must pass (joints do not wrap)"
                )
        if self.goal_position is not None:
            robot = self.scene.robot
            r = float(np.linalg.norm(self.goal_position - robot.chain.joint_origins[0]))
            if r > tip_reach(robot):
                raise InfeasibleProblemError(
                    f"goal.position {self.goal_position.tolist()} is out of reach: {r:.3f} m "
                    f"from the base, the tip reaches {tip_reach(robot):.3f} m"
                )

    @classmethod
    def from_toml(cls, path: str | Path) -> Problem:
        """Load a problem file or a shipped problem by name (``"fetch_reach"``); the schema is
        in ``docs/problem_file.md``. ProblemFileError names any bad field."""
        cfg = read_problem_file(path)
        try:
            return cls.from_config(cfg, base_dir=problem_file(path).parent)
        except ProblemFileError as e:
            raise ProblemFileError(f"{path}: {e}") from e

    @classmethod
    def from_config(cls, cfg: dict, base_dir: str | Path | None = None) -> Problem:
        """Problem from a parsed TOML mapping (see :meth:`from_toml`); relative paths in it
        (``[robot] urdf``) start at ``base_dir``, the current directory when None."""
        _no_unknown(cfg, TOP_KEYS, "top level")
        for key in ("start", "goal"):
            if not isinstance(cfg.get(key), dict):
                raise ProblemFileError(f"[{key}]: missing table", schema=True)
        _no_unknown(cfg["start"], START_KEYS, "[start]")
        _no_unknown(cfg["goal"], GOAL_KEYS, "[goal]")
        options = cfg.get("options", {})
        if not isinstance(options, dict):
            raise ProblemFileError("[options]: expected a table")
        _no_unknown(options, OPTION_KEYS, "[options]")
        solver = _solver_options(cfg.get("solver"))
        try:
            scene = scene_from_config(cfg, base_dir)
        except TypeError as e:
            raise ProblemFileError(f"[robot]/[scene]: unsupported option ({e})") from e
        goal = cfg["goal"]
        if ("q" in goal) == ("position" in goal):
            raise ProblemFileError(
                "[goal]: give exactly one of q = [...] or position = [x, y]", schema=True
            )
        if "q" not in cfg["start"]:
            raise ProblemFileError("[start] q: missing; give the start joint angles", schema=True)
        try:
            return cls(
                scene=scene,
                start=cfg["start"]["q"],
                goal=goal.get("q"),
                goal_position=goal.get("position"),
                solver=solver,
                **options,
            )
        except InputError as e:
            raise ProblemFileError(str(e)) from e


def read_problem_file(path: str | Path) -> dict:
    """The parsed TOML mapping of a problem file; ProblemFileError when it cannot be read, is
    not UTF-8 text, is malformed or nests deeper than Python's parser can follow.

    ``path``: a file, or the name of a shipped problem (``"fetch_reach"``).
    """
    path = problem_file(path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as e:
        raise ProblemFileError(f"{path}: cannot read the problem file ({e.strerror})") from e
    except UnicodeDecodeError as e:
        raise ProblemFileError(f"{path}: not UTF-8 text (byte {e.start}); save it as UTF-8") from e
    except tomllib.TOMLDecodeError as e:
        raise ProblemFileError(f"{path}: malformed TOML: {e}") from e
    except RecursionError as e:
        raise ProblemFileError(f"{path}: arrays or tables nest too deeply; flatten them") from e


def problem_start(cfg: dict, scene: Scene) -> np.ndarray | None:
    """The checked ``[start] q`` of a parsed problem file (None when absent), for drawing;
    the ``[solver]`` table is checked too (what ``plan`` rejects, ``show`` rejects)."""
    _solver_options(cfg.get("solver"))
    start = cfg.get("start")
    if start is None:
        return None
    if not isinstance(start, dict):
        raise ProblemFileError("[start]: expected a table with q = [...]")
    if "q" not in start:
        return None
    try:
        return _vector(start["q"], scene.robot.dof, "start.q")
    except InputError as e:
        raise ProblemFileError(str(e)) from e


def _solver_options(table: dict | None) -> TrajoptOptions | None:
    """TrajoptOptions from a problem file's ``[solver]`` table (None when absent)."""
    if table is None:
        return None
    if not isinstance(table, dict):
        raise ProblemFileError("[solver]: expected a table")
    _no_unknown(table, SOLVER_KEYS, "[solver]")
    if isinstance(table.get("ipopt"), dict):
        _no_unknown(table["ipopt"], IPOPT_OPTIONS.keys(), "[solver.ipopt]")
    defaults = TrajoptOptions()
    for key, value in table.items():
        default = getattr(defaults, key)  # None: int or bool settings with an automatic choice
        kind = (int, float) if type(default) is float else type(default)
        if default is not None and (
            not isinstance(value, kind) or isinstance(value, bool) != isinstance(default, bool)
        ):
            names = {float: "a number", int: "an integer", bool: "true or false", dict: "a table"}
            wanted = names.get(type(default), f"a {type(default).__name__}")
            raise ProblemFileError(f"[solver] {key}: expected {wanted}, got {value!r}")
    try:
        return replace(defaults, **table)
    except InputError as e:
        raise ProblemFileError(f"[solver] {e}") from e


_no_unknown = no_unknown_keys  # the check of every table's keys (cli.py uses it too)


def _vector(value, n: int, name: str) -> np.ndarray:
    """A finite float (n,) vector or InputError naming the field (no strings, no booleans)."""
    items = value.tolist() if isinstance(value, np.ndarray) else value
    if not isinstance(items, (list, tuple)) or not all(is_number(x) for x in items):
        raise InputError(f"{name}: expected a list of {n} numbers, got {value!r}")
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as e:
        raise InputError(f"{name}: expected {n} numbers, got {value!r}") from e
    if v.shape != (n,):
        raise InputError(f"{name}: expected {n} numbers, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise InputError(f"{name}: contains NaN or infinite values")
    v.setflags(write=False)
    return v


def first_joint_barrier(scene: Scene, a: float, b: float, n: int = 200) -> float | None:
    """A joint-1 angle between a and b (rad) where the links moved by joint 1 alone collide,
    or None when none of n samples does.

    Links on body 1 depend on q_1 only and joints do not wrap, so every path from q_1 = a to
    q_1 = b passes each angle between them in the same link pose: a collision there proves the
    problem infeasible. (Only a necessary condition is tested; None proves nothing.)
    """
    robot = scene.robot
    first = [k for k, p in enumerate(robot.polygons) if p.body == 1]
    if not first:
        return None
    q = np.zeros((n, robot.dof))
    q[:, 0] = np.linspace(a, b, n)
    d = signed_distance(scene, q, per_link=True)[:, first].min(axis=1)
    hit = np.flatnonzero(d <= 0)
    return float(q[hit[0], 0]) if hit.size else None


# -------------------------------------------------------------------- goal position -> q
def solve_ik(
    problem: Problem, seed: int = 0, restarts: int = 64, iterations: int = 100
) -> np.ndarray:
    """Collision-free joint goal (dof,) whose tip is at ``problem.goal_position``.

    Batched damped least squares Δq = Jᵀ(JJᵀ + λ²I)⁻¹ e from the start and ``restarts`` random
    configurations, clipped to the limits; among solutions within ``goal_tolerance`` and clear
    of the margin, the one closest to the start. Raises InfeasibleProblemError if none exists.
    """
    robot, target = problem.scene.robot, problem.goal_position
    rng = np.random.default_rng(seed)
    q = np.vstack([problem.start, rng.uniform(problem.lower, problem.upper, (restarts, robot.dof))])
    tip0, body = tip_point(robot)[None], np.array([robot.dof])
    for _ in range(iterations):
        p = robot.chain.transform(tip0, body, q)
        jac = robot.chain.jacobian(p, body, q)[:, 0]  # (B, 2, dof)
        err = target - p[:, 0]
        jjt = jac @ np.swapaxes(jac, 1, 2) + 1e-4 * np.eye(2)
        step = np.einsum("bji,bj->bi", jac, np.linalg.solve(jjt, err[..., None])[..., 0])
        q = np.clip(q + step, problem.lower, problem.upper)
    err = np.linalg.norm(tip_position(robot, q) - target, axis=1)
    ok = err <= problem.goal_tolerance / 2
    if ok.any():
        ok[ok] = signed_distance(problem.scene, q[ok]) > problem.margin
    for i in np.flatnonzero(ok):
        ok[i] = first_joint_barrier(problem.scene, problem.start[0], q[i, 0], n=50) is None
    if not ok.any():
        raise InfeasibleProblemError(
            f"goal.position {target.tolist()}: no collision-free joint configuration within the "
            "limits reaches it; move the goal or lower options.margin"
        )
    candidates = q[ok]
    return candidates[np.argmin(np.linalg.norm(candidates - problem.start, axis=1))]


# -------------------------------------------------------------------- plan
@dataclass(frozen=True)
class TrajoptOptions:
    """Solver settings (defaults are the benchmarked configuration), checked when made:
    a wrong type, NaN/inf or a value past its limit (:mod:`gdnplan.limits`: refine_rounds ≤ 8,
    interpolated ≤ 50, 1 ≤ starts ≤ 50, 1 ≤ max_iter ≤ 10 000, 1 ≤ adam_iterations ≤ 100 000,
    0 < rrt_time ≤ 600 s, ipopt options from an allow-list) is an InputError.

    Attributes:
        initial: "auto" (straight line when certified free, else RRT-Connect seeds),
            "straight" (always the straight line) or "rrt" (always RRT-Connect seeds).
        ccd: refine the check points of segments the continuous certificate rejects.
        refine_rounds: re-solves with refined check points (with ``ccd``).
        warm_start: start each refine round from the last round's solution and multipliers
            (Ipopt's warm start; new check points start with zero multipliers).
        per_link: one distance row per link polygon (capped at ``link_cap``) instead of one;
            None: when the model provides per-link distances (coal does).
        interpolated: M check points strictly between consecutive waypoints (before refining);
            None: 2 for Ipopt, 3 for Adam; Ipopt adds one per restart (``_plan_ipopt``).
            With 2 rather than 3 (the CCD certificate and refine rounds catch what the sparser
            check points miss) Ipopt with GraphDistNet took 25 % less time on (d) (a network
            pass costs about linearly in the check points) for +1 % mean path cost, 34 % less
            on the fetch layouts, 20 % more on (b), all 20/20 (benchmarks/RESULTS.md). Adam's
            stop test reads the check points alone, so Adam keeps the paper-baseline density.
        starts: Ipopt attempts (new seed path each) before giving up.
        max_iter: Ipopt iteration cap per attempt.
        tol: Ipopt tolerance.
        obj_change_tol: Ipopt also stops ("acceptable") once the relative change of the path
            cost stays below this for 3 iterations at a feasible point (constraint violation
            ≤ 1e-5): the certified check, not the KKT residual, judges the result. 1e-3 rather than
            1e-4 cut the Ipopt iterations of the (d) problems by 15 % (GraphDistNet) and 23 %
            (coal) for +0.1–0.3 % mean path cost (benchmarks/RESULTS.md).
        learned_margin: extra constraint margin (m) for learned models in the first solve;
            later rounds add the overestimate coal finds (see ``_solve_refined``).
        raise_window: a refine round raises a learned model's margin on the rejected
            segments and this many segments either side of each; None: on the whole path.
            2 rather than the whole path: the fetch bring-out (one attempt, seeds 0–3)
            certified 4/4 instead of 2/4, the (d) and fetch-layout problems stayed 20/20 with
            the same median evaluations (benchmarks/RESULTS.md).
        rrt_clearance: extra clearance (m) above the margin demanded of seed paths (at most
            half the start's and goal's own clearance above the margin); when RRT-Connect finds
            no such path, the same attempt retries demanding the margin only (narrow passages).
        rrt_time: time limit of one RRT-Connect run (s).
        rrt_step: RRT-Connect extension (rad, joint-space 2-norm); long steps were fastest on
            environment (d), narrow passages (fetch) may need ~0.3.
        link_cap: per-link distances above this (m) are reported as the cap (inactive rows).
        ipopt: extra Ipopt options (name → value) over the defaults, e.g.
            ``{"limited_memory_initialization": "scalar1"}`` (Ipopt's own default).
        adam_iterations: the paper's Adam optimiser: iteration cap.
        adam_lr: the Adam optimiser's step size (rad).
        adam_c: the Adam optimiser's collision-cost constant c.
        adam_eps: the Adam optimiser's collision-cost ε.
        adam_stop: the Adam optimiser stops once every check point is this far above the
            margin (m).
    """

    initial: str = "auto"
    ccd: bool = True
    refine_rounds: int = 3
    warm_start: bool = True
    per_link: bool | None = None
    interpolated: int | None = None
    starts: int = 3
    max_iter: int = 150
    tol: float = 1e-3
    obj_change_tol: float = 1e-3
    rrt_clearance: float = 0.02
    learned_margin: float = 0.0
    raise_window: int | None = 2
    rrt_time: float = 5.0
    rrt_step: float = 2.0
    link_cap: float = 0.3
    ipopt: dict = field(default_factory=dict)
    adam_iterations: int = 500
    adam_lr: float = 0.05
    adam_c: float = 1e-3
    adam_eps: float = 1e-3
    adam_stop: float = 0.01

    def __post_init__(self) -> None:
        """InputError naming the setting for a wrong type, NaN/inf or a value past its limit
        (limits in :mod:`gdnplan.limits`)."""
        if self.initial not in INITIAL_GUESSES:
            raise InputError(f"initial: unknown {self.initial!r}; choose one of {INITIAL_GUESSES}")
        for name in ("ccd", "warm_start") + (("per_link",) if self.per_link is not None else ()):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"{name}: expected true or false, got {getattr(self, name)!r}")
        check_int(self.refine_rounds, "refine_rounds", 0, MAX_REFINE_ROUNDS)
        if self.interpolated is not None:
            check_int(self.interpolated, "interpolated", 0, MAX_INTERPOLATED)
        if self.raise_window is not None:
            check_int(self.raise_window, "raise_window", 0, MAX_WAYPOINTS)
        check_int(self.starts, "starts", 1, MAX_STARTS)
        check_int(self.max_iter, "max_iter", 1, MAX_ITER)
        check_int(self.adam_iterations, "adam_iterations", 1, MAX_ADAM_ITERATIONS)
        for name in ("tol", "obj_change_tol", "rrt_step", "link_cap", "adam_lr", "adam_c"):
            check_number(getattr(self, name), name, strict=True)
        check_number(self.adam_eps, "adam_eps", strict=True)
        for name in ("rrt_clearance", "learned_margin", "adam_stop"):
            check_number(getattr(self, name), name)
        if check_number(self.rrt_time, "rrt_time", strict=True) > MAX_RRT_TIME:
            raise InputError(f"rrt_time: {self.rrt_time} s is over the limit {MAX_RRT_TIME} s")
        check_ipopt(self.ipopt)


SOLVER_KEYS = frozenset(f.name for f in fields(TrajoptOptions))  # a problem file's [solver]


@dataclass(frozen=True, eq=False)
class Plan:
    """Result of :func:`plan`.

    Attributes:
        success: the certified coal check passed and the goal is reached.
        q: (T, dof) waypoints (rad).
        min_distance: proven lower bound on the coal signed distance over the whole continuous
            path (m; the certificate of :func:`gdnplan.ccd.certify_path`, within 1 mm of the
            path's true minimum); −inf when the certificate could not prove the path free.
        sampled_min_distance: smallest coal distance over the configurations the certificate
            checked (m): an upper bound on the path's minimum (the true minimum lies in
            [min_distance, sampled_min_distance]).
        solve_time: wall time of the whole call: seeds, solves, verification (s); the time
            parametrisation after them is not included.
        iterations: solver iterations summed over attempts.
        status: the solver's last return status (Ipopt's, or "adam: …").
        reason: why the plan failed (or which attempt succeeded).
        path_cost: Σ_t ‖q_{t+1} − q_t‖² (rad²).
        model_calls: batched distance-model calls made by the solver.
        attempts: solver runs made.
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
    trajectory: TimedTrajectory | None = None

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


def resolve_model(collision: str | DistanceModel, scene: Scene, weights: str | Path | None):
    """The DistanceModel named by ``collision`` ("coal", "graphdistnet" or a model instance).

    ``weights`` (GraphDistNet): shipped weights by name (``"d"``) or a ``.safetensors`` path;
    None picks the shipped weights for the scene's robot and obstacles
    (:func:`gdnplan.assets.default_weights`).
    """
    if not isinstance(collision, str):
        if not isinstance(collision, DistanceModel):
            raise InputError(
                f"collision: expected 'coal', 'graphdistnet' or a DistanceModel, "
                f"got {type(collision).__name__}"
            )
        return checked(collision, scene)
    if collision == "coal":
        return CoalModel()
    if collision != "graphdistnet":
        raise InputError(f"collision: unknown {collision!r}; choose 'coal' or 'graphdistnet'")
    t0 = time.perf_counter()
    name = default_weights(scene) if weights is None else weights
    model = checked(load_model(name), scene)
    log.info("model: %s loaded, %.2f s", name, time.perf_counter() - t0)
    return model


def checked(model: DistanceModel, scene: Scene) -> DistanceModel:
    """``model`` after its ``check_scene(scene)``, where it has one (learned models: InputError
    when their weights were trained for another robot), before any solver runs it."""
    check = getattr(model, "check_scene", None)
    if check is not None:
        check(scene)
    return model


def plan(
    problem: Problem,
    collision: str | DistanceModel = "coal",
    solver: str = "ipopt",
    weights: str | Path | None = None,
    seed: int = 0,
    options: TrajoptOptions | None = None,
    max_velocity=None,
    max_acceleration=None,
) -> Plan:
    """Plan a trajectory for ``problem``; see the module docstring for the formulation.

    ``options`` default to the problem's own solver settings (``problem.solver``), else to
    :class:`TrajoptOptions`' defaults. ``max_velocity`` (rad/s; default: the URDF's limits)
    and ``max_acceleration`` (rad/s²; default None: velocity limits only), one number or one
    per joint, time the certified path (:func:`gdnplan.timing.time_path`, ``Plan.times``).

    Raises GdnplanError on bad input; a failed solve returns ``Plan(success=False, reason=…)``.
    """
    t0 = time.perf_counter()
    opts = options or problem.solver or TrajoptOptions()
    if not isinstance(opts, TrajoptOptions):
        raise InputError(f"options: expected TrajoptOptions, got {type(opts).__name__}")
    opts = replace(opts)  # re-runs the checks (a frozen dataclass can still be forged)
    _check_sizes(problem, opts, solver)
    dof = problem.scene.robot.dof
    if max_velocity is not None:
        max_velocity = limit_vector(max_velocity, dof, "max_velocity", "rad/s")
    if max_acceleration is not None:
        max_acceleration = limit_vector(max_acceleration, dof, "max_acceleration", "rad/s²")
    model = resolve_model(collision, problem.scene, weights)
    goal = problem.goal if problem.goal is not None else solve_ik(problem, seed)
    if solver == "ipopt":
        run = _plan_ipopt(problem, model, goal, opts, seed)
    elif solver == "adam":
        run = _plan_adam(problem, model, goal, opts)
    else:
        raise InputError(f"solver: unknown {solver!r}; choose 'ipopt' or 'adam'")
    result = _finish(problem, run, t0)
    trajectory, note = plan_timing(
        problem.scene, result.q, result.success, max_velocity, max_acceleration
    )
    reason = f"{result.reason}; {note}".strip("; ") if note else result.reason
    return replace(result, trajectory=trajectory, reason=reason)


def _check_sizes(problem: Problem, opts: TrajoptOptions, solver: str) -> None:
    """InputError when the first solve would exceed ``MAX_CHECK_POINTS`` check points."""
    default = IPOPT_INTERPOLATED if solver == "ipopt" else ADAM_INTERPOLATED
    per_segment = (default if opts.interpolated is None else opts.interpolated) + opts.starts
    total = (problem.waypoints - 1) * per_segment
    if total > MAX_CHECK_POINTS:
        raise InputError(
            f"options.waypoints × solver.interpolated: {total} check points, the limit is "
            f"{MAX_CHECK_POINTS}; use fewer waypoints or check points"
        )


@dataclass
class _Run:
    """What a solver hands back before verification."""

    q: np.ndarray
    iterations: int = 0
    status: str = ""
    reason: str = ""
    model_calls: int = 0
    attempts: int = 0
    verified: Certificate | None = None  # the certificate of q at margin 0, when made


def _finish(problem: Problem, run: _Run, t0: float) -> Plan:
    """Certify the path with coal, check the goal, package the Plan."""
    cert = run.verified or certify_path(problem.scene, run.q, margin=0.0)
    reached = _goal_error(problem, run.q[-1]) <= problem.goal_tolerance
    reason = run.reason
    if not cert.ok:
        reason = (
            f"{reason}; coal certificate failed: {cert.reason} "
            f"(smallest checked distance {cert.min_distance:+.4f} m)"
        )
    elif not reached:
        reason = f"{reason}; goal not reached"
    verdict = f"ok, clearance ≥ {cert.lower_bound:+.4f} m" if cert.ok else "not proven"
    log.info("certify: coal certificate %s%s", verdict, "" if reached else "; goal not reached")
    return Plan(
        success=bool(cert.ok and reached),
        q=run.q,
        min_distance=cert.lower_bound,
        solve_time=time.perf_counter() - t0,
        iterations=run.iterations,
        status=run.status,
        reason=reason.lstrip("; "),
        path_cost=path_cost(run.q),
        model_calls=run.model_calls,
        attempts=run.attempts,
        sampled_min_distance=cert.min_distance,
    )


def _goal_error(problem: Problem, q: np.ndarray) -> float:
    """Joint-space (rad, ∞-norm) or end-effector (m) distance of q to the goal."""
    if problem.goal is not None:
        return float(np.max(np.abs(q - problem.goal)))
    return float(np.linalg.norm(tip_position(problem.scene.robot, q)[0] - problem.goal_position))


def straight_line(start: np.ndarray, goal: np.ndarray, n: int) -> np.ndarray:
    """(n, dof) evenly spaced joint-space interpolation from start to goal."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    return start + s * (goal - start)


# -------------------------------------------------------------------- Ipopt
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

    Each round that the coal certificate rejects doubles the check points of the rejected
    segments and, for a learned model, raises the constraint margin by the model's observed
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
    margin = problem.margin + (opts.learned_margin if learned else 0.0)
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
        cert = certify_path(problem.scene, q, margin=0.0)
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
            over = model_overestimate(problem.scene, model, q, bad, problem.margin)
            raised[_near_segments(bad, len(splits), opts.raise_window)] += over
    return q, stats, False


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


def _interpolated(opts: TrajoptOptions, default: int) -> int:
    """Check points strictly inside each segment: ``opts.interpolated`` or the solver's default."""
    return _count(default if opts.interpolated is None else opts.interpolated, "interpolated")


def _count(value, name: str) -> int:
    """``value`` if it is an integer ≥ 0, else InputError naming the option."""
    if not isinstance(value, int) or value < 0:
        raise InputError(f"{name}: expected an integer ≥ 0 or None, got {value!r}")
    return value


def model_overestimate(
    scene: Scene, model: DistanceModel, q: np.ndarray, segments: list[int], margin: float
) -> float:
    """How much a learned model overestimates the distance where coal finds the path too close.

    Samples the given waypoint segments of q (T, dof) densely (20 points each) and returns
    max(d̂ − d_coal) over the points with d_coal < margin, at least 5 mm (m).
    """
    t = np.linspace(0.0, 1.0, 21)[:, None]
    points = np.concatenate([q[i] + t * (q[i + 1] - q[i]) for i in segments])
    d_coal = signed_distance(scene, points)
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
    never pass. Ipopt keeps the plain margin and has no rows at q_e (module docstring): with
    these bounds it optimised the fetch reach-in to a path cost of 0.09 but took 47 s and
    hugged the storage (coal clearance 0.4 mm).
    """
    bounds = np.full(int(np.sum(splits)) + 1, margin)
    if isinstance(model, CoalModel):
        return bounds
    d_ends = model.distance(problem.scene, np.stack([problem.start, goal]))
    first, last = slice(0, int(splits[0])), slice(len(bounds) - 1 - int(splits[-1]), None)
    for part, d_end in ((first, d_ends[0]), (last, d_ends[1])):
        bounds[part] = np.minimum(bounds[part], d_end - slack)
    return bounds


class _Transcription:
    """The NLP of the module docstring for one set of check points (segment t split in
    ``splits[t]`` pieces); rebuilt when the certificate refines them."""

    def __init__(
        self,
        problem: Problem,
        model: DistanceModel,
        goal,
        opts,
        splits: np.ndarray,
        margin: float | np.ndarray,
        warm: bool = False,
    ):
        robot = problem.scene.robot
        T, n = problem.waypoints, robot.dof
        self.problem, self.goal, self.T, self.splits = problem, goal, T, splits
        self.duals: tuple[np.ndarray, np.ndarray] | None = None
        x = casadi.MX.sym("x", (T - 2) * n)
        Q = casadi.vertcat(
            casadi.DM(problem.start).T, casadi.reshape(x, n, T - 2).T, casadi.DM(goal).T
        )  # (T, n)
        inner = slice(1, -1)  # the fixed start and goal are no rows (module docstring)
        W = casadi.sparsify(casadi.DM(_interpolation_matrix(splits)[inner]))  # (K, T)
        P = casadi.mtimes(W, Q)  # (K, n) check points along the path
        K = W.shape[0]
        self.callback = DistanceCallback(
            "distance", model, problem.scene, K, opts.per_link, opts.link_cap
        )
        rows = self.callback.rows
        d = self.callback(casadi.reshape(P.T, K * n, 1))  # (K·R,)
        steps = Q[1:, :] - Q[:-1, :]  # (T−1, n)
        g = casadi.vertcat(d, casadi.reshape(steps, (T - 1) * n, 1))
        n_steps = (T - 1) * n
        margins = np.repeat(np.broadcast_to(margin, (K,)), rows)  # check point by check point
        self.lbg = np.concatenate([margins, np.full(n_steps, -problem.max_step)])
        self.ubg = np.concatenate([np.full(K * rows, np.inf), np.full(n_steps, problem.max_step)])
        self.lbx = np.tile(problem.lower, T - 2)
        self.ubx = np.tile(problem.upper, T - 2)
        f = casadi.sumsqr(steps)
        ipopt = {
            "hessian_approximation": "limited-memory",
            # L-BFGS's initial matrix σ I with σ = sᵀy / sᵀs of the last step (Ipopt's
            # "scalar2"): on the (d) problems the line search then rarely backtracks, median
            # 63 instead of 100 constraint evaluations with GraphDistNet (benchmarks/RESULTS.md)
            "limited_memory_initialization": "scalar2",
            "print_level": 0,
            "max_iter": opts.max_iter,
            "tol": opts.tol,
            "acceptable_tol": 1e3,  # stop on objective stagnation + feasibility
            "acceptable_iter": 3,
            "acceptable_obj_change_tol": opts.obj_change_tol,
            "acceptable_constr_viol_tol": 1e-5,
            "mu_strategy": "adaptive",
            "sb": "yes",  # no banner: stdout stays clean for --json
        }
        ipopt.update(opts.ipopt)
        if warm:  # a refine round: start from the last round's primal-dual point
            ipopt.update(WARM_START_OPTIONS)
        self.solver = casadi.nlpsol(
            "trajopt",
            "ipopt",
            {"x": x, "f": f, "g": g},
            {"ipopt": ipopt, "print_time": False, "error_on_fail": False},
        )

    def solve(
        self, guess: np.ndarray, duals: tuple[np.ndarray, np.ndarray] | None = None
    ) -> tuple[np.ndarray, dict]:
        """Solve from an initial guess (T, dof) and, for a warm start, multipliers
        (λ_g, λ_x); returns the waypoints (T, dof) and Ipopt stats."""
        x0 = np.clip(guess[1:-1], self.problem.lower, self.problem.upper).ravel()
        bounds = {"lbx": self.lbx, "ubx": self.ubx, "lbg": self.lbg, "ubg": self.ubg}
        if duals is not None:
            bounds.update(lam_g0=duals[0], lam_x0=duals[1])
        try:
            sol = self.solver(x0=x0, **bounds)
        except RuntimeError as e:
            return guess, {"return_status": f"exception: {str(e).splitlines()[-1]}"[:200]}
        self.duals = (np.asarray(sol["lam_g"]).ravel(), np.asarray(sol["lam_x"]).ravel())
        inner = np.asarray(sol["x"]).reshape(self.T - 2, -1)
        stats = self.solver.stats()
        return np.vstack([self.problem.start, inner, self.goal]), stats

    def duals_on(self, refined: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """The last solution's multipliers (λ_g, λ_x) for the NLP with check points ``refined``
        (a refinement of ``self.splits``): check points of both keep their distance rows'
        multipliers, new ones start at 0; step rows and bounds keep theirs."""
        if self.duals is None:
            return None
        lam_g, lam_x = self.duals
        old, new = _path_parameters(self.splits)[1:-1], _path_parameters(refined)[1:-1]
        rows = self.callback.rows
        lam_d = lam_g[: len(old) * rows].reshape(len(old), rows)
        where = dict(zip(old.tolist(), range(len(old)), strict=True))
        lam_new = np.zeros((len(new), rows))
        for i, s_i in enumerate(new.tolist()):
            if s_i in where:
                lam_new[i] = lam_d[where[s_i]]
        return np.concatenate([lam_new.ravel(), lam_g[len(old) * rows :]]), lam_x


def _path_parameters(splits: np.ndarray) -> np.ndarray:
    """(Σ n_t + 1,) path parameter t + i / n_t of every check point of :func:`_interpolation_matrix`
    (waypoint t at t)."""
    parts = [t + np.arange(n_t) / n_t for t, n_t in enumerate(splits)]
    return np.concatenate([*parts, [float(len(splits))]])


def _interpolation_matrix(splits: np.ndarray) -> np.ndarray:
    """(Σ n_t + 1, T) weights: row k of W·Q is the k-th check point along the path, with
    segment t split into n_t = splits[t] pieces."""
    T = len(splits) + 1
    rows = []
    for t, n_t in enumerate(splits):
        for i in range(n_t):
            w = np.zeros(T)
            w[t], w[t + 1] = 1 - i / n_t, i / n_t
            rows.append(w)
    last = np.zeros(T)
    last[-1] = 1.0
    rows.append(last)
    return np.array(rows)


# -------------------------------------------------------------------- Adam (the paper's)
def collision_cost(
    d: np.ndarray, margin: float | np.ndarray, c: float, eps: float
) -> tuple[np.ndarray, np.ndarray]:
    """The paper's C(d) = c / ((d − d_margin)² + ε) for d ≥ d_margin and its derivative.

    Below the margin the paper's form would fall again (pushing deeper into collision), so
    there C continues linearly with slope −c/ε per metre: C = c/ε + (c/ε)(d_margin − d)/√ε.
    """
    gap = d - margin
    above = gap >= 0
    slope = c / eps / math.sqrt(eps)
    cost = np.where(above, c / (gap**2 + eps), c / eps - slope * gap)
    dcost = np.where(above, -2 * c * gap / (gap**2 + eps) ** 2, -slope)
    return cost, dcost


def _plan_adam(problem: Problem, model: DistanceModel, goal: np.ndarray, opts) -> _Run:
    """Adam on the interior waypoints of Σ_k C(d(p_k)) + Σ_t ‖q_{t+1} − q_t‖², from the
    straight line, until the collision cost falls below the threshold — every term below
    C(margin + adam_stop), i.e. min_k d(p_k) ≥ margin + adam_stop as C decreases above the
    margin — or the iteration cap. With ``ccd``, reaching the threshold triggers the continuous
    certificate; uncertified segments get twice the check points and Adam continues. The
    margin of each check point is that of :func:`distance_bounds` (relaxed next to an endpoint
    a learned model rates below the margin)."""
    T = problem.waypoints
    splits = np.full(T - 1, _interpolated(opts, ADAM_INTERPOLATED) + 1)
    W = _interpolation_matrix(splits)
    slack = opts.adam_stop + 0.005  # the fixed endpoints must pass the stop test
    lower = distance_bounds(problem, model, goal, splits, problem.margin, slack)
    q = straight_line(problem.start, goal, T)
    m, v = np.zeros_like(q), np.zeros_like(q)
    b1, b2 = 0.9, 0.999
    calls, refinements, status = 0, 0, "adam: iteration cap"
    for it in range(1, opts.adam_iterations + 1):
        d, g = model.distance_and_grad(problem.scene, W @ q)
        calls += 1
        if np.all(d >= lower + opts.adam_stop):
            cert = certify_path(problem.scene, q) if opts.ccd else None
            if cert is None or cert.ok or refinements == opts.refine_rounds:
                status = "adam: cost below threshold"
                break
            splits[list(cert.bad_segments)] *= 2
            W, refinements = _interpolation_matrix(splits), refinements + 1
            lower = distance_bounds(problem, model, goal, splits, problem.margin, slack)
            continue
        _, dc = collision_cost(np.asarray(d), lower, opts.adam_c, opts.adam_eps)
        grad = W.T @ (dc[:, None] * g)
        grad[1:] += 2 * (q[1:] - q[:-1])
        grad[:-1] -= 2 * (q[1:] - q[:-1])
        grad[[0, -1]] = 0.0
        m = b1 * m + (1 - b1) * grad
        v = b2 * v + (1 - b2) * grad**2
        step = opts.adam_lr * (m / (1 - b1**it)) / (np.sqrt(v / (1 - b2**it)) + 1e-8)
        q = np.clip(q - step, problem.lower, problem.upper)
    log.info("solve: %s, %d iterations", status, it)
    return _Run(q=q, iterations=it, status=status, reason=status, model_calls=calls, attempts=1)


__all__ = [
    "Plan",
    "Problem",
    "TrajoptOptions",
    "collision_cost",
    "distance_bounds",
    "first_joint_barrier",
    "path_cost",
    "plan",
    "solve_ik",
    "straight_line",
    "tip_position",
    "verify_path",
]
