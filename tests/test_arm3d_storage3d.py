"""The 3-D storage: its boxes leave the entrance open and hold the stick on its shelf, and
random placements stand on the table within the placement ranges."""

from __future__ import annotations

import coal
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gdnplan.arm3d.storage3d import (
    PLACEMENT_BEARING,
    PLACEMENT_RADIUS,
    PLACEMENT_YAW,
    Placement,
    check_placement,
    on_table,
    random_placement,
    random_storage,
    stick_obstacle,
    storage_obstacles,
    table_obstacle,
    tool_poses,
    tool_rotations,
)
from gdnplan.errors import InputError
from gdnplan.ur5e.gripper import BODY_DEPTH, BODY_WIDTH


def _inside(obstacles, point) -> bool:
    """True when a world point lies in one of the box obstacles (coal's own containment)."""
    probe = coal.Sphere(1e-6)
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    req.enable_signed_distance = True
    pose = coal.Transform3s(np.eye(3), np.asarray(point, float))
    return any(coal.distance(o.shape, o.pose, probe, pose, req, res) < 0 for o in obstacles)


def _to_world(placement, local):
    return (placement.transform() @ np.r_[local, 1.0])[:3]


@given(seed=st.integers(0, 10_000))
@settings(max_examples=25, deadline=None)
def test_the_entrance_is_open_and_the_stick_rests_on_its_shelf(seed):
    rng = np.random.default_rng(seed)
    s, p = random_storage(rng), random_placement(rng)
    boxes = storage_obstacles(s, p)
    # the gripper body's cross-section (plus 2 cm) fits the entrance all along the wall
    for x in np.linspace(-0.01, s.wall + 0.01, 5):
        for dy in (-1, 1):
            for dz in (-1, 1):
                y = dy * (BODY_WIDTH / 2 + 0.02)
                z = s.axis_height + dz * (BODY_DEPTH / 2 + 0.02) + (dz > 0) * 0.02  # + the lift
                assert not _inside(boxes, _to_world(p, [x, y, z]))
    # the front wall is closed beside the entrance, the roof and back are there
    assert _inside(boxes, _to_world(p, [s.wall / 2, s.entrance_width / 2 + 0.005, s.axis_height]))
    assert _inside(boxes, _to_world(p, [s.depth / 2, 0, s.top - s.wall / 2]))
    assert _inside(boxes, _to_world(p, [s.depth - s.wall / 2, 0, s.axis_height]))
    # the stick lies on the shelf block: touching it (d = 0), not penetrating
    stick = stick_obstacle(s, p)
    shelf = next(b for b in boxes if b.name == "storage_shelf")
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    req.enable_signed_distance = True
    d = coal.distance(stick.shape, stick.pose, shelf.shape, shelf.pose, req, res)
    assert abs(d) < 1e-9
    # its near end overhangs the block: below it, the shelf's space is free
    assert not _inside(boxes, _to_world(p, [s.stick_start + 0.01, 0, s.shelf - 0.01]))


@given(seed=st.integers(0, 10_000))
@settings(max_examples=50, deadline=None)
def test_random_placements_are_within_their_ranges(seed):
    p = random_placement(np.random.default_rng(seed))
    r, bearing = np.hypot(p.x, p.y), np.arctan2(p.y, p.x)
    assert PLACEMENT_RADIUS[0] <= r <= PLACEMENT_RADIUS[1]
    assert abs(bearing) <= PLACEMENT_BEARING and abs(p.yaw - bearing) <= PLACEMENT_YAW


def test_tool_poses_point_into_the_box_along_its_axis():
    rng = np.random.default_rng(3)
    s, p = random_storage(rng), Placement(0.6, 0.1, 0.4)
    poses = tool_poses(s, p)
    axis = p.transform()[:3, 0]
    assert np.allclose(poses["lift"] - poses["grasp"], [0, 0, 0.02])
    back = poses["grasp"] - poses["pregrasp"]
    assert np.allclose(back / np.linalg.norm(back), axis)
    for rot in tool_rotations(p):
        assert np.allclose(rot[:, 2], axis) and np.isclose(np.linalg.det(rot), 1.0)
        assert abs(rot[2, 1]) < 1e-12  # the fingers open horizontally
    out = tool_poses(s, p)["out"]  # the stick's far end 5 cm before the front face
    far_end = out + axis * (0.02 - 0.025 + s.stick_length)
    assert np.isclose(np.dot(far_end - p.transform()[:3, 3], axis), -0.05)


def test_the_table_is_clear_of_the_base_and_placements_off_it_are_flagged():
    table = table_obstacle()
    assert not _inside([table], [0, 0, -0.01])  # the base stands on the mounting surface
    assert _inside([table], [0.6, 0, -0.01])
    s = random_storage(np.random.default_rng(0))
    assert on_table(s, Placement(0.6, 0.0, 0.0))
    assert not on_table(s, Placement(1.05, 0.0, 0.0))


@pytest.mark.parametrize(
    "bad",
    [(np.nan, 0, 0), (0.5, "a", 0), (0.5, 0, np.inf), (3.0, 0, 0), (None, 0, 0), (True, 0, 0)],
)
def test_bad_placements_are_input_errors_naming_the_placement(bad):
    with pytest.raises(InputError, match=r"^placement: "):
        check_placement(*bad)
