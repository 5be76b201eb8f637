"""GraphDistNet-3D's soft-minimum readout (``min_readout``): the plain network unchanged without
it, the plain network's function at initialisation with it, ∂d̂/∂q against finite differences,
determinism and continuity along sweeps, the soft minimum between the minimum and the mean."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from model_checks import (
    assert_deterministic_and_continuous,
    assert_gradient_matches_central_differences,
)

from gdnplan.arm3d import load_robot3d, random_boxes
from gdnplan.errors import InputError
from gdnplan.models.graphdistnet3d import (
    GraphDistNet3D,
    GraphDistNet3DConfig,
    GraphDistNet3DModel,
    load_graphdistnet3d,
)

SHIPPED = "weights/ur5e_boxes3d_preliminary.safetensors"


@pytest.fixture(scope="module")
def robot():
    return load_robot3d("ur5e")


@pytest.fixture(scope="module")
def scene(robot):
    return random_boxes(robot, 20, seed=4)


def _config(**kw) -> GraphDistNet3DConfig:
    return GraphDistNet3DConfig(scale=1.2, layers=2, **kw)


def _trained_like(seed: int = 0) -> GraphDistNet3D:
    """A min-readout network whose node estimates are not zero (as after training)."""
    torch.manual_seed(seed)
    net = GraphDistNet3D(_config(min_readout=True, tau_min=0.2)).double()
    with torch.no_grad():
        net.node_head[-1].weight.normal_(0, 0.3)
        net.node_head[-1].bias.fill_(0.5)
    return net


@pytest.fixture(scope="module")
def model64():
    return GraphDistNet3DModel(_trained_like(), dtype=torch.float64, self_collision=False)


def test_without_it_the_network_and_its_random_draw_are_unchanged():
    torch.manual_seed(3)
    plain = GraphDistNet3D(_config())
    torch.manual_seed(3)
    with_min = GraphDistNet3D(_config(min_readout=True))
    assert not any(k.startswith(("node_head", "log_tau_min")) for k in plain.state_dict())
    for name, t in plain.state_dict().items():  # the new parameters are drawn after the old
        torch.testing.assert_close(with_min.state_dict()[name], t, rtol=0, atol=0)


def test_the_shipped_card_loads_as_a_plain_network():
    model = load_graphdistnet3d(SHIPPED)
    assert model.config.min_readout is False and not hasattr(model.net, "node_head")


def test_at_initialisation_it_is_the_plain_networks_function(robot, scene):
    torch.manual_seed(5)
    plain = GraphDistNet3D(_config())
    torch.manual_seed(5)
    with_min = GraphDistNet3D(_config(min_readout=True))
    q = robot.random_configurations(16, np.random.default_rng(0))
    # both on the torch path: the compiled pass serves the plain network only (float32 sums in
    # another order would differ in the last bits)
    a = GraphDistNet3DModel(plain, self_collision=False, fused=False)
    b = GraphDistNet3DModel(with_min, self_collision=False, fused=False)
    a, b = (m.learned_distance_and_grad(scene, q) for m in (a, b))
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_allclose(a[1], b[1], rtol=0, atol=1e-7)


def test_shapes_and_the_node_estimates_change_the_distance(model64, robot, scene):
    q = robot.random_configurations(5, np.random.default_rng(1))
    d, g = model64.distance_and_grad(scene, q)
    assert d.shape == (5,) and g.shape == (5, robot.dof) and np.isfinite(g).all()
    plain = GraphDistNet3D(_config()).double()
    plain.load_state_dict(
        {k: v for k, v in model64.net.state_dict().items() if k in plain.state_dict()}
    )
    d_plain = GraphDistNet3DModel(plain, dtype=torch.float64, self_collision=False).distance(
        scene, q
    )
    assert np.abs(d - d_plain).min() > 1e-4  # m: the soft minimum is not zero here


def test_soft_minimum_lies_between_the_minimum_and_the_mean():
    net = _trained_like()
    e = torch.tensor([[0.3, 1.0, 2.0, 5.0], [-1.0, -1.0, -1.0, -1.0]], dtype=torch.float64)
    m = net.soft_min(e)
    assert (m >= e.min(-1).values - 1e-12).all() and (m <= e.mean(-1) + 1e-12).all()
    torch.testing.assert_close(m[1], torch.tensor(-1.0, dtype=torch.float64))
    with torch.no_grad():
        net.log_tau_min.fill_(np.log(1e-3))
    torch.testing.assert_close(
        net.soft_min(e)[0],
        torch.tensor(0.3, dtype=torch.float64),
        atol=1e-3 * np.log(4) + 1e-9,
        rtol=0,
    )


def test_gradient_matches_finite_differences(model64, robot, scene):
    qs = robot.random_configurations(4, np.random.default_rng(2))
    assert_gradient_matches_central_differences(model64, scene, qs, h=1e-7)


def test_deterministic_and_continuous_along_a_sweep(model64, robot, scene):
    rng = np.random.default_rng(3)
    q0 = robot.random_configurations(1, rng)[0]
    path = q0 + np.arange(60)[:, None] * rng.uniform(-0.003, 0.003, robot.dof)
    assert_deterministic_and_continuous(model64, scene, path, step_bound=0.01)


def test_config_round_trip_and_bad_temperature():
    c = _config(min_readout=True, tau_min=0.1)
    assert GraphDistNet3DConfig.from_dict(c.to_dict()) == c
    with pytest.raises(InputError, match="tau_min"):
        _config(tau_min=0.0)
