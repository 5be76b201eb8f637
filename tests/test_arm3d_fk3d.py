"""Batched numpy forward kinematics against Pinocchio's forwardKinematics."""

import numpy as np
import pytest

from gdnplan.arm3d import load_robot3d
from gdnplan.arm3d.fk3d import body_placements_batch, shape_placements_batch


@pytest.mark.parametrize("name", ["ur5e", "panda", "ur5"])
def test_batched_placements_match_pinocchio(name):
    robot = load_robot3d(name)
    q = robot.random_configurations(20, np.random.default_rng(4))
    bodies = body_placements_batch(robot, q)
    shapes = shape_placements_batch(robot, q)
    for i, qi in enumerate(q):
        np.testing.assert_allclose(bodies[i], robot.body_placements(qi), atol=1e-12)
        np.testing.assert_allclose(shapes[i], robot.shape_placements(qi), atol=1e-12)


def test_one_configuration_is_a_batch_of_one():
    robot = load_robot3d("ur5e")
    q = np.array([0.1, -1.0, 0.5, 0.2, -0.3, 0.9])
    np.testing.assert_allclose(shape_placements_batch(robot, q)[0], robot.shape_placements(q))
