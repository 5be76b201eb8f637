"""Contact-only self pairs: the UR5e's forearm against wrist 2 and wrist 3 can collide, stay
closer than any useful margin, and are checked for d ≥ 0 (gdnplan.arm3d.pairs)."""

from __future__ import annotations

import itertools
import math

import coal
import numpy as np
import pinocchio as pin
import pytest

from gdnplan import plan
from gdnplan.arm3d import Scene3D, certify_path3d, checker3d, load_robot3d, signed_distance3d
from gdnplan.arm3d.builtin import UR5E_CONTACT_ONLY, UR5E_JOINTS
from gdnplan.arm3d.ccd3d import Certificate3D
from gdnplan.arm3d.distance3d import Coal3DModel
from gdnplan.arm3d.narrow3d import PairTable
from gdnplan.arm3d.robot3d import robot3d_from_urdf
from gdnplan.assets import robot_urdf
from gdnplan.errors import InfeasibleProblemError, InputError
from gdnplan.trajopt import Problem

# the reproducer: wrist 2's cylinder 8 mm inside the forearm's, every other pair clear
START = np.array([0.0, -1.6902, 0.5121, 1.4892, -2.4591, -3.2126])
GOAL = START + np.array([0.5, 0, 0, 0, 0, 0])


@pytest.fixture(scope="module")
def ur5e():
    return load_robot3d("ur5e")


def _adjacent_or_same(model: pin.Model, a: str, b: str) -> bool:
    """From the full URDF model alone: links on one joint or joined by one joint."""
    ja, jb = (model.frames[model.getFrameId(link)].parentJoint for link in (a, b))
    return ja == jb or model.parents[ja] == jb or model.parents[jb] == ja


def all_pair_minimum(robot, q: np.ndarray) -> float:
    """min signed distance (m) over every shape pair of two links that are neither adjacent
    nor on one joint of the URDF (SRDF-disabled and contact-only pairs included), straight
    from coal: independent of the robot's pair table."""
    full = pin.buildModelFromUrdf(str(robot_urdf("ur5e")))
    tf = robot.shape_placements(q)
    request = coal.DistanceRequest()
    request.enable_signed_distance = True
    best = math.inf
    for i, j in itertools.combinations(range(len(robot.shapes)), 2):
        a, b = robot.shapes[i], robot.shapes[j]
        if a.link == b.link or _adjacent_or_same(full, a.link, b.link):
            continue
        result = coal.DistanceResult()
        ta = coal.Transform3s(tf[i, :3, :3], tf[i, :3, 3])
        tb = coal.Transform3s(tf[j, :3, :3], tf[j, :3, 3])
        coal.distance(a.shape, ta, b.shape, tb, request, result)
        best = min(best, float(result.min_distance))
    return best


def test_the_ur5e_declares_the_forearm_wrist_pairs_contact_only(ur5e):
    pairs = {frozenset(p) for p in UR5E_CONTACT_ONLY}
    assert ur5e.contact_only == pairs
    assert not pairs & set(ur5e.disabled)  # checked, not disabled
    keys = _link_pairs(ur5e)
    flagged = {k for k, c in zip(keys, ur5e.self_contact_only, strict=True) if c}
    assert flagged == pairs and pairs <= set(keys)


def _link_pairs(robot):
    return [frozenset((robot.shapes[i].link, robot.shapes[j].link)) for i, j in robot.self_pairs]


def test_pair_table_offsets_mark_the_contact_only_pairs(ur5e):
    table = PairTable(Scene3D(ur5e, []))
    contact = np.array([p in ur5e.contact_only for p in _link_pairs(ur5e)])
    assert np.array_equal(table.contact_only, contact)
    assert np.array_equal(table.offsets(0.02), np.where(contact, 0.02, 0.0))
    assert np.all(table.offsets(0.0) == 0.0)
    for bad in (np.nan, -np.inf, "x", True):
        with pytest.raises(InputError, match="contact_offset"):
            table.offsets(bad)


def test_offsets_shift_the_minimum_and_true_distances_include_contact_pairs(ur5e):
    scene = Scene3D(ur5e, [])
    checker = checker3d(scene)
    q = ur5e.random_configurations(40, np.random.default_rng(3))
    pairs, _ = checker.pair_distances(q)  # (B, P) true distances of every pair
    contact = checker.contact_only
    for offset in (0.0, 0.02, 0.5):
        got = checker.evaluate(q, contact_offset=offset).distance
        assert np.allclose(got, np.min(pairs + np.where(contact, offset, 0.0), axis=1))
    assert np.allclose(checker.evaluate(q).distance, np.min(pairs[:, ~contact], axis=1))
    assert np.allclose(signed_distance3d(scene, q), np.min(pairs, axis=1))  # no offsets
    d_true = signed_distance3d(scene, START)[0]
    assert d_true < -0.005  # wrist 2 inside the forearm: a true, negative distance
    assert Coal3DModel().distance(scene, START)[0] == pytest.approx(d_true)
    shifted = checker.evaluate(START, contact_offset=0.02).distance[0]
    assert Coal3DModel(0.02).distance(scene, START)[0] == pytest.approx(shifted)
    assert shifted <= d_true + 0.02 + 1e-12
    per_link = checker.evaluate(q, per_link=True, contact_offset=0.02).distance
    assert np.allclose(per_link.min(axis=1), checker.evaluate(q, contact_offset=0.02).distance)


