"""The 3-D fetch sequence: the full UR5e takes the stick out of its storage, every stage certified.

Stages, from the configurations of :func:`gdnplan.arm3d.fetch3d_scene.fetch3d`:

============ ======================= ========= =========================================
stage        motion                  gripper   how
============ ======================= ========= =========================================
approach     q_home → q_pregrasp     open      planned (:func:`gdnplan.trajopt.plan`)
reach_in     q_pregrasp → q_grasp    open      planned, piece by piece between knots
                                               0.1 m apart on the tcp's straight line
                                               through the entrance (``fetch.lines``)
grasp        q_grasp                 holding   the fingers close on the stick, which
                                               becomes a shape of the robot; it rests on
                                               its shelf (d = 0 by construction)
lift         q_grasp → q_lift        holding   scripted: the tcp rises LIFT = 0.02 m on a
                                               straight line (pose IK), certified from its
                                               second point on (2 mm up, certified_from 1)
bring_out    q_lift → q_out          holding   planned, the stick back out through the
                                               entrance, piece by piece between knots
retreat      q_out → q_home          holding   planned
============ ======================= ========= =========================================

Planned stages are :class:`gdnplan.trajopt.Problem` s on the stage's Scene3D with clearance
``margin`` (m) and coal's exact distance (:func:`stage_problems`); a piece succeeds when the
coal certificate (:func:`gdnplan.arm3d.certify_path3d`) proves d > margin on its whole
continuous path (obstacles and self-collision, the held stick included), a stage when every
piece does (the pieces share their ends, so the stage's path is certified). The lift starts at
the stick's resting contact (d = 0), where no certificate proves a clearance: its first
segment, and the grasp, are proven never to penetrate by more than
:data:`~gdnplan.ccd_contact.CONTACT_ALLOWANCE` (:func:`gdnplan.ccd_contact.certify_from_contact`);
its ``min_distance`` is the smallest coal distance over its whole path (0 there),
``certified_min_distance`` the proven lower bound over rows ``certified_from`` = 1 on.
"""

from __future__ import annotations

import itertools
import logging
import time
from dataclasses import dataclass

import numpy as np

from ..ccd_contact import certify_from_contact, contact_detail
from ..errors import InputError
from ..trajopt import PlanConfig, Problem, plan
from ..trajopt.config import SeedConfig
from ..trajopt.planner import checked
from ..ur5e.layout import LIFT
from .ccd3d import certify_path3d
from .distance3d import checker3d
from .fetch3d_scene import Fetch3D, fetch3d
from .scene3d import Scene3D

log = logging.getLogger(__name__)  # one INFO line per finished stage

STAGES = ("approach", "reach_in", "grasp", "lift", "bring_out", "retreat")
PLANNED = {  # stage → (scene, start, goal)
    "approach": ("open", "q_home", "q_pregrasp"),
    "reach_in": ("open", "q_pregrasp", "q_grasp"),
    "bring_out": ("holding", "q_lift", "q_out"),
    "retreat": ("holding", "q_out", "q_home"),
}
WAYPOINTS = 30
KNOT_STEP = 10  # points of a straight tool line (LINE_STEP = 0.01 m apart) between knots
MARGIN = 0.01  # m: clearance of the planned stages
# the held stick threads the entrance: short RRT-Connect steps with more time (as the planar
# fetch's bring-out); the other stages use the planner's defaults
STAGE_SOLVERS = {
    "bring_out": PlanConfig(seed=SeedConfig(rrt_step=0.3, rrt_time=20.0)),
    "reach_in": PlanConfig(seed=SeedConfig(rrt_step=0.3, rrt_time=20.0)),
}


