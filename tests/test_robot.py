import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.robot import as_batch


@pytest.mark.parametrize("name", ["planar2", "planar7"])
def test_planar_chain_equals_pinocchio(name):
    robot = gp.load_robot(name)
    q = robot.sample(20, seed=1)
    np.testing.assert_allclose(
        robot.node_positions(q), robot.node_positions_pinocchio(q), atol=1e-12
    )
    np.testing.assert_allclose(
        robot.node_jacobians(q), robot.node_jacobians_pinocchio(q), atol=1e-12
    )


@pytest.mark.parametrize("name", ["planar2", "planar7"])
def test_node_jacobians_match_finite_differences(name):
    robot = gp.load_robot(name)
    q = robot.sample(10, seed=2)
    jac = robot.node_jacobians(q)
    eps = 1e-6
    for j in range(robot.dof):
        dq = np.zeros(robot.dof)
        dq[j] = eps
        fd = (robot.node_positions(q + dq) - robot.node_positions(q - dq)) / (2 * eps)
        np.testing.assert_allclose(jac[..., j], fd, atol=1e-8)


def test_planar_dimensions():
    p2, p7 = gp.load_robot("planar2"), gp.load_robot("planar7")
    assert (p2.dof, p7.dof) == (2, 7)
    assert p2.reach == pytest.approx(1.2, abs=0.01)
    assert p7.reach == pytest.approx(2.1, abs=0.01)
    # at q = 0 the arm lies along +x: the tip of the last link is at the reach
    tip = p7.link_polygons(np.zeros(7))[-1]
    assert tip[:, 0].max() == pytest.approx(2.1)
    assert np.ptp(tip[:, 1]) == pytest.approx(0.06)


def test_sample_within_limits_and_seeded():
    robot = gp.load_robot("planar7")
    q = robot.sample(1000, seed=5)
    assert q.shape == (1000, 7)
    assert robot.within_limits(q).all()
    np.testing.assert_array_equal(q, robot.sample(1000, seed=5))


def test_link_polygons_are_ccw_rectangles():
    robot = gp.load_robot("planar2")
    for poly in robot.link_polygons(np.array([0.3, -1.0])):
        assert poly.shape == (4, 2)
        assert gp.geometry.signed_area(poly) == pytest.approx(0.6 * 0.06)


def test_body_poses_place_bodies():
    robot = gp.load_robot("planar2")
    pose = robot.body_poses(np.array([np.pi / 2, np.pi / 2]))[0]
    np.testing.assert_allclose(pose[1], [0, 0, np.pi / 2], atol=1e-12)
    # body 2 rotates about joint 2, which sits at (0, 0.6): x0 = 0 maps to (0.6, 0.6)
    np.testing.assert_allclose(pose[2], [0.6, 0.6, np.pi], atol=1e-12)


@pytest.mark.parametrize("name", ["planar7", "ur5e"])
def test_body_poses_equal_the_chain_transform(name):
    robot = gp.load_robot(name)
    q = robot.sample(50, seed=0)
    poses = robot.body_poses(q)
    bodies = np.arange(robot.dof + 1)
    origin = robot.chain.transform(np.zeros((robot.dof + 1, 2)), bodies, q)  # image of 0
    np.testing.assert_allclose(poses[..., :2], origin, atol=1e-12)
    unit_x = robot.chain.transform(np.tile([1.0, 0.0], (robot.dof + 1, 1)), bodies, q) - origin
    np.testing.assert_allclose(np.cos(poses[..., 2]), unit_x[..., 0], atol=1e-12)
    np.testing.assert_allclose(np.sin(poses[..., 2]), unit_x[..., 1], atol=1e-12)


@pytest.mark.parametrize(
    ("q", "message"),
    [(np.zeros(3), "shape"), (np.array([0.0, np.nan]), "NaN"), ("ab", "numbers")],
)
def test_bad_q_raises_input_error(q, message):
    robot = gp.load_robot("planar2")
    with pytest.raises(gp.InputError, match=message):
        robot.node_positions(q)


def test_as_batch_promotes_single_configuration():
    assert as_batch([0.1, 0.2], 2).shape == (1, 2)


def test_unknown_robot_names_choices():
    with pytest.raises(gp.UnknownNameError, match="planar7"):
        gp.load_robot("planar9")


@pytest.mark.parametrize("n", [-1, 1.5, True, "3", None, 10**12])
def test_sample_refuses_a_count_that_is_not_a_sane_integer(n):
    with pytest.raises(gp.InputError, match="n:"):
        gp.load_robot("planar2").sample(n)


@settings(max_examples=40, deadline=None)
@given(
    rows=st.integers(1, 6),
    step=st.sampled_from([1, -1, 2, -2]),
    order=st.sampled_from(["C", "F"]),
    dtype=st.sampled_from([np.float64, np.float32, np.int16]),
)
@example(rows=3, step=-1, order="C", dtype=np.float64)
def test_as_batch_returns_c_contiguous_copies_of_views(rows, step, order, dtype):
    """A negative-stride view passed through as a view, which torch.as_tensor refused."""
    base = np.asarray(np.arange(rows * 2 * 4).reshape(rows * 2, 4), dtype=dtype, order=order)
    view = base[::step, ::-1] if step < 0 else base[::step]
    out = as_batch(view, 4)
    assert out.flags.c_contiguous and out.dtype == np.float64
    np.testing.assert_array_equal(out, view.astype(float))
