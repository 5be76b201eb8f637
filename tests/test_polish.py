"""The polish and repair solves after the seeds' (gdnplan.trajopt.polish)."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.ccd import certify_path
from gdnplan.distance import signed_distance
from gdnplan.limits import MAX_INTERPOLATED
from gdnplan.models import CoalModel
from gdnplan.trajopt import IpoptConfig, PlanConfig, Problem, RefineConfig, SeedConfig, plan
from gdnplan.trajopt.config import more_check_points
from gdnplan.trajopt.polish import (
    POLISH_ITER_FACTOR,
    POLISH_MIN_ITER,
    polish,
    polish_iterations,
    repair,
)
from gdnplan.trajopt.result import _Run

START, GOAL = [1.3, -2.9], [1.5, 0.1]  # planar2 around env a's square; the straight line hits it


@pytest.fixture(scope="module")
def square():
    return gp.make_scene("a")


def dense_min(scene, q: np.ndarray, n: int = 400) -> float:
    """Smallest coal distance at n points per segment of q (T, dof): independent of the
    certificate's bisection."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    return float(min(signed_distance(scene, a + s * (b - a)).min() for a, b in pairwise(q)))


def unpolished(square, margin: float = 0.02):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=12, margin=margin)
    cfg = PlanConfig(SeedConfig(initial="rrt", count=1), RefineConfig(polish=False, repair=False))
    return p, plan(p, collision="coal", solver=cfg)


def test_a_path_a_fraction_of_a_millimetre_inside_the_margin_is_repaired(square):
    """A certified path asked for 0.5 mm more clearance than it has (the refine rounds' typical
    end: a hair inside the margin between check points) fails the certificate; the repair
    solve from it returns a path certified at that margin, and dense sampling agrees."""
    _, base = unpolished(square)
    assert base.success, base.reason
    margin = base.sampled_min_distance + 0.0005  # above the path's true minimum
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=12, margin=margin)
    before = certify_path(square, base.q, p.certified_clearance)
    assert not before.ok and dense_min(square, base.q) > margin - 0.001  # fails by < 1 mm
    run = _Run(q=base.q, status="Solved_To_Acceptable_Level", verified=before)
    repair(p, CoalModel(), p.goal, PlanConfig(), run)
    assert run.verified.ok
    assert certify_path(square, run.q, p.certified_clearance).ok
    assert dense_min(square, run.q) > margin
    np.testing.assert_allclose(run.q[[0, -1]], [START, GOAL])


def test_the_polish_never_returns_a_costlier_or_uncertified_path(square):
    p, base = unpolished(square)
    cfg = PlanConfig(SeedConfig(initial="rrt", count=1))
    polished = plan(p, collision="coal", solver=cfg)
    assert base.success and polished.success, polished.reason
    assert polished.path_cost <= base.path_cost + 1e-12
    assert polished.min_distance > p.certified_clearance
    assert dense_min(square, polished.q) > p.certified_clearance


@pytest.mark.parametrize("goal", [[0.4, -0.2], [-2.0, 1.0]])
def test_a_free_straight_line_is_returned_as_is(square, goal):
    """Without obstacles (or with a free straight line) the line is the plan: no repair or
    polish solve runs on it, and it is certified (before, tol = inf never proved +inf)."""
    empty = square.with_obstacles([])
    p = Problem(scene=empty, start=[0.0, 0.0], goal=goal, waypoints=12, margin=0.02)
    result = plan(p, collision="coal")
    assert result.success and result.iterations == 0, result.reason
    assert "repaired" not in result.reason and result.min_distance == np.inf
    assert result.seed is not None and result.seed.kind == "straight"  # no seed was refined


@settings(max_examples=50, deadline=None)
@given(iterations=st.integers(0, 10_000), attempts=st.integers(0, 20), max_iter=st.integers(1, 500))
def test_the_polish_iteration_cap_follows_the_seeds_solves_within_its_bounds(
    iterations, attempts, max_iter
):
    cap = polish_iterations(_Run(q=np.zeros((2, 2)), iterations=iterations, attempts=attempts),
                            max_iter)  # fmt: skip
    mean = -(-iterations // max(attempts, 1))
    assert cap <= max_iter
    assert cap == min(max_iter, max(POLISH_MIN_ITER, POLISH_ITER_FACTOR * mean))


def test_every_polish_solve_gets_the_cap(square, monkeypatch):
    """The polish's solves run with max_iter = the cap (not the seeds' max_iter), and a run
    whose seeds took few iterations gets the floor."""
    import gdnplan.trajopt.ipopt as ipopt_module

    p, base = unpolished(square)
    seen = []

    def record(problem, model, goal, cfg, q0, run, deadline):
        seen.append(cfg.optimizer.max_iter)
        return q0, None, False

    monkeypatch.setattr(ipopt_module, "_solve_refined", record)
    cert = certify_path(square, base.q, p.certified_clearance)
    run = _Run(q=base.q, iterations=40, attempts=2, verified=cert, seed=base.seed)
    polish(p, CoalModel(), p.goal, PlanConfig(), run)
    assert seen and all(m == polish_iterations(run, PlanConfig().optimizer.max_iter) for m in seen)
    assert seen[0] == max(POLISH_MIN_ITER, POLISH_ITER_FACTOR * 20)


@pytest.mark.parametrize("stage", ["polish", "repair", "replaced attempt"])
def test_the_planner_adds_no_check_points_past_the_limit(square, stage):
    """IpoptConfig(interpolated=MAX_INTERPOLATED) is allowed; the check points the planner
    adds itself (a replaced attempt: one per failure, the polish and the repair: REPAIR_EXTRA
    and POLISH_STAGES' extras) stop at that limit. They re-made the config with
    interpolated = 51 and plan raised "interpolated: expected an integer in [0, 50], got 51",
    a setting the caller never gave."""
    top = IpoptConfig(interpolated=MAX_INTERPOLATED)
    assert more_check_points(top, 2).interpolated == MAX_INTERPOLATED
    assert more_check_points(IpoptConfig(interpolated=3), 2).interpolated == 5
    if stage == "polish":
        p = Problem(scene=square, start=START, goal=GOAL, waypoints=8)
        cfg = PlanConfig(SeedConfig(initial="rrt", count=1), RefineConfig(repair=False), top)
        result = plan(p, collision="coal", solver=cfg)
        assert result.success and certify_path(square, result.q, p.certified_clearance).ok
    elif stage == "repair":
        _, base = unpolished(square)
        margin = base.sampled_min_distance + 0.0005
        p = Problem(scene=square, start=START, goal=GOAL, waypoints=12, margin=margin)
        before = certify_path(square, base.q, p.certified_clearance)
        run = _Run(q=base.q, status="Solved_To_Acceptable_Level", verified=before)
        repair(p, CoalModel(), p.goal, PlanConfig(optimizer=top), run)
        assert run.verified is None or run.verified.ok is not None
    else:  # joint 0 held near 1.0: the forearm cannot get round, every attempt fails
        p = Problem(square, [1.0, -2.9], [1.0, 0.5], waypoints=5, lower=[0.98, -3.14],
                    upper=[1.02, 3.14])  # fmt: skip
        seed = SeedConfig(initial="straight", count=1, starts=2)
        cfg = PlanConfig(seed, RefineConfig(rounds=0, polish=False, repair=False), top)
        result = plan(p, collision="coal", solver=cfg)
        assert not result.success and result.attempts == 2
