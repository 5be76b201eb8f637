"""The planar planner on 3-D scenes: Problem, plan (Ipopt and Adam), the certificate that
judges every 3-D plan, timing, and what stays planar."""

import numpy as np
import pytest

from gdnplan.arm3d import (
    Coal3DModel,
    Scene3D,
    box_obstacle,
    certify_path3d,
    checker3d,
    load_robot3d,
    signed_distance3d,
)
from gdnplan.errors import InputError
from gdnplan.trajopt import AdamConfig, Problem, plan
from gdnplan.trajopt.planner import resolve_model
from gdnplan.trajopt.result import _finish, _Run

START = np.array([-0.6, -1.2, 1.2, -1.5, -1.57, 0.0])
GOAL = np.array([0.6, -1.2, 1.2, -1.5, -1.57, 0.0])


def wall() -> Scene3D:
    """The UR5e in front of a thin post the straight line from START to GOAL passes through."""
    return Scene3D(load_robot3d("ur5e"), [box_obstacle((0.1, 0.1, 0.6), (0.45, 0.0, 0.3))])


def clearance(scene: Scene3D, q: np.ndarray, margin: float) -> np.ndarray:
    """min_k (d_k + o_k) (m): what a margin is compared with (contact-only self pairs need
    d ≥ 0 only: offset o_k = margin; gdnplan.arm3d.pairs)."""
    return checker3d(scene).evaluate(q, contact_offset=margin).distance


def line(n: int = 50) -> np.ndarray:
    return START + np.linspace(0.0, 1.0, n)[:, None] * (GOAL - START)


def test_the_straight_line_collides():
    assert np.min(signed_distance3d(wall(), line())) < 0


def test_a_3d_plan_is_certified_along_the_whole_path():
    problem = Problem(wall(), START, goal=GOAL, waypoints=10, margin=0.02)
    result = plan(problem, collision="coal")
    assert result.success, result.reason
    assert result.clearance == problem.margin and result.min_distance > problem.margin
    np.testing.assert_array_equal(result.q[0], START)
    np.testing.assert_array_equal(result.q[-1], GOAL)
    cert = certify_path3d(problem.scene, result.q, problem.margin)  # independent re-check
    assert cert.ok
    dense = np.concatenate(
        [
            a + np.linspace(0, 1, 30)[:, None] * (b - a)
            for a, b in zip(result.q[:-1], result.q[1:], strict=True)
        ]
    )
    assert np.min(clearance(problem.scene, dense, problem.margin)) > problem.margin
    assert np.min(signed_distance3d(problem.scene, dense)) > 0  # contact-only pairs too
    assert result.trajectory is not None and result.trajectory.kind == "linear"


def test_the_finishing_step_refuses_a_penetrating_3d_path():
    problem = Problem(wall(), START, goal=GOAL, waypoints=10, margin=0.02)
    run = _Run(q=line(10), status="forged", reason="a solver's word")
    result = _finish(problem, run, 0.0)
    assert not result.success
    assert result.min_distance == -np.inf
    assert "coal certificate of clearance > 0.02 m failed" in result.reason
    assert result.sampled_min_distance < 0  # the counterexample the certificate found


def test_a_path_just_inside_the_clearance_is_refused():
    """Clearance is a promise in 3-D too: a collision-free path closer than the margin (the
    post moved back: the line passes 3.6 cm from it, the ends 5.5 cm) is no success."""
    scene = Scene3D(load_robot3d("ur5e"), [box_obstacle((0.1, 0.1, 0.6), (0.8, 0.0, 0.3))])
    margin = 0.045
    d_line = float(np.min(clearance(scene, line(200), margin)))
    ends = float(np.min(clearance(scene, np.stack([START, GOAL]), margin)))
    assert 0 < d_line < margin < ends
    problem = Problem(scene, START, goal=GOAL, waypoints=10, margin=margin)
    result = _finish(problem, _Run(q=line(10)), 0.0)
    assert not result.success and "coal certificate of clearance > 0.045 m failed" in result.reason


def test_adam_and_acceleration_limits_run_on_a_3d_scene():
    problem = Problem(wall(), START, goal=GOAL, waypoints=8, margin=0.02)
    result = plan(problem, collision="coal", solver=AdamConfig(iterations=30))
    if result.success:  # 30 iterations may not suffice; success must then be proven
        assert certify_path3d(problem.scene, result.q, problem.margin).ok
    free = Problem(Scene3D(load_robot3d("ur5e"), []), START, goal=GOAL, waypoints=5, margin=0.02)
    timed = plan(free, collision="coal", max_acceleration=2.0)
    assert timed.success and timed.attempts == 0  # the straight line, certified
    curve = timed.trajectory
    assert curve.kind == "smooth"  # the curve certificate works in 3-D (self-collision too)
    assert curve.min_distance is not None and curve.min_distance > 0
    _, q = curve.sample(curve.duration / 200)
    assert clearance(free.scene, q, 0.02).min() >= curve.min_distance - 1e-9
    assert signed_distance3d(free.scene, q).min() > 0  # contact-only pairs: d > 0


def test_coal_is_the_3d_model_and_learned_3d_weights_must_be_named():
    scene = wall()
    assert isinstance(resolve_model("coal", scene, None), Coal3DModel)
    with pytest.raises(InputError, match="on a 3-D scene needs weights named"):
        resolve_model("graphdistnet", scene, None)


def test_a_3d_goal_is_a_joint_vector():
    with pytest.raises(InputError, match=r"goal\.position: a 3-D problem's goal is a joint vector"):
        Problem(wall(), START, goal_position=np.array([0.3, 0.2]))


def test_the_3d_coal_model_gives_ipopt_one_capped_row_per_link():
    from gdnplan.casadi_bridge import distance_rows, supports_per_link

    scene, model = wall(), Coal3DModel()
    assert supports_per_link(model)
    rows, n = distance_rows(model, scene, per_link=True, cap=0.3)
    q = line(7)
    d, grad = rows(q)
    exact = signed_distance3d(scene, q, per_link=True)
    assert n == scene.robot.n_links and d.shape == exact.shape
    np.testing.assert_allclose(d, np.minimum(exact, 0.3), atol=1e-9)
    g = grad()
    assert g.shape == (7, n, 6) and np.all(g[d >= 0.3] == 0)
