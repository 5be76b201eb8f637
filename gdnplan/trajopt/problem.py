"""The planning problem: :class:`Problem`, its checks (limits, feasibility of the start and
goal) and its construction from a problem file.

A problem's scene is a planar :class:`~gdnplan.scene.Scene` or a 3-D
:class:`~gdnplan.arm3d.Scene3D`; everything the planner asks of it goes through
:mod:`gdnplan.exact`. The planar-only parts are a ``goal_position`` (and its reach) and the
first-joint sweep test; a 3-D goal is a joint vector.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..arm3d.scene3d import Scene3D
from ..arm3d.scene_file3d import pose_goal
from ..assets import problem_file
from ..ccd import proven_distance
from ..errors import InfeasibleProblemError, InputError, ProblemFileError
from ..exact import closest_pair, exact_distance, swept_radius_of
from ..limits import MAX_WAYPOINTS, check_int, check_number, is_number, plain_fields, shown
from ..robot import first_outside
from ..scene import Scene
from .config import PlanConfig
from .ik import first_joint_barrier, tip_reach
from .options import TrajoptOptions
from .problem_file import ProblemTables, _vector, problem_tables, read_problem_file

POSE_GOAL_SPARE = 1e-3  # m: a pose goal's IK keeps the margin plus this (coal's slack)


def check_reachable_in_steps(start, goal, max_step: float, waypoints: int) -> None:
    """InputError naming ``options.max_step`` when T = ``waypoints`` cannot reach ``goal``
    from ``start`` (rad) with steps of at most ``max_step`` (rad) per joint:
    max_step · (T − 1) < the largest joint distance; it says how many waypoints would."""
    gap = np.abs(np.asarray(goal, float) - np.asarray(start, float))
    j = int(np.argmax(gap))
    need = float(gap[j])
    if need <= max_step * (waypoints - 1) * (1 + 1e-12):
        return
    ratio = need / max_step  # may be huge (max_step = 1e-300) or inf: never an int then
    wanted = f"{math.ceil(ratio) + 1}" if ratio < 1e15 else f"{ratio:.3g}"
    wanted = wanted if math.isfinite(ratio) else "more than any"
    raise InputError(
        f"options.max_step: {max_step:g} rad per step cannot reach the goal in "
        f"{waypoints} waypoints ({waypoints - 1} steps): joint {j} moves {need:.4g} rad from "
        f"start to goal, which needs {wanted} waypoints (options.waypoints ≤ {MAX_WAYPOINTS}); "
        f"raise max_step to at least {need / (waypoints - 1):.4g} rad or add waypoints"
    )


@dataclass(frozen=True, eq=False)
class Problem:
    """A planning problem: move the robot of ``scene`` from ``start`` to a goal.

    Attributes:
        scene: robot and obstacles, planar (:class:`~gdnplan.scene.Scene`) or 3-D
            (:class:`~gdnplan.arm3d.Scene3D`).
        start: (dof,) start joint angles (rad).
        goal: (dof,) goal joint angles (rad), or None when ``goal_position`` is given.
        goal_position: (2,) end-effector goal in the plane (m), or None (planar scenes only).
        waypoints: 3 ≤ T ≤ ``limits.MAX_WAYPOINTS`` (500), waypoints including start and goal.
        margin: required clearance (m): the NLP keeps d ≥ margin at its check points, and a
            successful plan is proven to keep d > ``certified_clearance`` (the margin unless
            ``clearance`` asks for less) on the whole continuous path.
        max_step: largest change of any joint between consecutive waypoints (rad).
        goal_tolerance: end-effector position error accepted for ``goal_position`` (m).
        lower: (dof,) lower joint limits (rad), within the robot's; the robot's when None.
        upper: (dof,) upper joint limits (rad), within the robot's; the robot's when None.
        solver: the planner settings this problem needs (a problem file's ``[seed]``,
            ``[refine]``, ``[ipopt]`` / ``[adam]`` tables, e.g. short RRT-Connect steps for a
            narrow passage), a :class:`~gdnplan.trajopt.config.PlanConfig`; :func:`plan` uses
            them unless given others. None: the defaults. (A TrajoptOptions is deprecated and
            converted.)
        clearance: the clearance (m) a successful plan's coal certificate must prove along the
            whole continuous path, 0 ≤ clearance ≤ margin; None: the margin. Ask for less than
            the margin (e.g. 0: proven collision-free) to accept paths that dip below the
            margin between check points.
    """

    scene: Scene | Scene3D
    start: np.ndarray
    goal: np.ndarray | None = None
    goal_position: np.ndarray | None = None
    waypoints: int = 20
    margin: float = 0.02
    max_step: float = 1.0
    goal_tolerance: float = 1e-3
    lower: np.ndarray = field(default=None)  # type: ignore[assignment]
    upper: np.ndarray = field(default=None)  # type: ignore[assignment]
    solver: PlanConfig | None = None
    clearance: float | None = None

    @property
    def certified_clearance(self) -> float:
        """The clearance a successful plan is proven to keep (m): ``clearance``, or the margin
        when it is None."""
        return self.margin if self.clearance is None else self.clearance

    def __post_init__(self) -> None:
        plain_fields(self)  # numpy scalars as Python values (numpy integers wrap)
        if not isinstance(self.scene, (Scene, Scene3D)):
            raise InputError(
                f"scene: expected a planar Scene or a Scene3D, got {type(self.scene).__name__}"
            )
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
        elif isinstance(self.scene, Scene3D):
            raise InputError(
                "goal.position: a 3-D problem's goal is a joint vector q (end-effector pose "
                "goals come with the 3-D pose IK)"
            )
        else:
            set_(self, "goal_position", _vector(self.goal_position, 2, "goal.position"))
        check_int(self.waypoints, "options.waypoints", 3, MAX_WAYPOINTS)
        check_number(self.margin, "options.margin")
        self._check_clearance()
        check_number(self.max_step, "options.max_step", strict=True)
        check_number(self.goal_tolerance, "options.goal_tolerance", strict=True)
        self._check_limits()
        if isinstance(self.solver, TrajoptOptions):  # deprecated (it warned when made)
            set_(self, "solver", self.solver.to_config())
        if self.solver is not None and not isinstance(self.solver, PlanConfig):
            raise InputError(f"solver: expected a PlanConfig, got {type(self.solver).__name__}")
        self._check_feasible()
        if self.goal is not None:  # after the limits: a goal outside them is named first
            check_reachable_in_steps(self.start, self.goal, self.max_step, self.waypoints)

    def _check_clearance(self) -> None:
        """clearance: None or a finite number in [0, margin]."""
        if self.clearance is None:
            return
        if not (is_number(self.clearance) and math.isfinite(self.clearance)):
            raise InputError(
                f"options.clearance: expected a finite number in [0, margin] (m), got "
                f"{shown(self.clearance)}; leave it out to certify the margin"
            )
        if not 0 <= self.clearance <= self.margin:
            raise InputError(
                f"options.clearance: {self.clearance!r} m is outside [0, options.margin = "
                f"{self.margin!r} m]; the certified clearance is at most the margin (raise "
                "options.margin, or leave clearance out to certify the margin)"
            )
        object.__setattr__(self, "clearance", float(self.clearance))

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
        swept = swept_radius_of(self.scene)
        for name, q in named:
            j = first_outside(q, self.lower, self.upper)
            if j is not None:
                raise InfeasibleProblemError(
                    f"{name}[{j}] = {q[j]:.4g} is outside the joint limits "
                    f"[{self.lower[j]:.4g}, {self.upper[j]:.4g}]"
                )
            d = float(exact_distance(self.scene, q, margin=self.margin)[0])
            if d <= self.margin or proven_distance(d, swept) <= self.certified_clearance:
                raise InfeasibleProblemError(
                    f"{name} is in collision: distance {d:.4f} m ≤ margin {self.margin} m between "
                    f"{closest_pair(self.scene, q, margin=self.margin)}; move it away or lower "
                    "options.margin"
                )
        if self.goal is not None and isinstance(self.scene, Scene):
            blocked = first_joint_barrier(self.scene, self.start[0], self.goal[0])
            if blocked is not None:
                raise InfeasibleProblemError(
                    f"start.q[0] -> goal.q[0]: the first link collides at joint 1 = {blocked:.3f} "
                    "rad, which every motion between them must pass (joints do not wrap)"
                )
        if self.goal_position is not None:
            robot = self.scene.robot
            base = np.asarray(robot.chain.joint_origins[0], float)[:2]
            r = math.hypot(*(self.goal_position - base))  # no overflow for [1e300, 0.5]
            if r > tip_reach(robot):
                raise InfeasibleProblemError(
                    f"goal.position {self.goal_position.tolist()} is out of reach: "
                    f"{r:.4g} m from the base, the tip reaches {tip_reach(robot):.3f} m; give "
                    "a position within reach (metres)"
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
        return cls.from_tables(problem_tables(cfg, base_dir))

    @classmethod
    def from_tables(cls, tables: ProblemTables) -> Problem:
        """Problem from a file's checked tables
        (:func:`~gdnplan.trajopt.problem_file.problem_tables`)."""
        goal = dict(tables.goal or {})
        try:
            if "pose" in goal:  # a 3-D tool pose: its IK nearest the start, clear of the margin
                start = _vector(tables.start, tables.scene.robot.dof, "start.q")
                margin = tables.options.get("margin", cls.margin)
                margin = check_number(margin, "options.margin") + POSE_GOAL_SPARE
                goal["q"] = pose_goal(tables.scene, goal.pop("pose"), start, margin)
            return cls(
                scene=tables.scene,
                start=tables.start,
                goal=goal.get("q"),
                goal_position=goal.get("position"),
                solver=tables.solver,
                **tables.options,
            )
        except InputError as e:
            raise ProblemFileError(str(e)) from e