def test_the_certificate_refuses_the_reproducer_path(ur5e):
    scene = Scene3D(ur5e, [])
    cert = certify_path3d(scene, np.stack([START, GOAL]), margin=0.0)
    assert isinstance(cert, Certificate3D) and not cert.ok
    assert "forearm_link–wrist_2_link" in cert.contact_only


def test_planning_the_reproducer_at_margin_zero_never_certifies_a_collision(ur5e):
    scene = Scene3D(ur5e, [])
    try:
        problem = Problem(scene, START, goal=GOAL, waypoints=6, margin=0.0)
    except InfeasibleProblemError as e:
        assert "contact-only" in str(e)
        return
    result = plan(problem)
    if result.success:  # then every shape pair must be clear along the dense path
        s = np.linspace(0.0, 1.0, 200)[:, None]
        for qa, qb in itertools.pairwise(result.q):
            for q in qa + s * (qb - qa):
                assert all_pair_minimum(ur5e, q) >= -1e-6


def test_the_pointwise_certificate_accepts_only_configurations_clear_of_every_pair(ur5e):
    scene = Scene3D(ur5e, [])
    rng = np.random.default_rng(11)
    near = START + rng.normal(0.0, 0.03, (30, 6))  # around the reproducer
    q = np.vstack([START, near, ur5e.random_configurations(150, rng)])
    truth = np.array([all_pair_minimum(ur5e, qi) for qi in q])
    accepted = np.array(
        [certify_path3d(scene, np.stack([qi, qi]), margin=0.0, min_splits=1).ok for qi in q]
    )
    assert np.all(truth[accepted] >= 0.0)
    # the test can fail: some configurations collide only through a contact-only pair
    checker = checker3d(scene)
    hidden = (checker.evaluate(q).distance > 0.0) & (truth < 0.0)
    assert hidden.any() and not accepted[hidden].any()


def test_contact_at_the_default_margin_needs_only_d_geq_zero(ur5e):
    scene = Scene3D(ur5e, [])
    q = ur5e.random_configurations(60, np.random.default_rng(5))
    checker = checker3d(scene)
    d = checker.evaluate(q, contact_offset=0.02).distance
    pairs, _ = checker.pair_distances(q)
    contact = checker.contact_only
    ok = (pairs[:, ~contact].min(axis=1) >= 0.02) & (pairs[:, contact].min(axis=1) >= 0.0)
    assert np.array_equal(d >= 0.02, ok)
    assert (pairs[:, contact].min(axis=1) < 0.02).all()  # the margin would never fit


URDF = robot_urdf("ur5e")


@pytest.mark.parametrize(
    "pairs, match",
    [
        ([("forearm_link", "nowhere")], "not a link with collision shapes"),
        ([("forearm_link", "forearm_link")], "itself"),
        ([("forearm_link", "wrist_1_link")], "adjacent"),
        ([("base_link", "upper_arm_link")], "srdf"),
        ([("forearm_link",)], "pair of link names"),
        ("forearm_link", "list of"),
    ],
)
def test_bad_contact_only_pairs_are_input_errors(pairs, match):
    locked = {"left_finger_joint": 0.02, "right_finger_joint": 0.02}
    srdf = URDF.with_suffix(".srdf")
    with pytest.raises(InputError, match=match):
        robot3d_from_urdf(URDF, joints=UR5E_JOINTS, locked=locked, srdf=srdf, contact_only=pairs)


def test_a_user_robot_declares_its_own_contact_only_pairs():
    locked = {"left_finger_joint": 0.02, "right_finger_joint": 0.02}
    robot = robot3d_from_urdf(
        URDF, joints=UR5E_JOINTS, locked=locked, contact_only=[("wrist_1_link", "wrist_3_link")]
    )
    assert robot.contact_only == {frozenset(("wrist_1_link", "wrist_3_link"))}
    assert robot.self_contact_only.sum() >= 1


@pytest.mark.parametrize(
    "path",
    [
        "problems/fetch3d/fetch3d_approach.toml",
        "problems/fetch3d/fetch3d_reach_in.toml",
        "problems/fetch3d/fetch3d_bring_out.toml",
        "problems/ur5e_boxes3d.toml",  # margin 0.02, a real solve (about a minute)
    ],
)
def test_shipped_ur5e_problems_still_plan_and_certify(path):
    problem = Problem.from_toml(path)
    result = plan(problem)
    assert result.success, result.reason
    scene = problem.scene
    assert certify_path3d(scene, result.q, problem.certified_clearance).ok
    s = np.linspace(0.0, 1.0, 50)[:, None]
    dense = np.concatenate([a + s * (b - a) for a, b in itertools.pairwise(result.q)])
    pairs, _ = checker3d(scene).pair_distances(dense)
    contact = checker3d(scene).contact_only
    assert contact.any() and pairs[:, contact].min() >= 0.0  # contact-only pairs: d ≥ 0
