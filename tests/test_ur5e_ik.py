"""The UR5e's planar tcp pose and exact IK (gdnplan.ur5e.ik); the deprecated name solve_ik."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan import ur5e as U


def test_planar_ik_reaches_targets():
    robot = gp.load_robot("ur5e")
    q = robot.sample(30, seed=4)
    for qi in q:
        sols = U.analytic_ik(robot, U.tcp_pose(robot, qi))  # checks itself against Pinocchio
        assert any(np.allclose(s, qi, atol=1e-8) for s in sols)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    gripper=st.sampled_from(["open", "holding"]),
    up=st.floats(-0.2, 0.2),
)
def test_ik_solutions_reach_the_target_or_it_is_out_of_reach(seed, gripper, up):
    """Every returned q is within limits and reaches the target; a reachable target (the pose of
    some q, shifted) that the chain's elbow circle covers has a solution."""
    robot = gp.load_robot("ur5e", gripper=gripper)
    q = robot.sample(1, seed=seed)[0]
    target = U.tcp_pose(robot, q) + np.array([0.0, up, 0.0])
    solutions = U.analytic_ik(robot, target)
    assert len(solutions) <= 2
    for s in solutions:
        assert robot.within_limits(s)[0]
        pose = U.tcp_pose(robot, s)
        np.testing.assert_allclose(pose[:2], target[:2], atol=1e-9)
        assert abs(np.sin(pose[2] - target[2])) < 1e-9
    if up == 0.0:
        assert solutions


def test_solve_ik_is_a_deprecated_alias_of_analytic_ik():
    robot = gp.load_robot("ur5e")
    target = U.tcp_pose(robot, robot.sample(1, seed=7)[0])
    with pytest.warns(DeprecationWarning, match=r"gdnplan\.ur5e\.analytic_ik"):
        old = U.solve_ik
    assert old is U.analytic_ik
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new name does not warn
        new = U.analytic_ik(robot, target)
    assert all(np.array_equal(a, b) for a, b in zip(old(robot, target), new, strict=True))
    with pytest.raises(AttributeError, match="no attribute 'bogus'"):
        U.bogus  # noqa: B018
