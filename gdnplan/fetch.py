"""The UR5e fetch sequence (paper §V-C): reach into the storage, grasp the stick, bring it out.

Stages, from the configurations of the fetch scene's ``info`` (:func:`gdnplan.ur5e.fetch_scene`):

============ ======================= ========= =========================================
stage        motion                  gripper   how
============ ======================= ========= =========================================
approach     q_home → q_pregrasp     open      planned (:func:`gdnplan.trajopt.plan`)
reach_in     q_pregrasp → q_grasp    open      planned
grasp        q_grasp                 holding   the gripper closes: the stick leaves the
                                               obstacles and becomes a robot polygon
lift         q_grasp → q_lift        holding   scripted: the tcp rises LIFT = 0.02 m along
                                               a vertical line (planar IK), since the stick
                                               starts resting on its shelf (d = 0)
bring_out    q_lift → q_out          holding   planned
retreat      q_out → q_home          holding   planned
============ ======================= ========= =========================================

Planned stages use ``margin`` (m) as their clearance: a planned stage succeeds when the coal
certificate of :func:`gdnplan.ccd.certify_path` proves d > margin on the whole continuous path
(:attr:`gdnplan.trajopt.Plan.success`). The
lift is certified clear from its second point on (tcp 2 mm above the shelf, ``certified_from``
= 1): its start is the contact the grasp makes by design (d = 0), where no clearance can be
proven; its first segment, and the grasp itself, are proven never to penetrate by more than
:data:`~gdnplan.ccd_contact.CONTACT_ALLOWANCE` (:func:`gdnplan.ccd_contact.certify_from_contact`).
Its ``min_distance`` is the smallest coal distance over its whole path (0 at that contact),
``certified_min_distance`` the proven lower bound over the rows certified clear.
"""

from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from .ccd import verify_path
from .ccd_contact import certify_from_contact, contact_detail
from .distance import signed_distance
from .errors import InfeasibleProblemError, InputError
from .models import DistanceModel
from .scene import Scene, make_scene
from .timing import time_path, urdf_velocity
from .trajopt import Plan, PlanConfig, Problem, plan, resolve_model
from .trajopt.problem_file import plan_config_from_tables, read_problem_file
from .ur5e import LIFT, analytic_ik

log = logging.getLogger(__name__)  # one INFO line per finished stage

STAGES = ("approach", "reach_in", "grasp", "lift", "bring_out", "retreat")
LIFT_POINTS = 11  # IK points on the lift line, 2 mm apart
BRING_OUT_PROBLEM = "fetch_bring_out"  # the shipped problem whose planner tables bring-out uses


@cache
def bring_out_config() -> PlanConfig:
    """The bring-out stage's planner settings: the ``[seed]``/``[ipopt]`` tables of
    ``problems/fetch_bring_out.toml`` (the held stick threads the entrance: short RRT-Connect
    steps, a longer RRT time, three check points per segment; the file says why)."""
    config = plan_config_from_tables(read_problem_file(BRING_OUT_PROBLEM))
    assert config is not None, f"{BRING_OUT_PROBLEM}: no planner tables"
    return config


def __getattr__(name: str):
    if name == "BRING_OUT_OPTIONS":
        warnings.warn(
            "gdnplan.fetch.BRING_OUT_OPTIONS is deprecated; use gdnplan.fetch.bring_out_config()",
            DeprecationWarning,
            stacklevel=2,
        )
        return bring_out_config()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass(frozen=True)
