"""The contact certificate's bound on overlapping 3-D pairs (gdnplan.arm3d.depth3d), against an
analytic truth: a tilted cylinder on a turning arm pokes into a wide box from above, and its
penetration depth is the depth of its lowest point below the box top (the box is 4 m wide and
1 m thick, so pushing the cylinder up is the shortest way out). coal's EPA depth on the
cylinder stopped short of it by more than coal's slack, and a cylinder 10.3 µm deep was proven
never to be 10 µm deep."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from gdnplan.arm3d import LinkShape, Robot3D, Scene3D, box_obstacle, checker3d
from gdnplan.arm3d.depth3d import verified_pair
from gdnplan.arm3d.shapes import bounding_sphere
from gdnplan.ccd_contact import CONTACT_ALLOWANCE, certify_from_contact

# the crafted case: coal put this cylinder 7.9 µm deep, the certificate said d > −9.9 µm
CASE = {
    "radius": 0.0192840751443834,
    "length": 0.3995411636082378,
    "rotvec": [-0.09785948000657119, -1.247637072714629, 0.0],
    "depth": 1.0282135692784145e-05,
}


def cylinder_scene(radius: float, length: float, rotvec, depth: float) -> Scene3D:
    """One revolute z joint turning a cylinder (rotated by ``rotvec``, centre 0.5 m out) whose
    lowest point lies ``depth`` (m) below the top of a wide box (turning keeps the depth)."""
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j0")
    model.appendBodyToJoint(j, pin.Inertia.Random(), pin.SE3.Identity())
    model.addFrame(pin.Frame("link0", j, 0, pin.SE3.Identity(), pin.FrameType.BODY))
    model.lowerPositionLimit[:] = -3.0
    model.upperPositionLimit[:] = 3.0
    shape = coal.Cylinder(radius, length)
    rot = Rotation.from_rotvec(rotvec).as_matrix()
    placement = np.eye(4)
    placement[:3, :3], placement[:3, 3] = rot, [0.5, 0.0, 0.0]
    center, sphere = bounding_sphere(shape)
    link = LinkShape("cylinder", "link0", j, shape, placement, center, sphere)
    robot = Robot3D("turner", model, [link], np.zeros((0, 2), int), {})
    axis_z = rot[2, 2]  # the cylinder's lowest point lies this far below its centre:
    low = length / 2 * abs(axis_z) + radius * np.sqrt(max(0.0, 1.0 - axis_z**2))
    top = -low + depth
    return Scene3D(robot, [box_obstacle((4.0, 4.0, 1.0), (0.0, 0.0, top - 0.5))])


shapes = {
    "radius": st.floats(0.01, 0.3),
    "length": st.floats(0.03, 1.0),
    "rotvec": st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3),
}


@settings(max_examples=60, deadline=None)
@given(**shapes, depth=st.floats(CONTACT_ALLOWANCE, CONTACT_ALLOWANCE + 5e-6))
@example(**CASE)
def test_a_cylinder_deeper_than_the_allowance_is_never_proven(radius, length, rotvec, depth):
    scene = cylinder_scene(radius, length, rotvec, depth)
    assert not certify_from_contact(scene, np.zeros((1, 1))).ok
    assert not certify_from_contact(scene, np.array([[0.0], [0.01]])).ok  # a slide at that depth


@settings(max_examples=60, deadline=None)
@given(**shapes, depth=st.floats(-1e-4, 1e-3))
@example(**CASE)
def test_the_translated_bound_is_below_the_exact_distance_and_near_it(
    radius, length, rotvec, depth
):
    scene = cylinder_scene(radius, length, rotvec, depth)
    table = checker3d(scene)
    tf, _ = table.placements_batch(np.zeros((1, 1)))
    bound = verified_pair(table, 0, tf[0])
    assert bound <= -depth
    assert bound >= -depth - 1e-5  # tight: within 10 µm (the slack is ~2 µm)


def test_a_resting_cylinder_still_lifts_and_slides_a_little():
    scene = cylinder_scene(CASE["radius"], CASE["length"], CASE["rotvec"], 0.0)
    cert = certify_from_contact(scene, np.array([[0.0], [0.02]]))  # 1 cm along the box top
    assert cert.ok and cert.lower_bound > -CONTACT_ALLOWANCE
