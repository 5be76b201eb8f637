"""Pose IK of 3-D robots: round trips through Pinocchio's forward kinematics on random reachable
poses, collision-free solutions at the margin, the nearest to the reference, clear errors."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from gdnplan.arm3d import Scene3D, box_obstacle, checker3d, load_robot3d
from gdnplan.arm3d.ik3d import MIN_TOL, cartesian_path, frame_pose, solve_pose_ik, tool_frame
from gdnplan.errors import InfeasibleProblemError, InputError


def _fk(robot, q, frame):
    """World pose of a frame from Pinocchio directly (independent of ik3d's helpers)."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return data.oMf[robot.model.getFrameId(frame)]


@pytest.mark.parametrize("name", ["ur5e", "panda"])
@given(seed=st.integers(0, 10_000))
@settings(max_examples=6, deadline=None)
def test_round_trip_on_random_reachable_poses(name, seed):
    robot = load_robot3d(name)
    q_true = robot.random_configurations(1, np.random.default_rng(seed))[0]
    target = _fk(robot, q_true, tool_frame(robot))
    quat = pin.Quaternion(target.rotation).coeffs()  # (x, y, z, w)
    sol = solve_pose_ik(robot, target.translation, quat, margin=-1.0, seed=seed)
    got = _fk(robot, sol.q, tool_frame(robot))
    assert np.linalg.norm(got.translation - target.translation) < 1e-4
    assert np.abs(got.rotation - target.rotation).max() < 1e-3
    assert robot.within_limits(sol.q)[0]
    assert sol.position_error < 1e-4 and sol.rotation_error < 1e-3


def test_the_tool_frame_is_the_gripper_tcp_between_the_fingers():
    robot = load_robot3d("ur5e")
    q = np.array([0.3, -1.2, 1.4, -1.6, -1.57, 0.2])
    tcp = frame_pose(robot, q).translation
    fingers = [_fk(robot, q, f).translation for f in ("left_finger_link", "right_finger_link")]
    gripper = _fk(robot, q, "gripper_base_link")
    axis = gripper.rotation[:, 2]
    # the tcp lies on the tool axis, halfway along the fingers (0.08 m body + 0.025 m)
    assert np.allclose(tcp, gripper.translation + 0.105 * axis, atol=1e-9)
    assert np.allclose((fingers[0] + fingers[1]) / 2 + 0.025 * axis, tcp, atol=1e-9)


def test_the_solution_is_the_one_nearest_the_reference():
    robot = load_robot3d("ur5e")
    q_ref = np.array([0.2, -1.3, 1.5, -1.8, -1.57, 0.4])
    target = _fk(robot, q_ref, "gripper_tcp")
    sol = solve_pose_ik(robot, target.translation, target.rotation, reference=q_ref)
    assert np.allclose(sol.q, q_ref, atol=1e-4)  # other branches reach it too, but farther


def test_solutions_keep_the_margin_from_obstacles():
    robot = load_robot3d("ur5e")
    q = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    target = _fk(robot, q, "gripper_tcp")
    # a box right under the forearm of q: q itself is too close, another branch must be found
    elbow = _fk(robot, q, "forearm_link").translation
    scene = Scene3D(robot, [box_obstacle((0.1, 0.1, 0.1), elbow + np.array([0, 0, -0.12]))])
    assert checker3d(scene).evaluate(q).distance[0] < 0.05
    sol = solve_pose_ik(scene, target.translation, target.rotation, reference=q, margin=0.05)
    assert checker3d(scene).evaluate(sol.q).distance[0] >= 0.05
    assert np.isclose(sol.distance, checker3d(scene).evaluate(sol.q).distance[0])
    assert np.linalg.norm(frame_pose(robot, sol.q).translation - target.translation) < 1e-4


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_a_pose_out_of_reach_is_infeasible(name):
    robot = load_robot3d(name)
    with pytest.raises(InfeasibleProblemError, match="out of reach"):
        solve_pose_ik(robot, [1.8, 0.3, 0.5], restarts=16)


def test_a_pose_every_solution_of_which_collides_is_infeasible():
    robot = load_robot3d("ur5e")
    q = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    target = _fk(robot, q, "gripper_tcp")
    scene = Scene3D(robot, [box_obstacle((0.2, 0.2, 0.2), target.translation)])  # around the tcp
    with pytest.raises(InfeasibleProblemError, match="none with clearance"):
        solve_pose_ik(scene, target.translation, target.rotation, restarts=16)


@pytest.mark.parametrize(
    "rotation",
    [np.diag([1.0, 1.0, -1.0]), 2 * np.eye(3), [0, 0, 0, 0], [[1, 0], [0, 1]], [np.nan, 0, 0, 1]],
)
def test_an_orientation_that_is_not_a_rotation_is_an_input_error(rotation):
    with pytest.raises(InputError, match="rotation"):
        solve_pose_ik(load_robot3d("ur5e"), [0.4, 0.1, 0.3], rotation)


def test_bad_positions_frames_and_references_are_input_errors():
    robot = load_robot3d("ur5e")
    with pytest.raises(InputError, match="position"):
        solve_pose_ik(robot, [0.4, np.inf, 0.3])
    with pytest.raises(InputError, match="frame"):
        solve_pose_ik(robot, [0.4, 0.1, 0.3], frame="no_such_frame")
    with pytest.raises(InputError, match="reference"):
        solve_pose_ik(robot, [0.4, 0.1, 0.3], reference=np.zeros(5))


UR5E_Q = np.array([0.2, -1.3, 1.5, -1.8, -1.57, 0.4])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"position_tol": 1e-300}, "position_tol: 1e-300 is below 1e-12"),
        ({"rotation_tol": 1e-13}, "rotation_tol: 1e-13 is below 1e-12"),
        ({"position_tol": float("nan")}, "position_tol"),
        ({"position_tol": 1e10}, "position_tol: 1e\\+10 m is over 1 m"),
        ({"rotation_tol": 4.0}, "rotation_tol: 4 rad is over 3.14159 rad"),
    ],
)
def test_tolerances_the_solver_cannot_honour_are_refused(kwargs, match):
    robot = load_robot3d("ur5e")
    target = _fk(robot, UR5E_Q, "gripper_tcp")
    with pytest.raises(InputError, match=match):
        solve_pose_ik(robot, target.translation, target.rotation, **kwargs)


