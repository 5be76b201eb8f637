"""The ur5e and ur5 robots (gdnplan.ur5e.arms): the planar reduction, gripper states, meshes."""

import numpy as np
import pytest
from shapely.geometry import Polygon

import gdnplan as gp
from gdnplan import ur5e as U


@pytest.mark.parametrize("gripper", ["open", "closed", "holding"])
def test_reduced_nodes_equal_pinocchio_and_finite_differences(gripper):
    robot = gp.load_robot("ur5e", gripper=gripper)
    assert robot.dof == 3 and robot.joint_names == list(U.PLANNING_JOINTS)
    q = robot.sample(20, seed=3)
    np.testing.assert_allclose(
        robot.node_positions(q), robot.node_positions_pinocchio(q), atol=1e-12
    )
    np.testing.assert_allclose(
        robot.node_jacobians(q), robot.node_jacobians_pinocchio(q), atol=1e-12
    )
    jac, eps = robot.node_jacobians(q), 1e-6
    for j in range(3):
        dq = np.eye(3)[j] * eps
        fd = (robot.node_positions(q + dq) - robot.node_positions(q - dq)) / (2 * eps)
        np.testing.assert_allclose(jac[..., j], fd, atol=1e-8)


def test_plane_and_zero_pose():
    """At q = 0 the arm stretches along +u; the tcp is on the tool axis d5 below the forearm."""
    robot = gp.load_robot("ur5e")
    np.testing.assert_allclose(robot.plane.axes, [[1, 0, 0], [0, 0, 1]])
    np.testing.assert_allclose(
        robot.chain.joint_origins, [[0, 0], [0.425, 0], [0.8172, 0]], atol=1e-12
    )
    np.testing.assert_allclose(robot.lower, [-np.pi, -0.9 * np.pi, -np.pi])
    np.testing.assert_allclose(robot.upper, [0.0, 0.9 * np.pi, np.pi])
    np.testing.assert_allclose(
        U.tcp_pose(robot, np.zeros(3)), [0.8172 + 0.0996 + U.TCP, -0.0997, 0], atol=1e-12
    )
    # shoulder_lift = −π/2 points the upper arm straight up (UR convention)
    elbow = robot.chain.joint_positions(np.array([[-np.pi / 2, 0, 0]]))[0, 1]
    np.testing.assert_allclose(elbow, [0, 0.425], atol=1e-12)
    # everything fixed to the base stays inside base_radius, so obstacles never overlap it
    base = np.concatenate([p.vertices0 for p in robot.polygons if p.body == 0])
    assert np.linalg.norm(base, axis=1).max() < robot.base_radius


def test_gripper_states_change_polygons():
    opened, closed = gp.load_robot("ur5e", gripper="open"), gp.load_robot("ur5e", gripper="closed")
    held = gp.load_robot("ur5e", gripper="holding", stick_length=0.3, stick_width=0.02)
    names = ["base", "upper_arm", "forearm", "wrist", "hand", "finger_left", "finger_right"]
    assert [p.name for p in opened.polygons] == names == [p.name for p in closed.polygons]
    assert [p.name for p in held.polygons] == [*names, "stick"]

    def gap(robot):  # opening between the finger faces, across the tool axis (v at q = 0)
        left, right = (
            robot.polygons[names.index(f)].vertices0 for f in ("finger_left", "finger_right")
        )
        return left[:, 1].min() - right[:, 1].max()

    assert gap(opened) == pytest.approx(0.085)
    assert gap(closed) == pytest.approx(0.0, abs=1e-12)
    assert gap(held) == pytest.approx(0.02)
    stick = held.polygons[-1].vertices0
    assert np.ptp(stick[:, 0]) == pytest.approx(0.3) and np.ptp(stick[:, 1]) == pytest.approx(0.02)
    palm = opened.polygons[names.index("hand")].vertices0[:, 0].max()
    assert stick[:, 0].min() - palm == pytest.approx(U.GRASP_GAP)
    # centred between the fingers
    assert stick[:, 1].mean() == pytest.approx(U.tcp_pose(held, np.zeros(3))[1])
    assert held.reach > opened.reach + 0.15


def test_unknown_gripper_and_bad_stick():
    with pytest.raises(gp.UnknownNameError, match="gripper"):
        gp.load_robot("ur5e", gripper="bogus")
    with pytest.raises(gp.InputError, match="stick_length"):
        gp.load_robot("ur5e", gripper="holding", stick_length=-1.0)


def test_ur5_from_meshes():
    robot = gp.load_robot("ur5")
    assert robot.dof == 3 and robot.joint_names == list(U.PLANNING_JOINTS)
    assert [p.name for p in robot.polygons] == ["base", "upper_arm", "forearm", "wrist", "hand"]
    areas = {p.name: Polygon(p.vertices0).area for p in robot.polygons}
    assert 0.04 < areas["upper_arm"] < 0.08 and 0.03 < areas["forearm"] < 0.06  # ~0.5 m × 0.1 m
    assert all(a > 0.005 for a in areas.values())
    # reach: a2 + a3 + d6 along the arm, plus the hand's mesh
    assert 0.425 + 0.39225 + 0.0823 < robot.reach < 1.0
    upper = robot.polygons[1].vertices0
    assert upper[:, 0].max() == pytest.approx(0.425, abs=0.07)
    q = robot.sample(10, seed=5)
    np.testing.assert_allclose(
        robot.node_positions(q), robot.node_positions_pinocchio(q), atol=1e-12
    )
    np.testing.assert_allclose(
        robot.node_jacobians(q), robot.node_jacobians_pinocchio(q), atol=1e-12
    )