class Stage:
    """One stage of the fetch sequence.

    Attributes:
        name: one of STAGES.
        scene: the scene the stage moves in (its robot carries the gripper state).
        q: (T, 3) joint path (rad); a single configuration repeated for ``grasp``.
        success: certified collision-free (planned stages: :class:`~gdnplan.trajopt.Plan`'s
            success; grasp: the closed gripper holds the stick, proven not to penetrate the
            shelf; lift: certified off the shelf).
        min_distance: the smallest coal distance along the stage's whole path q (m): the
            certificate's proven lower bound when it covers all of q (planned stages; −inf when
            it could not prove one); grasp: coal's distance at the grasp; lift: the smaller of
            the smallest coal distance the contact certificate checked on its first segment
            (0 at the resting contact; the segment proven > −CONTACT_ALLOWANCE) and the proven
            bound over the rest.
        certified_from: the first row of q the continuous certificate covers (0: all of it;
            lift: 1), None when there is no certificate (grasp: one configuration).
        certified_min_distance: the certificate's proven lower bound over q[certified_from:]
            (m; None: min_distance when certified_from is 0).
        solve_time: wall time of the stage (s).
        planned: True when solved by :func:`~gdnplan.trajopt.plan`.
        detail: the planner's reason, or what a scripted stage did.
        times: (T,) time of each row of q from the stage's start (s): the plan's
            (:attr:`~gdnplan.trajopt.Plan.times`) or, scripted, the URDF velocity limits along
            the path (grasp: 0, 0); None for a failed planned stage.
    """

    name: str
    scene: Scene
    q: np.ndarray
    success: bool
    min_distance: float
    solve_time: float
    planned: bool
    detail: str
    times: np.ndarray | None = None
    certified_from: int | None = 0
    certified_min_distance: float | None = None

    def summary(self) -> dict:
        """JSON-ready summary (q as lists, t the times of its rows or null); non-finite
        distances are null."""
        proven = self.certified_min_distance
        if proven is None and self.certified_from == 0:
            proven = self.min_distance
        return {
            "stage": self.name,
            "gripper": self.scene.robot.info["gripper"],
            "success": bool(self.success),
            "min_distance": _json_distance(self.min_distance),
            "certified_from": self.certified_from,
            "certified_min_distance": None if proven is None else _json_distance(proven),
            "solve_time": float(self.solve_time),
            "planned": self.planned,
            "detail": self.detail,
            "joint_names": self.scene.robot.joint_names,
            "q": np.asarray(self.q).tolist(),
            "t": None if self.times is None else np.asarray(self.times).tolist(),
        }


def _json_distance(d: float) -> float | None:
    return float(d) if np.isfinite(d) else None


def fetch_scenes(seed: int = 0) -> dict[str, Scene]:
    """The fetch scene of ``seed`` with the gripper ``open`` and ``holding`` the stick."""
    return {g: make_scene("fetch", seed=seed, gripper=g) for g in ("open", "holding")}


def stage_problem(
    scene: Scene,
    start: np.ndarray,
    goal: np.ndarray,
    margin: float = 0.01,
    waypoints: int = 30,
    solver: PlanConfig | None = None,
) -> Problem:
    """A joint-space problem start → goal (3,) in ``scene`` with clearance ``margin`` (m) and
    the stage's own ``solver`` settings (None: the defaults)."""
    return Problem(
        scene=scene, start=start, goal=goal, waypoints=waypoints, margin=margin, solver=solver
    )


def lift_path(scene: Scene, n: int = LIFT_POINTS) -> np.ndarray:
    """(n, 3) IK path of the tcp from the grasp straight up by LIFT, nearest branch to q_grasp.

    Points p_k = grasp + (0, k · LIFT / (n − 1), 0), k = 0 … n − 1; each solved with
    :func:`gdnplan.ur5e.analytic_ik` and the solution nearest the previous configuration kept.
    """
    grasp = scene.info["layout"].grasp_target()
    path = [scene.info["q_grasp"]]
    for k in range(1, n):
        target = grasp + np.array([0.0, k * LIFT / (n - 1), 0.0])
        candidates = analytic_ik(scene.robot, target)
        if not candidates:
            raise InfeasibleProblemError(f"lift: no IK solution {k * LIFT / (n - 1):.3f} m up")
        path.append(min(candidates, key=lambda q: float(np.abs(q - path[-1]).sum())))
    return np.array(path)


def _lift(held: Scene) -> Stage:
    """The scripted lift: rows 1… certified clear (proven > 0); the first segment, leaving the
    resting contact at row 0, proven > −CONTACT_ALLOWANCE (:mod:`gdnplan.ccd_contact`)."""
    t0 = time.perf_counter()
    path = lift_path(held)
    ok, proven = verify_path(held, path[1:])
    leave = certify_from_contact(held, path[:2])
    up = 1000 * LIFT / (LIFT_POINTS - 1)
    detail = (
        f"scripted vertical lift of {LIFT} m; rows 1… ({up:.0f} mm up and above) certified, "
        f"proven d ≥ {proven:.4g} m; row 0 is the stick resting on its shelf (coal d = "
        f"{float(signed_distance(held, path[0])[0]):.3g} m), the first segment "
        + contact_detail(leave)
    )
    times = _scripted_times(held, path)
    dt = time.perf_counter() - t0
    low = min(leave.min_distance, proven)
    return Stage("lift", held, path, ok and leave.ok, low, dt, False, detail, times, 1, proven)


