"""GraphDistNet-3D as the planner's collision model: a 3-D reaching problem planned by Ipopt
with learned constraints (through the casadi callback) and certified by coal, and the refine
rounds' exact rows in 3-D (coal-3D, not the planar checker)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gdnplan.arm3d import Coal3DModel, Scene3D, certify_path3d, signed_distance3d
from gdnplan.arm3d.problem3d import reaching_problems
from gdnplan.models.graphdistnet3d import load_graphdistnet3d
from gdnplan.trajopt import PlanConfig, SeedConfig, plan
from gdnplan.trajopt.refine import ExactRows

WEIGHTS = Path(__file__).parents[1] / "weights" / "ur5e_boxes3d_preliminary.safetensors"


@pytest.fixture(scope="module")
def problem():
    return reaching_problems("ur5e", n=1, seed=0)[0]


def test_exact_rows_are_coal_3d(problem):
    model = load_graphdistnet3d(WEIGHTS)
    q = problem.scene.robot.random_configurations(6, np.random.default_rng(0))
    exact = np.array([True, False, True, False, False, True])
    rows = ExactRows(model, exact)
    d, g = rows.distance_and_grad(problem.scene, q)
    coal = signed_distance3d(problem.scene, q[exact])
    np.testing.assert_allclose(d[exact], coal, atol=1e-9)
    np.testing.assert_allclose(rows.distance(problem.scene, q)[exact], coal, atol=1e-9)
    learned, learned_g = model.distance_and_grad(problem.scene, q[~exact])
    np.testing.assert_allclose(d[~exact], learned)
    np.testing.assert_allclose(g[~exact], learned_g)


def test_self_rows_hold_contact_only_pairs_like_coal(problem):
    """The learned model's exact self distance counts contact-only pairs as coal does: true
    distances by default, d + o with :meth:`with_contact_offset` (the planner's margin)."""
    scene = problem.scene
    robot = scene.robot
    assert robot.self_contact_only.any()  # the UR5e's forearm–wrist pairs
    model = load_graphdistnet3d(WEIGHTS)
    q = robot.random_configurations(64, np.random.default_rng(1))
    alone = Scene3D(robot, ())
    for offset in (0.0, 0.01, 0.3):
        shifted = model.with_contact_offset(offset)
        assert shifted.net is model.net and model.contact_offset == 0.0
        d, g = shifted.distance_and_grad(scene, q)
        own = Coal3DModel(offset).distance(alone, q)
        np.testing.assert_allclose(d, np.minimum(model.learned_distance(scene, q), own))
        np.testing.assert_allclose(shifted.distance(scene, q), d)
        assert np.all(np.isfinite(g))
    true_self = signed_distance3d(alone, q)
    assert np.all(model.distance(scene, q) <= true_self + 1e-12)


def test_plan_gives_a_learned_model_the_margin_as_contact_offset(problem, monkeypatch):
    seen = []
    model = load_graphdistnet3d(WEIGHTS)
    original = type(model).with_contact_offset

    def spy(self, offset):
        seen.append(offset)
        return original(self, offset)

    monkeypatch.setattr(type(model), "with_contact_offset", spy)
    plan(problem, collision=model, solver=PlanConfig(seed=SeedConfig(time_budget=1e-9)))
    assert seen == [problem.margin]


@pytest.mark.slow
def test_a_reaching_problem_planned_with_graphdistnet3d_is_certified(problem):
    model = load_graphdistnet3d(WEIGHTS)
    assert model.fused  # the compiled pass serves the planner
    result = plan(problem, collision=model)
    assert result.success, result.reason
    assert result.model_calls > 0 and problem.scene in model._scenes  # the learned model ran
    np.testing.assert_allclose(result.q[0], problem.start)
    np.testing.assert_allclose(result.q[-1], problem.goal)
    assert certify_path3d(problem.scene, result.q, problem.margin).ok  # independent re-check