@dataclass(frozen=True)
class Stage3D:
    """One stage of the 3-D fetch.

    Attributes:
        name: one of STAGES. gripper: ``open`` or ``holding``.
        scene: the Scene3D the stage moves in.
        q: (T, 6) joint path (rad); grasp: q_grasp twice.
        success: certified (planned: the plan's certificate; grasp: the stick rests on its
            shelf without penetration; lift: certified off the shelf).
        min_distance: the smallest coal distance along the whole path q (m): the proven lower
            bound when the certificate covers all of q (planned; −inf when none was proven);
            grasp: coal's distance at q_grasp; lift: the smaller of the smallest coal distance
            the contact certificate checked on its first segment (0 at the resting contact; the
            segment proven > −CONTACT_ALLOWANCE) and the proven bound over the rest.
        solve_time: wall time of the stage (s). planned: solved by :func:`plan`.
        detail: the planner's reason or what the scripted stage did.
        certified_from: the first row of q the certificate covers (0: all; lift: 1), None
            without a certificate (grasp).
        certified_min_distance: the proven lower bound over q[certified_from:] (m; None:
            min_distance when certified_from is 0).
    """

    name: str
    gripper: str
    scene: Scene3D
    q: np.ndarray
    success: bool
    min_distance: float
    solve_time: float
    planned: bool
    detail: str
    certified_from: int | None = 0
    certified_min_distance: float | None = None

    def summary(self) -> dict:
        """JSON-ready summary (q as lists; non-finite distances null)."""
        proven = self.certified_min_distance
        if proven is None and self.certified_from == 0:
            proven = self.min_distance
        return {
            "stage": self.name,
            "gripper": self.gripper,
            "success": bool(self.success),
            "min_distance": _json_distance(self.min_distance),
            "certified_from": self.certified_from,
            "certified_min_distance": None if proven is None else _json_distance(proven),
            "solve_time": float(self.solve_time),
            "planned": self.planned,
            "detail": self.detail,
            "joint_names": list(self.scene.robot.joint_names),
            "q": np.asarray(self.q).tolist(),
        }


def _json_distance(d: float) -> float | None:
    return float(d) if np.isfinite(d) else None


def knots(fetch: Fetch3D, name: str) -> list[np.ndarray]:
    """The configurations a planned stage passes: start, the knots of its straight tool line
    (reach_in, bring_out: every KNOT_STEP points of ``fetch.lines``), goal."""
    _, start, goal = PLANNED[name]
    if name not in fetch.lines:
        return [fetch.q[start], fetch.q[goal]]
    line = fetch.lines[name]
    inner = list(line[KNOT_STEP:-1:KNOT_STEP])
    if inner and np.linalg.norm(line[-1] - inner[-1]) < 1e-9:
        inner.pop()
    return [fetch.q[start], *inner, fetch.q[goal]]


def stage_problems(fetch: Fetch3D, name: str, margin: float = MARGIN) -> list[Problem]:
    """The planning problems of a planned stage (approach, reach_in, bring_out, retreat): one
    for approach and retreat, one per piece between consecutive :func:`knots` for the stages
    along a straight tool line (the pieces are short, so their joint-space lines stay near the
    tool line and the planner's straight-line check or a short RRT-Connect solves them)."""
    if name not in PLANNED:
        raise InputError(f"stage: {name!r} is not planned; planned stages: {list(PLANNED)}")
    scene = fetch.scenes[PLANNED[name][0]]
    points = knots(fetch, name)
    return [
        Problem(
            scene=scene,
            start=a,
            goal=b,
            waypoints=WAYPOINTS,
            margin=margin,
            solver=STAGE_SOLVERS.get(name),
        )
        for a, b in itertools.pairwise(points)
    ]


