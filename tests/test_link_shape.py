"""A hand-built link shape is checked when made: the certificate's lever arms and the broad phase
trust its bounding sphere, and a 10 cm cube given radius 1e-6 m was certified 1 cm clear of a
wall its corners turned 1.07 cm into (the path's checked ends are the symmetric, clear poses)."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from gdnplan.arm3d import LinkShape, Robot3D, Scene3D, box_obstacle, checker3d
from gdnplan.arm3d.ccd3d import certify_path3d
from gdnplan.arm3d.shapes import bounding_sphere
from gdnplan.errors import InputError

CUBE = coal.Box(0.1, 0.1, 0.1)  # its bounding sphere: centre 0, radius 0.0866 m


def turner() -> pin.Model:
    """One revolute z joint at the origin with a link frame."""
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j0")
    model.appendBodyToJoint(j, pin.Inertia.Random(), pin.SE3.Identity())
    model.addFrame(pin.Frame("link0", j, 0, pin.SE3.Identity(), pin.FrameType.BODY))
    model.lowerPositionLimit[:] = -4.0
    model.upperPositionLimit[:] = 4.0
    return model


@settings(max_examples=30, deadline=None)
@given(
    radius=st.floats(0.0, 0.0866),
    center=st.lists(st.floats(-0.05, 0.05), min_size=3, max_size=3),
)
@example(radius=1e-6, center=[0.0, 0.0, 0.0])  # certified 1 cm clear through a wall
def test_a_sphere_that_does_not_enclose_the_shape_is_refused(radius, center):
    with pytest.raises(InputError, match=r"do not enclose its shape"):
        LinkShape("cube", "link0", 1, CUBE, np.eye(4), np.array(center), radius)


def test_the_crafted_turn_through_a_wall_is_refused_with_an_honest_sphere():
    center, radius = bounding_sphere(CUBE)
    shape = LinkShape("cube", "link0", 1, CUBE, np.eye(4), center, radius)
    robot = Robot3D("turner", turner(), [shape], np.zeros((0, 2), int), {})
    scene = Scene3D(robot, [box_obstacle((0.1, 1.0, 1.0), (0.11, 0.0, 0.0))])  # 1 cm from a face
    path = np.array([[-np.pi], [np.pi]])
    samples = np.linspace(-np.pi, np.pi, 2001)[:, None]
    assert checker3d(scene).evaluate(samples).distance.min() < -0.01  # the corners go in
    assert not certify_path3d(scene, path, margin=0.0).ok


@pytest.mark.parametrize(
    "field, value, message",
    [
        ("body", -1, r"\.body"),
        ("placement", np.diag([2.0, 1.0, 1.0, 1.0]), r"\.placement"),
        ("placement", np.zeros((3, 4)), r"\.placement"),
        ("shape", "box", r"expected a coal"),
        ("center", [np.nan, 0.0, 0.0], r"\.center"),
        ("radius", "1", r"do not enclose"),
    ],
)
def test_bad_link_shapes_are_input_errors(field, value, message):
    center, radius = bounding_sphere(CUBE)
    args = {
        "name": "cube",
        "link": "link0",
        "body": 1,
        "shape": CUBE,
        "placement": np.eye(4),
        "center": center,
        "radius": radius,
        field: value,
    }
    with pytest.raises(InputError, match=message):
        LinkShape(**args)


def test_a_shape_on_a_body_the_model_lacks_is_refused():
    center, radius = bounding_sphere(CUBE)
    shape = LinkShape("cube", "link0", 5, CUBE, np.eye(4), center, radius)
    with pytest.raises(InputError, match=r"hangs from body 5"):
        Robot3D("turner", turner(), [shape], np.zeros((0, 2), int), {})


@pytest.mark.parametrize("pairs", [[[0, 1]], [[-1, 0]]])
def test_self_pairs_name_shapes_the_robot_has(pairs):
    center, radius = bounding_sphere(CUBE)
    shape = LinkShape("cube", "link0", 1, CUBE, np.eye(4), center, radius)
    with pytest.raises(InputError, match=r"self_pairs"):
        Robot3D("turner", turner(), [shape], np.array(pairs), {})
