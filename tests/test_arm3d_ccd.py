"""The 3-D continuous certificate: sound lever arms, no certificate through an obstacle, and
certified segments stay free when sampled densely."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gdnplan.arm3d import Scene3D, box_obstacle, checker3d, load_robot3d, random_boxes
from gdnplan.arm3d.ccd3d import certify_path3d, lever_arms3d, motion_bound3d
from gdnplan.errors import InputError

HOME = np.array([0.0, -1.57, 1.57, -1.57, -1.57, 0.0])


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_lever_arms_bound_every_shape_from_every_joint_origin(name):
    robot = load_robot3d(name)
    arms = lever_arms3d(robot)
    for q in robot.random_configurations(20, np.random.default_rng(0)):
        tf = robot.shape_placements(q)
        origins = robot.body_placements(q)[:, :3, 3]
        for k, s in enumerate(robot.shapes):
            far = np.linalg.norm(tf[k, :3, :3] @ s.center + tf[k, :3, 3] - origins[1:], axis=1)
            moved = arms[k] > 0
            assert np.all(far[moved] + s.radius <= arms[k, moved] * (1 + 1e-12))
            support = set(robot.model.supports[s.body]) - {0}
            assert set(np.flatnonzero(moved) + 1) == support


def test_a_segment_through_an_obstacle_is_never_certified():
    robot = load_robot3d("ur5e")
    qa, qb = HOME, HOME + np.array([1.2, 0.0, 0.0, 0.0, 0.0, 0.0])
    mid = robot.shape_placements((qa + qb) / 2)
    gripper = [s.link for s in robot.shapes].index("gripper_base_link")
    scene = Scene3D(robot, [box_obstacle((0.05, 0.05, 0.05), mid[gripper, :3, 3])])
    ends = checker3d(scene).evaluate(np.stack([qa, qb])).distance
    assert np.all(ends > 0.02)  # both ends are free: only the motion collides
    cert = certify_path3d(scene, np.stack([qa, qb]))
    assert not cert.ok and cert.bad_segments == (0,) and cert.min_distance < 0


@given(seed=st.integers(0, 10_000), scale=st.floats(0.05, 0.6))
@settings(max_examples=8, deadline=None)
def test_a_certified_segment_sampled_densely_never_collides(seed, scale):
    robot = load_robot3d("ur5e")
    scene = random_boxes(robot, 20, seed=seed % 50)
    rng = np.random.default_rng(seed)
    qa = HOME + rng.normal(size=6) * 0.2
    qb = qa + rng.normal(size=6) * scale
    cert = certify_path3d(scene, np.stack([qa, qb]))
    if not cert.ok:
        return
    s = np.linspace(0, 1, 200)[:, None]
    d = checker3d(scene).evaluate(qa + s * (qb - qa)).distance
    assert d.min() >= cert.lower_bound - 1e-9 and d.min() > 0


def test_certificate_input_errors():
    scene = Scene3D(load_robot3d("ur5e"), [])
    with pytest.raises(InputError, match="2 waypoints"):
        certify_path3d(scene, HOME[None])
    with pytest.raises(InputError, match="margin"):
        certify_path3d(scene, np.stack([HOME, HOME]), margin=-1.0)
    with pytest.raises(InputError, match=r"^stop_early: expected True or False, got 'no'$"):
        certify_path3d(scene, np.stack([HOME, HOME]), stop_early="no")


@pytest.mark.parametrize(
    ("robot", "qa", "qb", "message"),
    [
        ("ur5e", HOME[None], HOME[None, :5], r"^qb: expected shape \(B, 6\)"),  # broadcast error
        ("ur5e", HOME + 1j, HOME, r"^qa: expected real numbers"),  # imaginary part dropped
        ("ur5e", HOME * np.nan, HOME, r"^qa: contains NaN"),  # a NaN bound
        ("ur5e", np.stack([HOME] * 3), np.stack([HOME] * 2), r"^qa, qb: expected as many"),
        (None, HOME, HOME, r"^robot: expected a Robot3D, got NoneType"),  # AttributeError
        ("planar2", HOME, HOME, r"^robot: expected a Robot3D, got Robot; a planar Robot"),
    ],
)
def test_motion_bounds_check_robot_and_configurations(robot, qa, qb, message):
    import gdnplan as gp

    robot = {"ur5e": load_robot3d("ur5e"), "planar2": gp.load_robot("planar2")}.get(robot)
    with pytest.raises(InputError, match=message):
        motion_bound3d(robot, qa, qb)
    if robot is None or robot.name == "planar2":
        with pytest.raises(InputError, match=message):
            lever_arms3d(robot)


def test_one_configuration_pairs_with_a_batch():
    robot = load_robot3d("ur5e")
    batch = HOME + np.linspace(0, 0.1, 4)[:, None]
    assert np.allclose(motion_bound3d(robot, HOME, batch), motion_bound3d(robot, batch, HOME))
