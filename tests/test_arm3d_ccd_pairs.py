"""The self-pair motion bound of the 3-D certificate: only joints moving one shape of a pair
but not the other change its distance, and never by more than δ_στ."""

import numpy as np
import pytest

from gdnplan.arm3d import Scene3D, checker3d, lever_arms3d, load_robot3d, motion_bound3d
from gdnplan.arm3d.ccd3d import self_pair_arms


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_self_pair_distances_change_within_their_bound(name):
    robot = load_robot3d(name)
    checker = checker3d(Scene3D(robot, []))  # self pairs only
    weights = self_pair_arms(robot)
    rng = np.random.default_rng(1)
    s = np.linspace(0.0, 1.0, 9)[:, None]
    for qa in robot.random_configurations(6, rng):
        qb = qa + rng.normal(0.0, 0.4, robot.dof)
        d, _ = checker.pair_distances(qa + s * (qb - qa))  # (9, P)
        bound = s * (weights @ np.abs(qb - qa))[None]  # (9, P)
        assert np.all(np.abs(d - d[0]) <= bound + 1e-5)


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_the_self_pair_bound_is_at_most_the_sum_of_both_motions(name):
    robot = load_robot3d(name)
    rng = np.random.default_rng(2)
    qa = robot.random_configurations(50, rng)
    qb = qa + rng.normal(0.0, 0.5, qa.shape)
    delta = np.abs(qb - qa) @ lever_arms3d(robot).T
    pairs = robot.self_pairs
    both = delta[:, pairs[:, 0]] + delta[:, pairs[:, 1]]
    assert np.all(np.abs(qb - qa) @ self_pair_arms(robot).T <= both + 1e-12)
    assert np.all(motion_bound3d(robot, qa, qb) <= np.maximum(delta.max(1), both.max(1)) + 1e-12)
    assert np.all(motion_bound3d(robot, qa, qb) >= delta.max(1))