def test_the_smallest_tolerance_is_reached_on_a_reachable_pose():
    robot = load_robot3d("ur5e")
    target = _fk(robot, UR5E_Q, "gripper_tcp")
    sol = solve_pose_ik(
        robot, target.translation, target.rotation, margin=-1.0, position_tol=MIN_TOL,
        rotation_tol=MIN_TOL,
    )  # fmt: skip
    assert sol.position_error <= MIN_TOL


def test_an_unmet_tolerance_on_a_reachable_pose_is_not_out_of_reach():
    robot = load_robot3d("ur5e")
    target = _fk(robot, UR5E_Q, "gripper_tcp")
    with pytest.raises(InfeasibleProblemError, match="tolerance was not met") as err:
        solve_pose_ik(
            robot, target.translation, target.rotation, reference=UR5E_Q + 0.02, margin=-1.0,
            restarts=1, iterations=2,
        )  # fmt: skip
    assert "out of reach" not in str(err.value)


@pytest.mark.parametrize(
    ("positions", "kwargs", "match"),
    [
        ([[1, 2]], {}, r"positions: expected \(K, 3\)"),
        ("abc", {}, r"positions: expected \(K, 3\)"),
        ([[1], [1, 2, 3]], {}, r"positions: expected \(K, 3\)"),
        (np.zeros((0, 3)), {}, r"positions: expected \(K, 3\)"),
        ([[0.4, 0.1, np.nan]], {}, r"positions\[0\]: contains NaN"),
        ([[0.4, 0.1, "0.3"]], {}, r"positions\[0\]: expected 3 numbers"),
        ([[0.4, 0.1, 0.3]], {"max_jump": float("nan")}, "max_jump"),
        ([[0.4, 0.1, 0.3]], {"max_jump": 0.0}, "max_jump"),
        ([[0.4, 0.1, 0.3]], {"margin": float("inf")}, "margin"),
        ([[0.4, 0.1, 0.3]], {"frame": "nope"}, "frame"),
        ([[0.4, 0.1, 0.3]], {"rotation": [0, 0, 0, 0]}, "rotation"),
    ],
)
def test_cartesian_path_refuses_bad_arguments_by_name(positions, kwargs, match):
    robot = load_robot3d("ur5e")
    rotation = kwargs.pop("rotation", _fk(robot, UR5E_Q, "gripper_tcp").rotation)
    with pytest.raises(InputError, match=match):
        cartesian_path(robot, UR5E_Q, positions, rotation, **kwargs)


def test_cartesian_path_takes_one_point_or_several():
    robot = load_robot3d("ur5e")
    tcp = _fk(robot, UR5E_Q, "gripper_tcp")
    up = tcp.translation + np.array([0.0, 0.0, 0.01])
    one = cartesian_path(robot, UR5E_Q, tcp.translation, tcp.rotation, margin=-1.0)
    two = cartesian_path(
        robot, UR5E_Q, [tcp.translation, up], tcp.rotation,
        margin=-1.0,
    )  # fmt: skip
    assert one.shape == (2, 6) and two.shape == (3, 6)
    assert np.linalg.norm(frame_pose(robot, two[-1]).translation - up) < 1e-4


@settings(max_examples=15, deadline=None)
@given(
    st.one_of(
        st.integers(-(2**70), -1),
        st.floats(allow_nan=True),
        st.booleans(),
        st.text(max_size=3),
    )
)
@example(-1)  # the audit's case: numpy's ValueError, exit 3 from a problem file's caller
def test_a_bad_ik_seed_is_an_input_error_naming_it(seed):
    """solve_pose_ik and collision_fraction check their seed as every other seed is checked
    (a negative one raised numpy's ValueError, a float numpy's TypeError)."""
    from gdnplan.arm3d.problem3d import collision_fraction

    scene = Scene3D(load_robot3d("ur5e"))
    with pytest.raises(InputError, match="seed: expected"):
        solve_pose_ik(scene, (0.4, 0.0, 0.5), seed=seed)
    with pytest.raises(InputError, match="seed: expected"):
        collision_fraction(scene, n=2, seed=seed)
