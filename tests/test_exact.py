"""The exact-geometry protocol (gdnplan.exact): each scene kind answers with its own exact
geometry, and an unknown kind is refused."""

import numpy as np
import pytest

import gdnplan as gp
from gdnplan.arm3d import (
    Scene3D,
    box_obstacle,
    certify_path3d,
    checker3d,
    load_robot3d,
    motion_bound3d,
    signed_distance3d,
)
from gdnplan.ccd import certify_path, motion_bound
from gdnplan.distance import signed_distance
from gdnplan.errors import InputError
from gdnplan.exact import certify, closest_pair, exact_distance, motion_bound_of


def planar_scene():
    return gp.make_scene("d", seed=3)


def scene3d():
    return Scene3D(load_robot3d("ur5e"), [box_obstacle((0.2, 0.2, 0.2), (0.5, 0.0, 0.3))])


def test_each_kind_answers_with_its_own_geometry():
    s2, s3 = planar_scene(), scene3d()
    q2, q3 = s2.robot.sample(6, seed=1), np.random.default_rng(0).uniform(-3, 3, (6, 6))
    np.testing.assert_array_equal(exact_distance(s2, q2), signed_distance(s2, q2))
    # margin 0: true distances (contact-only self pairs included, gdnplan.arm3d.pairs)
    np.testing.assert_array_equal(exact_distance(s3, q3, margin=0.0), signed_distance3d(s3, q3))
    np.testing.assert_array_equal(
        exact_distance(s3, q3, per_link=True, margin=0.0),
        signed_distance3d(s3, q3, per_link=True),
    )
    left_out = checker3d(s3).evaluate(q3).distance  # no margin: contact-only pairs left out
    np.testing.assert_array_equal(exact_distance(s3, q3), left_out)
    shifted = checker3d(s3).evaluate(q3, contact_offset=0.02).distance
    np.testing.assert_array_equal(exact_distance(s3, q3, margin=0.02), shifted)
    np.testing.assert_array_equal(
        motion_bound_of(s2.robot, q2[:3], q2[3:]), motion_bound(s2.robot, q2[:3], q2[3:])
    )
    np.testing.assert_array_equal(
        motion_bound_of(s3.robot, q3[:3], q3[3:]), motion_bound3d(s3.robot, q3[:3], q3[3:])
    )


def test_certify_is_the_scene_kinds_certificate():
    s2, s3 = planar_scene(), scene3d()
    path2 = s2.robot.sample(3, seed=2)
    a, b = certify(s2, path2, 0.0), certify_path(s2, path2, 0.0)
    assert (a.ok, a.lower_bound, a.n_checks) == (b.ok, b.lower_bound, b.n_checks)
    path3 = np.array([[0.0, -1.5, 0.0, -1.5, 0.0, 0.0], [0.3, -1.4, 0.2, -1.5, 0.1, 0.0]])
    c = certify(s3, path3, 0.0, tol=np.inf)
    d = certify_path3d(s3, path3, 0.0)
    assert (c.ok, c.lower_bound, c.n_checks) == (d.ok, d.lower_bound, d.n_checks)


def test_certify_with_tol_brackets_the_minimum_more_tightly():
    s3 = scene3d()
    path = np.array([[0.0, -1.5, 0.0, -1.5, 0.0, 0.0], [0.8, -1.2, 0.4, -1.5, 0.3, 0.0]])
    loose, tight = certify(s3, path, 0.0, tol=np.inf), certify(s3, path, 0.0, tol=1e-3)
    assert loose.ok and tight.ok
    assert tight.lower_bound >= loose.lower_bound
    assert tight.min_distance - tight.lower_bound <= 1e-3 + 1e-9


def test_closest_pair_names_a_self_collision():
    robot = load_robot3d("ur5e")
    scene = Scene3D(robot, [])
    q = np.array([0.0, -1.57, 2.9, 0.0, 0.0, 0.0])  # elbow folded: forearm into upper arm
    if exact_distance(scene, q)[0] > 0:
        pytest.skip("this configuration is not in self-collision for this model")
    assert "self-collision" in closest_pair(scene, q)


def test_an_unknown_scene_kind_is_refused():
    with pytest.raises(InputError, match="expected a planar Scene or a Scene3D"):
        exact_distance(object(), np.zeros(2))
    with pytest.raises(InputError, match="expected a planar Scene or a Scene3D"):
        certify("scene", np.zeros((2, 2)))
