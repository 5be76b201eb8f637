"""The 3-D certificate's motion bound per joint kind: a prismatic joint moves every point below
it by its whole travel (its lever arm was the shape's radius, and a slider was certified
straight through a wall); kinds without a proven bound are refused."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from gdnplan.arm3d import LinkShape, Robot3D, Scene3D, box_obstacle, checker3d
from gdnplan.arm3d.ccd3d import certify_path3d, lever_arms3d
from gdnplan.arm3d.shapes import bounding_sphere
from gdnplan.errors import InputError


def _robot(*joints: pin.JointModel) -> Robot3D:
    """A serial chain of ``joints`` (each 0.3 m along x from its parent) with a 10 cm cube on
    the last body."""
    model = pin.Model()
    parent = 0
    for i, joint in enumerate(joints):
        offset = pin.SE3(np.eye(3), np.array([0.3 * (i > 0), 0.0, 0.0]))
        parent = model.addJoint(parent, joint, offset, f"j{i}")
        model.appendBodyToJoint(parent, pin.Inertia.Random(), pin.SE3.Identity())
        model.addFrame(pin.Frame(f"link{i}", parent, 0, pin.SE3.Identity(), pin.FrameType.BODY))
    model.lowerPositionLimit[:] = -5.0
    model.upperPositionLimit[:] = 5.0
    cube = coal.Box(0.1, 0.1, 0.1)
    center, radius = bounding_sphere(cube)
    shape = LinkShape("cube", f"link{len(joints) - 1}", parent, cube, np.eye(4), center, radius)
    return Robot3D("chain", model, [shape], np.zeros((0, 2), int), {})


@given(qa=st.floats(-3.0, 3.0), qb=st.floats(-3.0, 3.0), splits=st.integers(1, 8))
@example(qa=-2.0, qb=2.5, splits=4)  # the old arm (8.7 cm per m) proved it 0.41 m clear
@settings(max_examples=25, deadline=None)
def test_a_certified_slide_keeps_its_bound_when_sampled_densely(qa, qb, splits):
    """A cube on a prismatic x joint past a wall at x = 0: a certified path's dense samples
    never fall below the certificate's bound."""
    robot = _robot(pin.JointModelPX())
    scene = Scene3D(robot, [box_obstacle((0.1, 1.0, 1.0), (0.0, 0.0, 0.0))])
    path = np.array([[qa], [qb]])
    cert = certify_path3d(scene, path, margin=0.01, min_splits=splits)
    if cert.ok:
        s = np.linspace(0.0, 1.0, 20_001)[:, None]
        d = checker3d(scene).evaluate(path[0] + s * (path[1] - path[0])).distance
        assert d.min() >= cert.lower_bound - 1e-12


def test_a_prismatic_arm_is_one_metre_per_metre():
    """The slide moves the cube by its travel; the revolute joint at the cube's centre by the
    cube's half-diagonal per rad."""
    arms = lever_arms3d(_robot(pin.JointModelPX(), pin.JointModelRZ()))
    assert np.allclose(arms, [[1.0, 0.05 * np.sqrt(3)]])


@pytest.mark.parametrize(
    "joints",
    [
        (pin.JointModelRZ(), pin.JointModelPX()),  # a slide below a revolute joint
        (pin.JointModelHX(),),  # helical
        (pin.JointModelRUBZ(),),  # continuous, two coordinates
    ],
)
def test_joints_without_a_proven_bound_are_refused(joints):
    scene = Scene3D(_robot(*joints), [box_obstacle((0.1, 1.0, 1.0), (2.0, 0.0, 0.0))])
    q = np.zeros((2, scene.robot.dof))
    with pytest.raises(InputError, match="certificate"):
        certify_path3d(scene, q)
