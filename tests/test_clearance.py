"""The margin is a promise (#22): a successful plan is proven to keep its requested clearance
(the margin unless ``[options] clearance`` asks for less) along the whole continuous path."""

import functools
import itertools
import math
import time

import numpy as np
import pytest

import gdnplan as gp
from gdnplan.assets import problem_names
from gdnplan.cli import plan_summary
from gdnplan.exact import certify, exact_distance
from gdnplan.trajopt import PlanConfig, Problem, RefineConfig, SeedConfig, plan
from gdnplan.trajopt.check_points import constraint_margin
from gdnplan.trajopt.result import _finish, _Run

SLOW = {"fetch_bring_out", "ur5e_boxes3d", "panda_shelf3d", "ur5e_cloud3d"}  # 7-60 s with coal
PROBLEMS_3D = {"ur5e_boxes3d", "panda_shelf3d", "ur5e_cloud3d"}  # coal only (no 3-D weights)


def _check_kept(problem: Problem, result) -> None:
    assert result.success, result.reason
    assert result.clearance == problem.certified_clearance == problem.margin
    assert result.min_distance > problem.margin  # the proven bound, not bound − margin
    cert = certify(problem.scene, result.q, problem.margin)
    assert cert.ok and cert.lower_bound > problem.margin
    check_promise(problem, result)  # and dense coal samples agree


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in problem_names()],
)
def test_every_shipped_problem_keeps_its_margin_with_coal(name):
    problem = Problem.from_toml(name)
    _check_kept(problem, plan(problem, collision="coal"))


@pytest.mark.parametrize(
    "name",
    [
        n if n == "planar2_square" else pytest.param(n, marks=pytest.mark.slow)
        for n in problem_names()
        if n not in PROBLEMS_3D
    ],
)
def test_every_shipped_problem_keeps_its_margin_with_graphdistnet(name):
    problem = Problem.from_toml(name)
    _check_kept(problem, plan(problem, collision="graphdistnet"))


def test_clearance_zero_certifies_collision_freedom_only():
    default = Problem.from_toml("planar2_square")
    cfg = gp.trajopt.read_problem_file("planar2_square")
    cfg["options"]["clearance"] = 0.0
    zero = Problem.from_config(cfg)
    assert zero.clearance == zero.certified_clearance == 0.0 and zero.margin == default.margin
    result = plan(zero, collision="coal")
    assert result.success and result.clearance == 0.0 and result.min_distance > 0.0
    assert plan_summary(result, ["a", "b"])["clearance"] == 0.0
    # at clearance 0 the check points keep the margin; between them the path may dip below it
    assert constraint_margin(zero, RefineConfig().clearance_buffer) == zero.margin
    # this path (what the old rule, a certificate of d > 0, accepted) dips below the margin:
    # certified at the margin, the default problem refuses it
    assert 0.0 < result.min_distance < default.margin
    refused = _finish(default, _Run(q=result.q, reason="given"), time.perf_counter())
    assert not refused.success and math.isinf(refused.min_distance)
    assert "clearance > 0.02 m failed" in refused.reason


@pytest.mark.parametrize("value", [-0.01, 0.03, float("nan"), float("inf"), True, "0.01"])
def test_bad_clearance_is_refused_naming_the_setting(value):
    cfg = gp.trajopt.read_problem_file("planar2_square")  # margin 0.02
    cfg["options"]["clearance"] = value
    with pytest.raises(gp.ProblemFileError, match=r"options\.clearance"):
        Problem.from_config(cfg)
    base = Problem.from_toml("planar2_square")
    with pytest.raises(gp.InputError, match=r"options\.clearance"):
        Problem(scene=base.scene, start=base.start, goal=base.goal, clearance=value)


def test_clearance_equal_to_the_margin_is_the_default():
    base = Problem.from_toml("planar2_square")
    same = Problem(scene=base.scene, start=base.start, goal=base.goal, clearance=0.02)
    assert same.certified_clearance == base.certified_clearance == 0.02
    assert constraint_margin(base, 0.002) == pytest.approx(0.022)


def test_without_a_buffer_the_refine_rounds_still_never_accept_less_than_the_margin():
    problem = Problem.from_toml("planar7_d")
    opts = PlanConfig(
        SeedConfig(starts=1, initial="rrt"), RefineConfig(clearance_buffer=0.0, rounds=1)
    )
    result = plan(problem, collision="coal", solver=opts)
    # check points at exactly the margin: active rows end a hair inside it, so the
    # certificate at the margin rejects them; success, if any, is still proven
    assert not result.success or result.min_distance > problem.margin
    if not result.success:
        assert "clearance > 0.02 m failed" in result.reason
    cert = certify(problem.scene, result.q, problem.margin)
    assert cert.ok == result.success
    assert np.all(result.q[[0, -1]] == [problem.start, problem.goal])


def dense_min_distance(scene, q: np.ndarray, per_segment: int = 200) -> float:
    """Smallest coal signed distance at ``per_segment`` evenly spaced points of every segment
    of the path q (T, dof), ends included: an independent upper bound of the path's minimum
    (the certificate's proven bound must lie below it)."""
    s = np.linspace(0.0, 1.0, per_segment + 1)[:, None]
    points = np.concatenate([a + s * (b - a) for a, b in itertools.pairwise(q)])
    return float(np.min(exact_distance(scene, points)))  # planar or 3-D


def check_promise(problem: Problem, result) -> None:
    """A successful plan proves d > its requested clearance on the whole path: the Plan's bound,
    the certificate run again, and dense coal samples all say so (failures are allowed)."""
    if not result.success:
        return
    c = problem.certified_clearance
    assert result.clearance == c
    assert result.min_distance > c  # the proven bound the Plan reports
    cert = certify(problem.scene, result.q, c)
    assert cert.ok and cert.lower_bound > c
    dense = dense_min_distance(problem.scene, result.q)
    assert dense > c  # independent of the certificate
    assert result.min_distance <= dense + 1e-9  # a lower bound is below every sample


@functools.cache
def table2_problems(setting: str, n: int) -> tuple:
    from gdnplan.table2 import reaching_problems

    return tuple(reaching_problems(setting, n=n))


@functools.cache
def table2_model(setting: str, collision: str):
    from gdnplan.table2 import WEIGHTS_ENV

    return "coal" if collision == "coal" else gp.load_model(WEIGHTS_ENV[setting])


@pytest.mark.parametrize(
    ("setting", "collision", "n"),
    [("b", "coal", 2), ("b", "graphdistnet", 1)]
    + [
        pytest.param(s, c, 20, marks=pytest.mark.slow)  # minutes each
        for s in ("b", "d", "fetch")
        for c in ("coal", "graphdistnet")
    ],
)
def test_table2_plans_keep_their_margin(setting, collision, n):
    """Table II's problems (its margins: 2 cm on (b) and (d), 1 cm on fetch), planned with the
    defaults: every success keeps the margin along the whole path, and most succeed."""
    problems = table2_problems(setting, n)
    model = table2_model(setting, collision)
    solved = 0
    for problem in problems:
        result = plan(problem, collision=model)
        check_promise(problem, result)
        solved += result.success
    assert solved >= 0.9 * len(problems)