def _planned(fetch: Fetch3D, name: str, margin: float, collision="coal") -> Stage3D:
    """Plan every piece of a stage with the constraints of ``collision`` ("coal" or a
    DistanceModel, checked against the stage's scene); the stage succeeds when every piece is
    certified (by coal)."""
    t0 = time.perf_counter()
    problems = stage_problems(fetch, name, margin)
    runs = [plan(p, collision=collision) for p in problems]
    # the stacked path drops each next piece's first row: it is certified only when that row
    # is exactly the previous piece's last (a plan ends exactly at its joint goal)
    joined = all(np.array_equal(a.q[-1], b.q[0]) for a, b in itertools.pairwise(runs))
    ok = all(r.success for r in runs) and joined
    q = np.vstack([runs[0].q, *(r.q[1:] for r in runs[1:])])
    lower = min(r.min_distance for r in runs) if ok else -np.inf
    reasons = dict.fromkeys(r.reason for r in runs)
    detail = "; ".join(reasons) if len(runs) == 1 else f"{len(runs)} pieces: " + "; ".join(reasons)
    scene = problems[0].scene
    dt = time.perf_counter() - t0
    return Stage3D(name, PLANNED[name][0], scene, q, ok, lower, dt, True, detail)


def _grasp(fetch: Fetch3D) -> Stage3D:
    t0 = time.perf_counter()
    scene = fetch.scenes["holding"]
    d = float(checker3d(scene).evaluate(fetch.q["q_grasp"]).distance[0])
    s = fetch.storage
    detail = (
        f"fingers closed on a {s.stick_length:.3f} m × {s.stick_width:.3f} m stick; it rests on "
        f"its shelf (d = {d:.4f} m)"
    )
    q = np.array([fetch.q["q_grasp"]] * 2)
    ok = certify_from_contact(scene, q[:1]).ok
    dt = time.perf_counter() - t0
    return Stage3D("grasp", "holding", scene, q, ok, d, dt, False, detail, None)


def _lift(fetch: Fetch3D) -> Stage3D:
    t0 = time.perf_counter()
    scene, path = fetch.scenes["holding"], fetch.lines["lift"]
    cert = certify_path3d(scene, path[1:], margin=0.0)
    lower = cert.lower_bound if cert.ok else -np.inf
    leave = certify_from_contact(scene, path[:2])
    ok = cert.ok and leave.ok
    resting = float(checker3d(scene).evaluate(path[0]).distance[0])
    detail = (
        f"scripted straight lift; rows 1… ({1000 * LIFT / (len(path) - 1):.0f} mm up and above) "
        f"certified, proven d ≥ {lower:.4g} m; row 0 is the stick resting on its shelf (coal "
        f"d = {resting:.3g} m), the first segment " + contact_detail(leave)
    )
    dt = time.perf_counter() - t0
    low = min(leave.min_distance, lower)
    return Stage3D("lift", "holding", scene, path, ok, low, dt, False, detail, 1, lower)


def run_fetch3d(
    seed: int = 0,
    margin: float = MARGIN,
    stages: tuple[str, ...] = STAGES,
    fetch: Fetch3D | None = None,
    collision="coal",
) -> list[Stage3D]:
    """Run the 3-D fetch (or the listed ``stages``, in order) on fetch ``seed`` (or a given
    :class:`Fetch3D`). Every stage runs even when an earlier one failed (each starts from its
    own configuration); each finished stage is logged (``gdnplan.arm3d.fetch3d``, INFO).
    ``collision``: the planned stages' constraints, "coal" or a DistanceModel (e.g.
    GraphDistNet-3D weights trained on ``ur5e_storage``); it must accept both fetch scenes
    (``check_scene``), checked before any stage is planned."""
    for name in stages:
        if name not in STAGES:
            raise InputError(f"stages: unknown stage {name!r}; choose from {STAGES}")
    fetch = fetch if fetch is not None else fetch3d(seed)
    if not isinstance(collision, str):
        for scene in fetch.scenes.values():
            checked(collision, scene)
    out = []
    for name in stages:
        if name == "grasp":
            out.append(_grasp(fetch))
        elif name == "lift":
            out.append(_lift(fetch))
        else:
            out.append(_planned(fetch, name, margin, collision))
        done = out[-1]
        verdict = "certified" if done.success else "FAILED"
        log.info("fetch3d stage %s: %s, %.2f s", name, verdict, done.solve_time)
    return out


__all__ = ["MARGIN", "PLANNED", "STAGES", "Stage3D", "knots", "run_fetch3d", "stage_problems"]
