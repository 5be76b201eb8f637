"""The pair table and coal's narrow phase (gdnplan.arm3d.narrow3d): every pair keeps the
convention p₁ on the robot shape, p₂ on the other, p₂ − p₁ = d n, octree obstacles included
(coal reports those in the order octree, shape)."""

from __future__ import annotations

import coal
import numpy as np
import pytest

from gdnplan.arm3d import Scene3D, box_obstacle, load_robot3d, obstacle
from gdnplan.arm3d.narrow3d import PairTable, check_cap
from gdnplan.errors import InputError


def on_shape(shape, tf: np.ndarray, point: np.ndarray) -> float:
    """coal distance (m) from ``point`` (3,) to ``shape`` placed at ``tf`` (4, 4)."""
    ball = coal.Sphere(1e-9)
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    coal.distance(
        shape,
        coal.Transform3s(tf[:3, :3], tf[:3, 3]),
        ball,
        coal.Transform3s(np.eye(3), point),
        req,
        res,
    )
    return max(res.min_distance, 0.0)


@pytest.mark.parametrize("kind", ["box", "octree"])
def test_witness_points_keep_the_robot_shape_first(kind):
    robot = load_robot3d("ur5e")
    if kind == "box":
        obs = box_obstacle((0.02, 0.6, 0.6), (0.4, 0.0, 0.3), name="wall")
    else:
        rng = np.random.default_rng(1)
        pts = np.column_stack([np.full(300, 0.4), rng.uniform((-0.3, 0.0), (0.3, 0.6), (300, 2))])
        obs = obstacle(coal.makeOctree(pts, 0.02), name="cloud")
    table = PairTable(Scene3D(robot, [obs]))
    assert table.swapped[: table.n_obstacle_pairs].all() == (kind == "octree")
    assert not table.swapped[table.n_obstacle_pairs :].any()
    checked = 0
    for q in robot.random_configurations(40, np.random.default_rng(2)):
        tf, bounds = table.placements(q)
        for k in np.flatnonzero(bounds[: table.n_obstacle_pairs] < 0.05):
            d, p1, p2, n = table.pair(k, tf)
            a = table.pair_a[k]
            assert on_shape(robot.shapes[a].shape, tf[a], p1) <= 1e-6  # p₁ on the robot shape
            np.testing.assert_allclose(p2 - p1, d * n, atol=1e-6)
            if d > 1e-3:  # apart: n points from the robot shape to the obstacle
                assert on_shape(robot.shapes[a].shape, tf[a], p1 + 0.5 * d * n) > 0.25 * d
            checked += 1
    assert checked >= 5


@pytest.mark.parametrize("bad", [float("nan"), "one", None, True])
def test_cap_must_be_a_number(bad):
    with pytest.raises(InputError, match="cap"):
        check_cap(bad)
