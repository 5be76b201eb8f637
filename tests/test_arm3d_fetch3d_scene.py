"""The 3-D fetch scene: configurations put the tcp on the storage's poses, keep their
clearance, and the straight tool lines through the entrance are certified collision-free."""

from __future__ import annotations

import numpy as np
import pytest

from gdnplan.arm3d import certify_path3d, checker3d
from gdnplan.arm3d.fetch3d_scene import CONFIGS, MIN_CLEARANCE, fetch3d
from gdnplan.arm3d.held import HELD_LINK
from gdnplan.arm3d.ik3d import frame_pose
from gdnplan.arm3d.storage3d import Placement, tool_poses
from gdnplan.errors import InfeasibleProblemError, InputError

STATE = {"q_home": "open", "q_pregrasp": "open", "q_grasp": "open"}
STATE |= {"q_lift": "holding", "q_out": "holding"}


@pytest.fixture(scope="module", params=[0, 3])
def fetch(request):
    return fetch3d(request.param)


def test_configurations_reach_the_storage_poses_with_their_clearance(fetch):
    poses = tool_poses(fetch.storage, fetch.placement)
    axis = fetch.placement.transform()[:3, 0]
    for key in CONFIGS:
        scene = fetch.scenes[STATE[key]]
        tcp = frame_pose(scene.robot, fetch.q[key])
        assert np.linalg.norm(tcp.translation - poses[key[2:]]) < 1e-4
        assert np.allclose(tcp.rotation[:, 2], axis, atol=1e-3)  # tool axis into the box
        assert checker3d(scene).evaluate(fetch.q[key]).distance[0] >= MIN_CLEARANCE
    home = checker3d(fetch.scenes["holding"]).evaluate(fetch.q["q_home"]).distance[0]
    assert home >= MIN_CLEARANCE  # the retreat ends there holding the stick


def test_the_tool_lines_are_straight_and_certified(fetch):
    for name, state, margin, start in (
        ("reach_in", "open", 0.01, 0),
        ("lift", "holding", 0.0, 1),  # from the first point off the shelf
        ("bring_out", "holding", 0.01, 0),
    ):
        path = fetch.lines[name]
        scene = fetch.scenes[state]
        tcp = np.array([frame_pose(scene.robot, q).translation for q in path])
        direction = (tcp[-1] - tcp[0]) / np.linalg.norm(tcp[-1] - tcp[0])
        off_line = (tcp - tcp[0]) - np.outer((tcp - tcp[0]) @ direction, direction)
        assert np.abs(off_line).max() < 1e-4
        assert np.abs(np.diff(path, axis=0)).max() <= 0.3
        cert = certify_path3d(scene, path[start:], margin=margin)
        assert cert.ok, (name, cert.reason)


def test_the_grasped_stick_rests_on_its_shelf_and_is_part_of_the_robot(fetch):
    held = fetch.scenes["holding"]
    assert HELD_LINK in held.robot.links
    assert "stick" in [o.name for o in fetch.scenes["open"].obstacles]
    assert "stick" not in [o.name for o in held.obstacles]
    at_grasp = checker3d(held).evaluate(fetch.q["q_grasp"], per_link=True).distance[0]
    assert abs(at_grasp[held.robot.links.index(HELD_LINK)]) < 1e-6  # contact, not penetration


def test_a_storage_facing_away_is_out_of_reach():
    with pytest.raises(InfeasibleProblemError, match="fetch3d"):
        fetch3d(0, placement=Placement(0.7, 0.0, np.pi))


def test_bad_seeds_and_placements_off_the_table_are_input_errors():
    for bad in (-1, 1.5, "1", True):
        with pytest.raises(InputError, match="seed"):
            fetch3d(bad)
    with pytest.raises(InputError, match="off the table"):
        fetch3d(0, placement=Placement(1.0, 0.0, 0.0))
