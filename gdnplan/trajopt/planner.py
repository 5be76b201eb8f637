"""The plan loop: :func:`plan` checks the settings, resolves the distance model, turns a goal
position into a joint goal, runs the solver and certifies and times its path."""

from __future__ import annotations

import logging
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..arm3d.distance3d import Coal3DModel
from ..arm3d.scene3d import Scene3D
from ..assets import default_weights
from ..distance import signed_distance
from ..errors import InfeasibleProblemError, InputError
from ..limits import MAX_CHECK_POINTS, MAX_ITER, MAX_SEED, check_int
from ..models import CoalModel, DistanceModel, load_model
from ..scene import Scene
from ..timing import limit_vector, plan_timing
from .adam import _plan_adam
from .config import (
    AdamConfig,
    IpoptConfig,
    PlanConfig,
    finite_budget,
    more_check_points,
    with_optimizer,
)
from .ik import first_joint_barrier, tip_point, tip_position
from .ipopt import _plan_ipopt
from .options import TrajoptOptions
from .polish import POLISH_STAGES, REPAIR_EXTRA, polish, repair
from .problem import Problem, check_reachable_in_steps
from .result import Plan, _finish

log = logging.getLogger("gdnplan.trajopt")  # one logger for the package: the stage lines


def resolve_model(
    collision: str | DistanceModel, scene: Scene | Scene3D, weights: str | Path | None
):
    """The DistanceModel named by ``collision`` ("coal", "graphdistnet" or a model instance).

    "coal" is the scene kind's exact model: :class:`~gdnplan.models.CoalModel` for a planar
    scene, :class:`~gdnplan.arm3d.Coal3DModel` for a 3-D one (:func:`plan` gives it the
    problem's margin as contact offset: the rows then keep contact-only self pairs at d ≥ 0
    and every other pair at the margin).

    ``weights`` (GraphDistNet): shipped weights by name (``"d"``, ``"ur5e_boxes3d_preliminary"``)
    or a ``.safetensors`` path; None picks the shipped weights for a planar scene's robot and
    obstacles (:func:`gdnplan.assets.default_weights`); a 3-D scene has no default (the
    shipped 3-D weights are preliminary) and needs them named. The model refuses a scene it was
    not trained for (its ``check_scene``); weights with any other ``collision`` are refused
    (they would be silently unused).
    """
    if weights is not None and collision != "graphdistnet":
        what = collision if isinstance(collision, str) else "a DistanceModel"
        raise InputError(
            f"weights: only collision='graphdistnet' loads weights, not {what!r}; drop the "
            "weights (--weights) or use collision='graphdistnet'"
        )
    if not isinstance(collision, str):
        if not isinstance(collision, DistanceModel):
            raise InputError(
                f"collision: expected 'coal', 'graphdistnet' or a DistanceModel, "
                f"got {type(collision).__name__}"
            )
        return check_outputs(checked(collision, scene), scene)
    if collision == "coal":
        return Coal3DModel() if isinstance(scene, Scene3D) else CoalModel()
    if collision != "graphdistnet":
        raise InputError(f"collision: unknown {collision!r}; choose 'coal' or 'graphdistnet'")
    if isinstance(scene, Scene3D) and weights is None:
        raise InputError(
            "collision: graphdistnet on a 3-D scene needs weights named (no default: the shipped "
            "GraphDistNet-3D weights, 'ur5e_boxes3d_preliminary', are preliminary and know the "
            "UR5e among random boxes only); give weights=... (--weights) or use collision='coal'"
        )
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


