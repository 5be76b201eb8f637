"""The ClearanceNet-style 3-D baseline: its obstacle vector, ∂d̂/∂q against finite differences,
and a short fit that beats the mean predictor."""

from __future__ import annotations

import numpy as np
import pytest
import torch

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
