"""The ClearanceNet-style 3-D baseline: its obstacle vector, ∂d̂/∂q against finite differences,
and a short fit that beats the mean predictor."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from hypothesis import example, given, settings
from hypothesis import strategies as st

from gdnplan.arm3d import load_robot3d, random_boxes, sphere_obstacle
from gdnplan.arm3d.scene3d import Scene3D
from gdnplan.data.shards3d import generate3d
from gdnplan.errors import InputError
from gdnplan.models.clearancenet3d import (
    ClearanceNet3D,
    ClearanceNet3DConfig,
    ClearanceNet3DModel,
    scene_vector,
)
from gdnplan.train.clearancenet3d import evaluate_clearancenet3d, load_arrays, train_clearancenet3d


def test_gradient_matches_finite_differences():
    robot = load_robot3d("ur5e")
    scene = random_boxes(robot, 20, seed=0)
    torch.manual_seed(0)
    net = ClearanceNet3D(ClearanceNet3DConfig(scale=1.2))
    model = ClearanceNet3DModel(net, dtype=torch.float64)
    q = robot.random_configurations(2, np.random.default_rng(0))
    d, g = model.distance_and_grad(scene, q)
    np.testing.assert_allclose(d, model.distance(scene, q))
    h = 1e-6
    for b in range(2):
        fd = [
            (model.distance(scene, q[b] + e) - model.distance(scene, q[b] - e))[0] / (2 * h)
            for e in np.eye(6) * h
        ]
        np.testing.assert_allclose(g[b], fd, rtol=1e-5, atol=1e-9)


def test_scene_vector_needs_exactly_the_boxes():
    robot = load_robot3d("ur5e")
    assert scene_vector(random_boxes(robot, 20, seed=1), 20).shape == (120,)
    with pytest.raises(InputError, match="20 boxes"):
        scene_vector(random_boxes(robot, 3, seed=1), 20)
    with pytest.raises(InputError, match="20 boxes"):
        scene_vector(Scene3D(robot, [sphere_obstacle(0.1, (0.5, 0, 0.5))] * 20), 20)


def test_a_short_fit_beats_the_mean(tmp_path):
    generate3d("ur5e_boxes", 200, 0, tmp_path, workers=1, shard_size=100)
    data = load_arrays(tmp_path)
    assert len(data["d"]) == 200 and data["boxes"].shape == (200, 120)
    net, summary = train_clearancenet3d(data, scale=1.2, batch=64, epochs=40)
    m = evaluate_clearancenet3d(net, data)
    assert summary["epochs"] == 40
    assert m["mae_m"] < np.mean(np.abs(data["d"] - data["d"].mean()))


MODEL = ClearanceNet3DModel(ClearanceNet3D(ClearanceNet3DConfig(scale=1.2)), dtype=torch.float64)


@pytest.mark.parametrize(
    ("robot", "match"),
    [
        ("panda", r"takes 6 joint angles, robot 'panda' has 7"),  # was torch's RuntimeError
        ("ur5", r"trained for robot 'ur5e', not 'ur5'"),  # six joints: the UR5e's numbers
    ],
)
def test_another_robot_is_refused_not_given_the_ur5es_distances(robot, match):
    other = load_robot3d(robot)
    scene = random_boxes(other, 20, seed=0)
    q = other.random_configurations(2, np.random.default_rng(0))
    for call in (MODEL.distance, MODEL.distance_and_grad):
        with pytest.raises(InputError, match=match):
            call(scene, q)


def _turned(scene: Scene3D, k: int, rotation) -> Scene3D:
    """``scene`` with obstacle k turned by ``rotation`` (x, y, z, w) about its centre."""
    from gdnplan.arm3d import box_obstacle

    boxes = list(scene.obstacles)
    o = boxes[k]
    boxes[k] = box_obstacle(2 * np.asarray(o.shape.halfSide), o.pose.getTranslation(), rotation)
    return Scene3D(scene.robot, boxes)


def test_a_rotated_box_is_refused_not_read_as_an_unrotated_one():
    """The obstacle vector had no rotation: a box turned by 45° gave the d̂ of the unturned."""
    scene = random_boxes(load_robot3d("ur5e"), 20, seed=0)
    turned = _turned(scene, 3, [0.0, 0.0, np.sin(np.pi / 8), np.cos(np.pi / 8)])
    with pytest.raises(InputError, match=r"obstacles\[3\].*rotated box"):
        MODEL.distance(turned, np.zeros(6))
    with pytest.raises(InputError, match="axis-aligned"):
        scene_vector(turned, 20)


QUARTER_TURNS = [  # (x, y, z, w) of the 24 rotations of a cube
    tuple(q)
    for q in __import__("scipy.spatial.transform", fromlist=["Rotation"])
    .Rotation.create_group("O")
    .as_quat()
]


@settings(max_examples=12, deadline=None)
@given(turn=st.sampled_from(QUARTER_TURNS), k=st.integers(0, 19))
@example(turn=(0.0, 0.0, np.sqrt(0.5), np.sqrt(0.5)), k=0)  # 90° about z: sides x and y swap
def test_a_box_turned_by_quarter_turns_is_its_world_extents(turn, k):
    """A box turned by a multiple of 90° is the axis-aligned box of its world extents (the
    obstacle vector held its own sides, unpermuted)."""
    from gdnplan.arm3d import box_obstacle

    scene = random_boxes(load_robot3d("ur5e"), 20, seed=2)
    turned = _turned(scene, k, turn)
    o = scene.obstacles[k]
    rot = np.abs(np.asarray(turned.obstacles[k].pose.getRotation()))
    extents = rot @ (2 * np.asarray(o.shape.halfSide))
    same = list(scene.obstacles)
    same[k] = box_obstacle(extents, o.pose.getTranslation())
    q = load_robot3d("ur5e").random_configurations(3, np.random.default_rng(k))
    np.testing.assert_allclose(
        MODEL.distance(turned, q), MODEL.distance(Scene3D(scene.robot, same), q), atol=1e-12
    )


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"seconds": float("inf")}, "seconds"),  # trained for ever
        ({"seconds": float("nan")}, "seconds"),  # trained nothing
        ({"epochs": 1.5}, "epochs"),
        ({"epochs": 1, "batch": 0}, "batch"),
        ({"epochs": 1, "lr": 1e300}, "lr"),
        ({"epochs": 1, "seed": -1}, "seed"),
    ],
)
def test_bad_clearancenet3d_training_arguments_name_the_field(changes, field):
    data = {"q": np.zeros((4, 6)), "boxes": np.zeros((4, 120)), "d": np.zeros(4)}
    with pytest.raises(InputError, match=rf"^{field}: "):
        train_clearancenet3d(data, 1.0, **changes)
