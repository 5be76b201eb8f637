"""The held object in 3-D: a shape of the last body, its pairs (every link but the gripper
holding it), gradients against central differences, distances against coal called directly."""

from __future__ import annotations

import coal
import numpy as np
import pytest

from gdnplan.arm3d import Checker3D, Scene3D, box_obstacle, random_boxes
from gdnplan.arm3d.builtin import ur5e3d
from gdnplan.arm3d.held import HELD_LINK, hold, stick
from gdnplan.arm3d.ik3d import frame_pose
from gdnplan.arm3d.pairs import checked_link_pairs
from gdnplan.arm3d.shapes import box
from gdnplan.errors import InputError

GRIPPER = {"wrist_3_link", "gripper_base_link", "left_finger_link", "right_finger_link"}
Q = np.array([0.3, -1.2, 1.4, -1.6, -1.57, 0.2])


@pytest.fixture(scope="module")
def held():
    return hold(ur5e3d(finger=0.015), *stick(0.25, 0.03))


def _coal(shape_a, tf_a, shape_b, tf_b) -> float:
    """Signed distance of two posed shapes from coal directly."""
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    req.enable_signed_distance = True
    pose = [coal.Transform3s(t[:3, :3], t[:3, 3]) for t in (tf_a, tf_b)]
    return float(coal.distance(shape_a, pose[0], shape_b, pose[1], req, res))


def test_the_stick_sits_between_the_closed_fingers_along_the_tool_axis(held):
    tcp = frame_pose(held, Q)
    tfs = held.shape_placements(Q)
    axis = tcp.rotation[:, 2]
    # its near end 0.02 m in front of the palm (the palm 0.025 m behind the tcp), 0.25 m long
    assert np.allclose(tfs[-1][:3, 3], tcp.translation + (0.02 - 0.025 + 0.125) * axis)
    assert np.allclose(tfs[-1][:3, :3], tcp.rotation)
    fingers = [k for k, s in enumerate(held.shapes) if s.link.endswith("finger_link")]
    for k in fingers:  # the closed fingers (0.015 m each) touch its sides
        d = _coal(held.shapes[k].shape, tfs[k], held.shapes[-1].shape, tfs[-1])
        assert abs(d) < 1e-9


def test_held_pairs_are_every_link_but_the_gripper_holding_it(held):
    base = ur5e3d(finger=0.015)
    links = set(base.links)
    pairs = checked_link_pairs(held)
    with_held = {next(iter(p - {HELD_LINK})) for p in pairs if HELD_LINK in p}
    assert with_held == links - GRIPPER  # wrist_2 (adjacent to the wrist-3 body) is checked
    assert pairs - {p for p in pairs if HELD_LINK in p} == checked_link_pairs(base)
    for link in GRIPPER:
        assert held.disabled[frozenset((link, HELD_LINK))].startswith("same body")


def test_self_distance_of_the_stick_matches_coal_called_directly(held):
    """Per-link distance of the held object (self pairs only) = min over its checked links."""
    checker = Checker3D(Scene3D(held), tolerance=1e-9)
    k = held.links.index(HELD_LINK)
    others = [i for i, s in enumerate(held.shapes[:-1]) if s.link not in GRIPPER]
    negative = 0
    for q in held.random_configurations(40, np.random.default_rng(0)):
        tfs = held.shape_placements(q)
        truth = min(
            _coal(held.shapes[i].shape, tfs[i], held.shapes[-1].shape, tfs[-1]) for i in others
        )
        got = checker.evaluate(q, per_link=True).distance[0, k]
        assert got == pytest.approx(truth, abs=1e-6)
        negative += truth < 0
    assert negative >= 2  # the stick does hit the arm on some random configurations


def test_gradients_with_the_held_object_match_central_differences(held):
    """Stick–box pairs (polytopes): the held link's gradient matches to 1e-5 relative."""
    scene = random_boxes(held, 20, seed=3)
    checker = Checker3D(scene, tolerance=1e-9)
    k, h = held.links.index(HELD_LINK), 1e-5
    checked = 0
    for q in held.random_configurations(150, np.random.default_rng(4)):
        res = checker.evaluate(q, per_link=True, gradient=True)
        pair = res.pair[0, k]
        if pair < 0 or checker.is_self[pair]:
            continue
        fd, same = np.zeros(held.dof), True
        for j in range(held.dof):
            e = np.eye(held.dof)[j] * h
            plus = checker.evaluate(q + e, per_link=True)
            minus = checker.evaluate(q - e, per_link=True)
            same &= plus.pair[0, k] == pair == minus.pair[0, k]
            fd[j] = (plus.distance[0, k] - minus.distance[0, k]) / (2 * h)
        if not same:
            continue
        g = res.gradient[0, k]
        assert np.linalg.norm(g - fd) <= 1e-5 * max(np.linalg.norm(fd), 1e-2)
        checked += 1
    assert checked >= 10


def test_an_obstacle_ahead_of_the_stick_is_seen_by_the_held_link_only(held):
    tip = held.shape_placements(Q)[-1]
    ahead = tip[:3, 3] + tip[:3, :3] @ np.array([0, 0, 0.2])  # 0.075 m past the stick's end
    obstacle = [box_obstacle((0.05, 0.05, 0.05), ahead, tip[:3, :3])]  # aligned with it
    checker = Checker3D(Scene3D(held, obstacle))
    d, _ = checker.pair_distances(Q)
    obstacle_pairs = d[0, : checker.n_obstacle_pairs]  # one per robot shape, in shape order
    assert obstacle_pairs[-1] == pytest.approx(0.075 - 0.025, abs=1e-6)  # the stick's
    assert obstacle_pairs[:-1].min() > 0.1  # the arm and gripper are far from it
    k = held.links.index(HELD_LINK)
    assert checker.evaluate(Q, per_link=True).distance[0, k] == pytest.approx(0.05, abs=1e-6)


def test_bad_holds_are_input_errors(held):
    with pytest.raises(InputError, match="already holds"):
        hold(held, box((0.1, 0.1, 0.1)))
    with pytest.raises(InputError, match="frame"):
        hold(ur5e3d(), box((0.1, 0.1, 0.1)), frame="nowhere")
    with pytest.raises(InputError, match="placement"):
        hold(ur5e3d(), box((0.1, 0.1, 0.1)), np.eye(3))
    bad = np.eye(4)
    bad[:3, :3] = np.diag([1, 1, -1])
    with pytest.raises(InputError, match="rotation"):
        hold(ur5e3d(), box((0.1, 0.1, 0.1)), bad)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ({"placement": "x"}, r"^placement: expected a \(4, 4\) transform, got 'x'"),  # ValueError
        ({"placement": np.eye(4) + 0.5j}, r"^placement: expected a \(4, 4\) transform"),  # cast
        ({"placement": [[1, 0], [0]]}, r"^placement: expected a \(4, 4\) transform"),
        ({"name": 3}, r"^name: expected the held object's name \(a string\), got 3"),
        ({"robot": None}, r"^robot: expected a Robot3D, got NoneType"),  # AttributeError
    ],
)
def test_hostile_hold_arguments_are_input_errors(args, message):
    robot = args.pop("robot", ur5e3d())
    with pytest.raises(InputError, match=message):
        hold(robot, box((0.1, 0.1, 0.1)), **args)