def _planned(
    name: str,
    problem: Problem,
    collision: str | DistanceModel,
    weights: str | Path | None,
) -> Stage:
    """Solve one stage with :func:`~gdnplan.trajopt.plan`."""
    r: Plan = plan(problem, collision=collision, weights=weights)
    scene = problem.scene
    return Stage(name, scene, r.q, r.success, r.min_distance, r.solve_time, True, r.reason, r.times)


def _scripted_times(scene: Scene, path: np.ndarray) -> np.ndarray:
    """(T,) times of a scripted path at the URDF velocity limits (s)."""
    return time_path(path, urdf_velocity(scene.robot)).times


def run_fetch(
    seed: int = 0,
    collision: str | DistanceModel = "graphdistnet",
    weights: str | Path | None = None,
    margin: float = 0.01,
    stages: tuple[str, ...] = STAGES,
) -> list[Stage]:
    """Run the fetch sequence (or the listed ``stages`` of it, in order) on fetch ``seed``.

    Every stage is run even when an earlier one failed (each starts from its own configuration
    of ``scene.info``), so a failure is reported per stage; each finished stage is logged
    (``gdnplan.fetch`` logger, INFO).
    """
    scenes = fetch_scenes(seed)
    open_, held = scenes["open"], scenes["holding"]
    info = open_.info
    if isinstance(collision, str):  # resolve (load weights) once for every planned stage
        collision, weights = resolve_model(collision, open_, weights), None
    out = []
    for name in stages:
        if name == "approach":
            problem = stage_problem(open_, info["q_home"], info["q_pregrasp"], margin)
            out.append(_planned(name, problem, collision, weights))
        elif name == "reach_in":
            problem = stage_problem(open_, info["q_pregrasp"], info["q_grasp"], margin)
            out.append(_planned(name, problem, collision, weights))
        elif name == "grasp":
            t0 = time.perf_counter()
            d = float(signed_distance(held, info["q_grasp"])[0])
            at_grasp = np.array([info["q_grasp"]] * 2)
            out.append(
                Stage(
                    name,
                    held,
                    at_grasp,
                    certify_from_contact(held, at_grasp[:1]).ok,
                    d,
                    time.perf_counter() - t0,
                    False,
                    f"gripper closed on a {held.robot.info['stick_length']:.3f} m × "
                    f"{held.robot.info['stick_width']:.3f} m stick; it rests on its shelf "
                    f"(d = {d:.4f} m)",
                    _scripted_times(held, at_grasp),
                    None,
                )
            )
        elif name == "lift":
            out.append(_lift(held))
        elif name == "bring_out":
            problem = stage_problem(
                held, info["q_lift"], info["q_out"], margin, solver=bring_out_config()
            )
            out.append(_planned(name, problem, collision, weights))
        elif name == "retreat":
            problem = stage_problem(held, info["q_out"], info["q_home"], margin)
            out.append(_planned(name, problem, collision, weights))
        else:
            raise InputError(f"stages: unknown stage {name!r}; choose from {STAGES}")
        done = out[-1]
        how = "planned" if done.planned else "scripted"
        verdict = "certified" if done.success else "FAILED"
        log.info("fetch stage %s: %s, %s, %.2f s", name, how, verdict, done.solve_time)
    return out


def stick_clearance(scene: Scene, path: np.ndarray, per_segment: int = 20) -> float:
    """Smallest coal distance (m) of the held stick alone to the obstacles along ``path``.

    The path (T, 3) is interpolated linearly with ``per_segment`` points per segment; the
    stick is the robot polygon named ``stick`` (per-link signed distance).
    """
    names = [p.name for p in scene.robot.polygons]
    if "stick" not in names:
        raise InputError("stick_clearance: the robot holds no stick")
    t = np.linspace(0.0, 1.0, per_segment, endpoint=False)
    dense = (path[:-1, None] + t[None, :, None] * np.diff(path, axis=0)[:, None]).reshape(-1, 3)
    dense = np.vstack([dense, path[-1:]])
    return float(signed_distance(scene, dense, per_link=True)[:, names.index("stick")].min())