def check_outputs(model: DistanceModel, scene: Scene | Scene3D) -> DistanceModel:
    """``model`` when its ``distance`` and ``distance_and_grad`` return real distances (B,) and
    gradients (B, dof) for a batch of B = 2 configurations (the middle of the joint limits and
    the lower limits), else InputError naming the model and the method: a caller's model of
    the wrong shapes or of strings failed deep inside the solver with numpy's broadcast or
    ufunc errors, a complex one lost its imaginary part. NaN values pass (the solver treats
    them as an invalid trial point)."""
    robot = scene.robot
    q = np.stack([(robot.lower + robot.upper) / 2, robot.lower])
    q = np.where(np.isfinite(q), q, 0.0)
    name = getattr(model, "name", type(model).__name__)
    d = model.distance(scene, q)
    try:
        d2, g = model.distance_and_grad(scene, q)
    except (TypeError, ValueError) as e:  # not a pair
        raise InputError(
            f"collision: model {name!r}: distance_and_grad must return (distances, gradients)"
        ) from e
    for what, value, shape in (
        ("distance", d, (2,)),
        ("distance_and_grad's distances", d2, (2,)),
        ("distance_and_grad's gradients", g, (2, robot.dof)),
    ):
        try:
            arr = np.asarray(value)
        except (TypeError, ValueError):  # ragged rows
            arr = np.asarray(None)
        if arr.dtype.kind not in "iuf" or arr.shape != shape:
            got = f"an array of {arr.dtype} of shape {arr.shape}"
            raise InputError(
                f"collision: model {name!r}: {what} returned {got} for 2 configurations; "
                f"expected real numbers of shape {shape} (see gdnplan.DistanceModel)"
            )
    return model


Solver = PlanConfig | IpoptConfig | AdamConfig


def plan(
    problem: Problem,
    collision: str | DistanceModel = "coal",
    solver: Solver | str | None = None,
    weights: str | Path | None = None,
    seed: int = 0,
    options: TrajoptOptions | None = None,
    max_velocity=None,
    max_acceleration=None,
) -> Plan:
    """Plan a trajectory for ``problem``; see :mod:`gdnplan.trajopt` for the formulation.

    ``solver``: the planner settings (:func:`plan_config`): a :class:`PlanConfig`, or an
    :class:`IpoptConfig` / :class:`AdamConfig` alone (that optimiser, with the problem's seed
    and refine settings); None: the problem's own (``problem.solver``), else the defaults
    (Ipopt). The strings "ipopt"/"adam" and ``options`` (a TrajoptOptions) are deprecated.
    ``seed``: the random stream of the first seed path (seed i uses ``seed + i``).
    ``max_velocity`` (rad/s; default: the URDF's limits) and ``max_acceleration`` (rad/s²;
    default None: velocity limits only), one number or one per joint, time the certified path
    (:func:`gdnplan.timing.time_path`, ``Plan.times``).

    Raises GdnplanError on bad input (InputError naming ``problem`` or ``seed``, an integer in
    [0, ``limits.MAX_SEED``]); a failed solve returns ``Plan(success=False, reason=…)``.
    """
    t0 = time.perf_counter()
    if not isinstance(problem, Problem):
        raise InputError(f"problem: expected a gdnplan.Problem, got {type(problem).__name__}")
    seed = check_int(seed, "seed", 0, MAX_SEED)  # a Python int: a numpy seed reached Plan.seed
    cfg = plan_config(problem, solver, options)
    _check_sizes(problem, cfg)
    dof = problem.scene.robot.dof
    if max_velocity is not None:
        max_velocity = limit_vector(max_velocity, dof, "max_velocity", "rad/s")
    if max_acceleration is not None:
        max_acceleration = limit_vector(max_acceleration, dof, "max_acceleration", "rad/s²")
    model = resolve_model(collision, problem.scene, weights)
    if hasattr(model, "with_contact_offset"):  # contact-only pairs: rows d + margin ≥ margin
        model = model.with_contact_offset(problem.margin)
    goal = problem.goal
    if goal is None:  # the joint goal of goal_position: the step bound must still reach it
        goal = numeric_ik(problem, seed)
        check_reachable_in_steps(problem.start, goal, problem.max_step, problem.waypoints)
    deadline = t0 + finite_budget(cfg.seed.time_budget)
    if isinstance(cfg.optimizer, IpoptConfig):
        run = _plan_ipopt(problem, model, goal, cfg, seed, deadline)
        if cfg.refine.repair:
            repair(problem, model, goal, cfg, run, deadline)
        if cfg.refine.polish:
            polish(problem, model, goal, cfg, run, deadline)
    else:
        run = _plan_adam(problem, model, goal, cfg, seed, deadline)
    result = _finish(problem, run, t0)
    trajectory, note = plan_timing(
        problem.scene, result.q, result.success, max_velocity, max_acceleration, result.clearance
    )
    reason = f"{result.reason}; {note}".strip("; ") if note else result.reason
    return replace(result, trajectory=trajectory, reason=reason)


