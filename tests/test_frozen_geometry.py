"""Scenes and robots cannot change after their checkers and lever arms are cached: moving an
obstacle in place (``scene.obstacles[0] += offset``) or replacing a 3-D scene's obstacles left
the certificate running on the geometry as it was, and a path through the moved obstacle was
certified."""

from __future__ import annotations

import coal
import numpy as np
import pytest

import gdnplan as gp
from gdnplan.arm3d import Scene3D, box_obstacle, load_robot3d
from gdnplan.arm3d.ccd3d import certify_path3d
from gdnplan.arm3d.scene3d import Obstacle3D, world_sphere
from gdnplan.arm3d.shapes import box
from gdnplan.ccd import certify_path

PATH = np.array([[0.0, 0.0], [0.3, 0.0]])  # planar2 turns its shoulder by 0.3 rad
PATH3D = np.array([[0.0, -1.57, 0.0, -1.57, 0.0, 0.0], [1.5, -1.57, 0.0, -1.57, 0.0, 0.0]])


def test_a_planar_obstacle_cannot_be_moved_in_place_after_a_certificate():
    scene = gp.make_scene("a")
    assert certify_path(scene, PATH).ok  # caches the scene's coal checker
    tip = scene.robot.link_polygons(np.array([0.15, 0.0]))[-1].mean(0)
    with pytest.raises(ValueError, match="read-only"):
        scene.obstacles[0] += tip - scene.obstacles[0].mean(0)  # onto the path: was certified
    moved = scene.with_obstacles([scene.obstacles[0] + (tip - scene.obstacles[0].mean(0))])
    assert not certify_path(moved, PATH).ok  # a new scene is the way to move it


@pytest.mark.parametrize(
    "array",
    [
        lambda s: s.obstacles[0],
        lambda s: s.obstacle_parts[0],
        lambda s: s.robot.polygons[0].vertices0,
        lambda s: s.robot.nodes0,
        lambda s: s.robot.node_body,
        lambda s: s.robot.chain.joint_origins,
        lambda s: s.robot.lower,
    ],
)
def test_planar_geometry_arrays_are_read_only(array):
    scene = gp.make_scene("a")
    with pytest.raises(ValueError, match="read-only"):
        array(scene)[0] = 1.0


def test_a_3d_scene_cannot_take_other_obstacles_after_a_certificate():
    robot = load_robot3d("ur5e")
    scene = Scene3D(robot, [])
    assert certify_path3d(scene, PATH3D, margin=0.01).ok  # caches the scene's checker
    tip = robot.shape_placements((PATH3D[0] + PATH3D[1]) / 2)[-1, :3, 3]
    cube = box_obstacle((0.05, 0.05, 0.05), tip)
    with pytest.raises(AttributeError, match="immutable"):
        scene.obstacles = (cube,)  # was certified clear of the cube on the path
    assert not certify_path3d(Scene3D(robot, [cube]), PATH3D, margin=0.01).ok


def test_3d_obstacle_and_link_shape_arrays_are_read_only():
    obstacle = box_obstacle((0.1, 0.1, 0.1), (1.0, 0.0, 0.0))
    shape = load_robot3d("ur5e").shapes[0]
    for array in (obstacle.center, shape.center, shape.placement):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 5.0


def test_a_3d_obstacle_keeps_its_own_pose():
    """A caller's pose object moved after the obstacle was made leaves the obstacle where it was
    (the pair tables cached its broad phase there)."""
    shape = box((0.1, 0.1, 0.1), "box")
    pose = coal.Transform3s(np.eye(3), np.array([1.0, 0.0, 0.0]))
    obstacle = Obstacle3D("box", shape, pose, *world_sphere(shape, pose))
    pose.setTranslation(np.array([5.0, 0.0, 0.0]))
    assert np.allclose(obstacle.pose.getTranslation(), [1.0, 0.0, 0.0])
