"""A successful plan keeps every constraint the problem asks for: max_step, the joint limits, the
certified clearance and the goal; Ipopt's word alone never makes one; absurd max_step values and
seeds are refused naming them."""

from __future__ import annotations

import math
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.errors import GdnplanError, InputError
from gdnplan.trajopt import AdamConfig, PlanConfig, Problem, RefineConfig, SeedConfig, plan
from gdnplan.trajopt.adam import project_steps
from gdnplan.trajopt.planner import numeric_ik
from gdnplan.trajopt.result import STEP_TOL, _finish, _Run, path_violation

SQUARE = Path(__file__).parent.parent / "problems" / "planar2_square.toml"
BASE = tomllib.loads(SQUARE.read_text())
NEED = 2.722 - 0.737  # rad: joint 1's distance from start to goal in planar2_square


def problem(**options) -> Problem:
    cfg = {k: dict(v) for k, v in BASE.items()}
    cfg["options"].update(options)
    return Problem.from_config(cfg)


@pytest.fixture(scope="module")
def square() -> Problem:
    return problem()


def largest_step(q: np.ndarray) -> float:
    return float(np.max(np.abs(np.diff(q, axis=0))))


@pytest.mark.parametrize("max_step", [0.0, -0.1, math.nan, math.inf, 1e-300, 5e-324, 0.1])
def test_absurd_max_step_is_refused_naming_it(max_step):
    with pytest.raises(GdnplanError, match="max_step"):
        problem(max_step=max_step)


def test_a_max_step_too_small_for_the_waypoints_says_how_many_would_do():
    with pytest.raises(GdnplanError, match=r"needs 21 waypoints") as info:
        problem(max_step=0.1)  # the audit's reproducer: 19 steps of 0.1 rad < 1.985 rad
    assert "options.max_step" in str(info.value) and "0.1045" in str(info.value)
    assert problem(max_step=0.1, waypoints=21).max_step == 0.1  # enough waypoints: accepted


@settings(max_examples=60, deadline=None)
@given(max_step=st.floats(1e-3, 3.0), waypoints=st.integers(3, 60))
def test_max_step_is_refused_exactly_when_the_waypoints_cannot_reach_the_goal(max_step, waypoints):
    reachable = max_step * (waypoints - 1) >= NEED * (1 + 1e-9)
    try:
        p = problem(max_step=max_step, waypoints=waypoints)
    except GdnplanError as e:
        assert "options.max_step" in str(e) and not reachable
    else:
        assert max_step * (waypoints - 1) >= NEED * (1 - 1e-9)
        assert p.max_step == max_step


@pytest.mark.parametrize("solver", ["ipopt", "adam"])
@pytest.mark.parametrize("max_step", [0.11, 0.15, 0.3])
def test_a_successful_plan_keeps_max_step(max_step, solver):
    p = problem(max_step=max_step)
    cfg = PlanConfig(SeedConfig(count=1), RefineConfig(polish=False))
    if solver == "adam":
        cfg = replace(cfg, optimizer=AdamConfig())
    result = plan(p, collision="coal", solver=cfg)
    if solver == "ipopt" or max_step >= 0.15:  # Adam cannot fold the elbow in 0.11 rad steps
        assert result.success, result.reason
    if result.success:
        assert largest_step(result.q) <= max_step + STEP_TOL
        assert path_violation(p, result.q) is None
    else:
        assert result.reason


def test_adam_without_a_step_bound_would_take_longer_steps(square):
    # the default max_step (1 rad) lets Adam take ~0.49 rad steps: 0.15 is a real constraint
    result = plan(problem(max_step=1.0), collision="coal", solver=AdamConfig())
    assert result.success and largest_step(result.q) > 0.3


def test_project_steps_reaches_the_step_bound_and_keeps_the_ends_and_limits():
    rng = np.random.default_rng(0)
    q = rng.normal(size=(12, 3)) * 2
    q[0], q[-1] = [0.0, 0.0, 0.0], [1.0, -1.0, 0.5]
    lower, upper = np.full(3, -2.0), np.full(3, 2.0)
    out = project_steps(q, 0.1, lower, upper)
    assert largest_step(out) <= 0.1 + 1e-12
    np.testing.assert_array_equal(out[[0, -1]], q[[0, -1]])
    assert np.all(out >= lower) and np.all(out <= upper)
    free = np.linspace(q[0], q[-1], 12)
    np.testing.assert_array_equal(project_steps(free, 0.1, lower, upper), free)  # feasible: kept


