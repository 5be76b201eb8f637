"""GraphDistNet-3D: ∂d̂/∂q against finite differences, determinism and continuity along sweeps,
padding invariance, the training path equal to the inference path, exact self-collision."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from model_checks import (
    assert_deterministic_and_continuous,
    assert_gradient_matches_central_differences,
)

from gdnplan.arm3d import Checker3D, Scene3D, load_robot3d, random_boxes
from gdnplan.errors import InputError
from gdnplan.graph3d import robot_graph3d, scene_graph3d
from gdnplan.models import DistanceModel
from gdnplan.models.graphdistnet3d import (
    GraphDistNet3D,
    GraphDistNet3DConfig,
    GraphDistNet3DModel,
    ObstacleInput,
    boxes_input,
    forward_with_grad,
    obstacle_input,
)


@pytest.fixture(scope="module")
def robot():
    return load_robot3d("ur5e")


@pytest.fixture(scope="module")
def scene(robot):
    return random_boxes(robot, 20, seed=4)


def _net(seed: int = 0) -> GraphDistNet3D:
    torch.manual_seed(seed)
    return GraphDistNet3D(GraphDistNet3DConfig(scale=1.2, layers=2, tau=0.05))


@pytest.fixture(scope="module")
def model64():
    return GraphDistNet3DModel(_net().double(), dtype=torch.float64, self_collision=False)


def test_is_a_distance_model(model64):
    assert isinstance(model64, DistanceModel)


def test_gradient_matches_finite_differences(model64, robot, scene):
    qs = robot.random_configurations(4, np.random.default_rng(0))
    # h = 1e-7: at 1e-6 one of these steps crosses a LeakyReLU kink
    assert_gradient_matches_central_differences(model64, scene, qs, h=1e-7)


def test_deterministic_and_continuous_along_a_sweep(model64, robot, scene):
    rng = np.random.default_rng(1)
    q0 = robot.random_configurations(1, rng)[0]
    step = rng.uniform(-0.003, 0.003, robot.dof)  # ≤ 0.003 rad per joint
    path = q0 + np.arange(60)[:, None] * step
    # m per ≤ 0.003 rad joint step (untrained weights)
    assert_deterministic_and_continuous(model64, scene, path, step_bound=0.01)


def test_padded_obstacle_nodes_change_nothing(robot, scene):
    net = _net().double()
    graph = scene_graph3d(scene)
    obs = obstacle_input([graph], torch.float64)
    wide = ObstacleInput(
        torch.cat([obs.nodes, torch.full((1, 7, 3), 0.3, dtype=torch.float64)], 1),
        torch.cat([obs.mask, torch.zeros(1, 7, dtype=torch.bool)], 1),
        torch.cat(
            [
                obs.nbr,
                torch.arange(obs.nbr.shape[1], obs.nbr.shape[1] + 7)[None, :, None].expand(1, 7, 3),
            ],
            1,
        ),
        torch.cat([obs.nbr_mask, torch.zeros(1, 7, 3, dtype=torch.bool)], 1),
    )
    rg = robot_graph3d(robot)
    q = robot.random_configurations(1, np.random.default_rng(2))
    nodes = torch.as_tensor(rg.positions(q))
    nbr, mask = torch.as_tensor(rg.nbr), torch.as_tensor(rg.nbr_mask)
    with torch.no_grad():
        a = net(nodes, nbr, mask, net.obstacle_pass(obs))
        b = net(nodes, nbr, mask, net.obstacle_pass(wide))
    torch.testing.assert_close(a, b, rtol=0, atol=1e-12)


def test_training_batches_equal_per_scene_inference(robot):
    net = _net().double()
    model = GraphDistNet3DModel(net, dtype=torch.float64, self_collision=False)
    rg = robot_graph3d(robot)
    rng = np.random.default_rng(3)
    scenes = [random_boxes(robot, 20, seed=s) for s in (10, 11)]
    centers = np.array([[o.pose.getTranslation() for o in s.obstacles] for s in scenes])
    sizes = np.array([[2 * np.asarray(o.shape.halfSide) for o in s.obstacles] for s in scenes])
    q = robot.random_configurations(6, rng)
    rows = torch.tensor([0, 1, 1, 0, 1, 0])
    feats = net.obstacle_pass(boxes_input(centers, sizes, torch.float64)).take(rows)
    nodes, jac = rg.positions_and_jacobians(q)
    d, g = forward_with_grad(
        net, rg, torch.as_tensor(nodes), torch.as_tensor(jac), feats, create_graph=False
    )
    for i, s in enumerate(rows.tolist()):
        di, gi = model.distance_and_grad(scenes[s], q[i])
        np.testing.assert_allclose(d[i].item(), di[0], atol=1e-12)
        np.testing.assert_allclose(g[i].detach().numpy(), gi[0], atol=1e-10)


def test_self_collision_stays_exact(robot, scene):
    net = _net().double()
    exact = GraphDistNet3DModel(net, dtype=torch.float64, self_collision=True)
    learned = GraphDistNet3DModel(net, dtype=torch.float64, self_collision=False)
    q = robot.random_configurations(20, np.random.default_rng(4))
    d, g = exact.distance_and_grad(scene, q)
    dl, gl = learned.distance_and_grad(scene, q)
    res = Checker3D(Scene3D(robot, ())).evaluate(q, gradient=True)
    np.testing.assert_allclose(d, np.minimum(dl, res.distance))
    own = res.distance < dl
    np.testing.assert_allclose(g[own], res.gradient[own])
    np.testing.assert_allclose(g[~own], gl[~own])
    np.testing.assert_allclose(exact.distance(scene, q), d)


def test_rejects_other_robots_and_empty_scenes(robot):
    model = GraphDistNet3DModel(_net(), card={"robot": "ur5e"})
    with pytest.raises(InputError, match="panda"):
        model.distance(random_boxes(load_robot3d("panda"), 2, seed=0), np.zeros(7))
    with pytest.raises(InputError, match="obstacle"):
        model.distance(Scene3D(robot, ()), np.zeros(6))


def test_config_round_trip_and_bad_values():
    c = GraphDistNet3DConfig(scale=1.1, origin=(0.0, 0.0, 0.1))
    assert GraphDistNet3DConfig.from_dict(c.to_dict()) == c
    with pytest.raises(InputError):
        GraphDistNet3DConfig(scale=-1)
    with pytest.raises(InputError, match="unknown"):
        GraphDistNet3DConfig.from_dict({"bogus": 1})