def plan_config(
    problem: Problem, solver: Solver | str | None = None, options: TrajoptOptions | None = None
) -> PlanConfig:
    """The checked PlanConfig :func:`plan` runs: ``solver`` when it is a PlanConfig; else the
    problem's settings (``problem.solver``, else the defaults) with the optimiser ``solver``
    names (an IpoptConfig or AdamConfig; None keeps the problem's)."""
    base = problem.solver or PlanConfig()
    if options is not None:
        if not isinstance(options, TrajoptOptions):
            raise InputError(f"options: expected TrajoptOptions, got {type(options).__name__}")
        warnings.warn(
            "plan(options=TrajoptOptions(...)) is deprecated; pass solver=gdnplan.PlanConfig(...)",
            DeprecationWarning,
            stacklevel=3,
        )
        kind = solver if isinstance(solver, str) else "adam" * isinstance(solver, AdamConfig)
        base = options.to_config(kind or "ipopt")
    if isinstance(solver, str):
        base = with_optimizer(base, solver)
        new = f"gdnplan.{type(base.optimizer).__name__}()"
        warnings.warn(
            f"plan(solver={solver!r}) is deprecated; pass solver={new}",
            DeprecationWarning,
            stacklevel=3,
        )
        solver = base.optimizer
    if isinstance(solver, PlanConfig):
        cfg = solver
    elif isinstance(solver, (IpoptConfig, AdamConfig)):
        cfg = replace(base, optimizer=solver)
    elif solver is None:
        cfg = base
    else:
        raise InputError(
            f"solver: expected a PlanConfig, IpoptConfig or AdamConfig, got {type(solver).__name__}"
        )
    return cfg.checked()  # re-runs the checks (a frozen dataclass can still be forged)


def _check_sizes(problem: Problem, cfg: PlanConfig) -> None:
    """InputError when a solve before refining would exceed ``MAX_CHECK_POINTS`` check points:
    the first, or one with the planner's own additions (a replaced attempt: up to starts − 1;
    the polish and repair: ``POLISH_STAGES``' and ``REPAIR_EXTRA``; all capped by
    :func:`~.config.more_check_points`). Counting ``starts − 1`` alone let the polish of a
    one-start call exceed the limit by 2 (T − 1) check points."""
    extra = cfg.seed.starts - 1
    if isinstance(cfg.optimizer, IpoptConfig):
        extra = max(
            extra,
            max(e for _, e, _ in POLISH_STAGES) if cfg.refine.polish else 0,
            REPAIR_EXTRA if cfg.refine.repair else 0,
        )
        per_segment = more_check_points(cfg.optimizer, extra).interpolated + 1
    else:  # Adam keeps its check points
        per_segment = cfg.interpolated + 1
    total = (problem.waypoints - 1) * per_segment
    if total > MAX_CHECK_POINTS:
        raise InputError(
            f"options.waypoints × interpolated: {total} check points, the limit is "
            f"{MAX_CHECK_POINTS}; use fewer waypoints or check points"
        )


def numeric_ik(
    problem: Problem, seed: int = 0, restarts: int = 64, iterations: int = 100
) -> np.ndarray:
    """Collision-free joint goal (dof,) whose tip is at ``problem.goal_position``.

    Batched damped least squares Δq = Jᵀ(JJᵀ + λ²I)⁻¹ e from the start and ``restarts`` random
    configurations, clipped to the limits; among solutions within ``goal_tolerance`` and clear
    of the margin, the one closest to the start. Raises InfeasibleProblemError if none exists;
    InputError naming ``seed`` (an integer in [0, MAX_SEED]), ``restarts`` ([0, 10 000]) or
    ``iterations`` ([1, MAX_ITER]) when out of range.
    """
    if not isinstance(problem, Problem) or problem.goal_position is None:
        raise InputError("problem: expected a gdnplan.Problem with a goal position")
    seed = check_int(seed, "seed", 0, MAX_SEED)
    check_int(restarts, "restarts", 0, 10_000)
    check_int(iterations, "iterations", 1, MAX_ITER)
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