def certified_path(square: Problem) -> np.ndarray:
    result = plan(square, collision="coal", solver=PlanConfig(SeedConfig(count=1)))
    assert result.success, result.reason
    return result.q


@pytest.mark.parametrize(
    "status", ["Infeasible_Problem_Detected", "Maximum_Iterations_Exceeded", "Restoration_Failed"]
)
def test_an_ipopt_failure_is_success_only_when_the_path_keeps_every_constraint(square, status):
    q = certified_path(square)
    ok = _finish(square, _Run(q=q, status=status, reason="rrt seed 0"), 0.0)
    assert ok.success and ok.status == status  # the honest status, and why it is accepted
    assert "Ipopt did not report success" in ok.reason and status in ok.reason
    tight = replace(square, max_step=largest_step(q) - 1e-3)  # the same path over max_step
    bad = _finish(tight, _Run(q=q, status=status, reason="rrt seed 0"), 0.0)
    assert not bad.success and "options.max_step" in bad.reason


@pytest.mark.parametrize(
    "change, field",
    [
        (lambda q: q, None),
        (lambda q: np.vstack([q[:1], q[1:-1] * np.nan, q[-1:]]), "NaN"),
        (lambda q: np.vstack([q[:1] + 0.01, q[1:]]), "start.q"),
        (lambda q: np.vstack([q[:1], q[1:2] * 0 + [3.2, 0.0], q[2:]]), "options.upper"),
    ],
)
def test_path_violation_names_the_constraint(square, change, field):
    q = change(certified_path(square))
    broken = path_violation(square, q)
    if field is None:
        assert broken is None
    else:
        assert field in broken
        result = _finish(square, _Run(q=q, status="Solve_Succeeded", reason="x"), 0.0)
        assert not result.success and field in result.reason


@pytest.mark.parametrize("seed", [-1, 0.5, True, "3", 2**70, None, np.float64(1.0)])
def test_bad_seeds_are_input_errors_naming_seed(square, seed):
    with pytest.raises(InputError, match="seed"):
        plan(square, collision="coal", seed=seed)


def test_a_numpy_integer_seed_is_accepted(square):
    result = plan(
        square, collision="coal", seed=np.int64(2), solver=PlanConfig(SeedConfig(count=1))
    )
    assert result.success and result.seed.stream == 2


@pytest.mark.parametrize(
    "kwargs, field",
    [({"seed": -1}, "seed"), ({"restarts": -1}, "restarts"), ({"iterations": 0}, "iterations")],
)
def test_numeric_ik_checks_its_integers(square, kwargs, field):
    target = gp.trajopt.tip_position(square.scene.robot, square.goal)[0]
    p = Problem(square.scene, square.start, goal_position=target)
    with pytest.raises(InputError, match=field):
        numeric_ik(p, **kwargs)


def test_plan_refuses_a_non_problem():
    with pytest.raises(InputError, match="problem"):
        plan("planar2_square", collision="coal")


@settings(max_examples=5, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**62))
def test_any_allowed_seed_plans(square, seed):
    result = plan(square, collision="coal", seed=seed, solver=PlanConfig(SeedConfig(count=1)))
    assert result.success, result.reason


def test_the_check_point_limit_counts_the_planners_own_additions():
    """MAX_CHECK_POINTS bounds every solve before refining, the polish's and the repair's
    (two more check points per segment) included: T = 500, interpolated = 39 and one start
    passed (499 · 40 = 19 960) while the polish solved with 499 · 42 = 20 958; the limit is
    checked before any solve, and without the polish and repair those settings plan."""
    from gdnplan.trajopt import IpoptConfig, planner

    problem = Problem.from_toml("planar2_square")
    big = replace_waypoints(problem, 500)
    seed = SeedConfig(starts=1)
    cfg = PlanConfig(seed, RefineConfig(), IpoptConfig(interpolated=39))
    with pytest.raises(InputError, match="20958 check points, the limit is 20000"):
        plan(big, "coal", solver=cfg)
    bare = PlanConfig(seed, RefineConfig(polish=False, repair=False), IpoptConfig(interpolated=39))
    planner._check_sizes(big, bare)  # 19 960: within the limit
    adam = PlanConfig(seed, optimizer=AdamConfig(interpolated=39))
    planner._check_sizes(big, adam)  # Adam adds none


def replace_waypoints(problem: Problem, waypoints: int) -> Problem:
    """``problem`` with ``waypoints`` waypoints."""
    return Problem(problem.scene, problem.start, problem.goal, waypoints=waypoints,
                   margin=problem.margin)  # fmt: skip
